"""Sensors (§5) and the velocity/acceleration observer (eq. 5.2.2).

The Hall sensor reads rack A's position every 1 ms; the pressure sensors read
the chambers and the supply. Noise is white and uniform within the bounds of
:class:`twin.params.SensorParams` (*inferred*: SPEC gives "+-" bounds).
Each scenario draws its noise from its own generator, so batching does not
change any scenario's numbers.
"""

from __future__ import annotations

import math

import numpy as np

from twin.params import ObserverParams


def uniform_noise(rng: np.random.Generator, bound: float, shape: tuple[int, ...]) -> np.ndarray:
    """White noise uniform in [-bound, bound]."""
    return rng.uniform(-bound, bound, size=shape) if bound > 0 else np.zeros(shape)


class FirstOrderObserver:
    """v_hat = z + K y, dz/dt = -K v_hat (eq. 5.2.2): v_hat = K s / (s + K) y.

    Discretised exactly for a measurement held over each sample (zero-order
    hold). Applied twice: to the position for v_hat, to v_hat for a_hat.
    Arrays are (n,).
    """

    def __init__(self, *, params: ObserverParams, sample_period: float, initial: np.ndarray):
        self.gain = params.gain
        self._decay = math.exp(-params.gain * sample_period)
        self._z_velocity = -self.gain * initial
        self._z_acceleration = np.zeros_like(initial)

    def _derivative(self, z: np.ndarray, signal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        estimate = z + self.gain * signal
        z_next = self._decay * z - (1.0 - self._decay) * self.gain * signal
        return estimate, z_next

    def update(self, position: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(velocity, acceleration) estimates from the newest position sample."""
        velocity, self._z_velocity = self._derivative(self._z_velocity, position)
        acceleration, self._z_acceleration = self._derivative(self._z_acceleration, velocity)
        return velocity, acceleration
