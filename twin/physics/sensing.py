"""Sensors (§5) and the velocity/acceleration observer (eq. 5.2.2).

The Hall sensor reads rack A's position every 1 ms; the pressure sensors read
the chambers and the supply. Noise is white and uniform within the bounds of
:class:`twin.physics.params.SensorParams` (*inferred*: SPEC gives "+-" bounds).
Each scenario draws its noise from its own generator, so batching does not
change any scenario's numbers.
"""

from __future__ import annotations

import numpy as np


def uniform_noise(rng: np.random.Generator, bound: float, shape: tuple[int, ...]) -> np.ndarray:
    """White noise uniform in [-bound, bound]."""
    return rng.uniform(-bound, bound, size=shape) if bound > 0 else np.zeros(shape)


class FirstOrderObserver:
    """v_hat = z + K y, dz/dt = -K v_hat (eq. 5.2.2): v_hat = K s / (s + K) y.

    Discretised with the matched pole d = exp(-K T) and unit gain on a ramp::

        v_hat[k] = d v_hat[k-1] + (1 - d) (y[k] - y[k-1]) / T

    (the zero-order-hold form over-reads every slope by K T / (1 - d), 5 % at
    K = 100 1/s). Applied twice: to the position for v_hat, to v_hat for a_hat.
    Arrays are (n,).
    """

    def __init__(self, *, gain: np.ndarray | float, sample_period: float, initial: np.ndarray):
        self.gain = gain  # 1/s, K_OB, per scenario
        self._decay = np.exp(-np.asarray(gain, dtype=float) * sample_period)
        self._period = sample_period
        self._position = np.array(initial, dtype=float)
        self._velocity = np.zeros_like(self._position)
        self._acceleration = np.zeros_like(self._position)

    def update(self, position: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(velocity, acceleration) estimates from the newest position sample."""
        velocity = self._decay * self._velocity + (1.0 - self._decay) * (position - self._position) / self._period
        self._acceleration = (self._decay * self._acceleration
                              + (1.0 - self._decay) * (velocity - self._velocity) / self._period)
        self._position, self._velocity = np.array(position, dtype=float), velocity
        return velocity, self._acceleration
