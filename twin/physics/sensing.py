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


class KalmanObserver:
    """A model-based velocity and acceleration observer (SPEC §10): a steady-state Kalman filter
    on the rack's nominal dynamics, driven by the measured chamber pressures.

    State x = (y, v, b): rack position, velocity and the acceleration the nominal model does not
    explain (Coulomb friction and stiction, gravity, mass error), taken as a random walk::

        dy/dt = v
        dv/dt = (A (P_a - P_b) - F_v v) / M + b
        db/dt = w,   E[w(t) w(s)] = q delta(t - s)

    with nominal numbers (A, F_v; M as the caller gives it). Discretised exactly over
    the 1 ms sample (zero-order hold on the pressures, Van Loan for q); the measured pressures'
    white noise enters as input noise, the Hall sensor's as measurement noise (uniform bounds,
    variance bound^2 / 3). The gain is the steady state of the Riccati equation, so the filter is
    a fixed linear observer: without noise and with the model right, its error obeys
    e[k+1] = (I - K H) F e[k] and shrinks by :attr:`rate` per sample. The supply pressure is not
    used: with both chambers measured it adds nothing to the force on the rack. Arrays are (n,).
    """

    def __init__(self, *, mass: float, area: float, viscous: float, disturbance_density: float,
                 position_noise: float, pressure_noise: float, sample_period: float, initial: np.ndarray):
        from scipy.linalg import expm, solve_discrete_are

        T, c = sample_period, viscous / mass
        a_c = np.array([[0.0, 1.0, 0.0], [0.0, -c, 1.0], [0.0, 0.0, 0.0]])
        b_c = np.array([[0.0], [1.0], [0.0]])  # input: A (P_a - P_b) / M, m/s^2
        block = np.zeros((4, 4))
        block[:3, :3], block[:3, 3:] = a_c, b_c
        step = expm(block * T)
        self.transition, self.input = step[:3, :3], step[:3, 3]  # F, G
        # Van Loan: the disturbance's covariance over one sample.
        q_c = np.zeros((3, 3))
        q_c[2, 2] = disturbance_density
        van_loan = expm(np.block([[-a_c, q_c], [np.zeros((3, 3)), a_c.T]]) * T)
        q = self.transition @ van_loan[:3, 3:]
        input_variance = 2.0 * pressure_noise**2 / 3.0 * (area / mass) ** 2  # two chambers' noise in A dP / M
        q = q + input_variance * np.outer(self.input, self.input)
        q = (q + q.T) / 2.0
        r = max(position_noise**2 / 3.0, 1e-18)  # m^2; a floor keeps the Riccati equation solvable without noise
        h = np.array([[1.0, 0.0, 0.0]])
        prior = solve_discrete_are(self.transition.T, h.T, q, np.array([[r]]))
        self.gain = (prior @ h.T / (h @ prior @ h.T + r))[:, 0]  # K (3,)
        self.error_matrix = (np.eye(3) - np.outer(self.gain, h[0])) @ self.transition
        self._area, self._mass, self._c = area, mass, c
        initial = np.array(initial, dtype=float)
        self._state = np.stack([initial, np.zeros_like(initial), np.zeros_like(initial)])  # (3, n)
        self._input = np.zeros_like(initial)

    @property
    def rate(self) -> float:
        """The designed convergence: the error's largest factor per sample, |eig((I - K H) F)|."""
        return float(np.max(np.abs(np.linalg.eigvals(self.error_matrix))))

    def update(self, position: np.ndarray, pressure_a: np.ndarray, pressure_b: np.ndarray
               ) -> tuple[np.ndarray, np.ndarray]:
        """(velocity, acceleration) estimates after the newest Hall sample, given the chamber
        pressures measured at the same tick (they drive the rack until the next one)."""
        prior = self.transition @ self._state + np.outer(self.input, self._input)
        self._state = prior + np.outer(self.gain, position - prior[0])
        self._input = self._area * (np.asarray(pressure_a) - np.asarray(pressure_b)) / self._mass
        velocity = self._state[1].copy()
        acceleration = self._input - self._c * velocity + self._state[2]
        return velocity, acceleration
