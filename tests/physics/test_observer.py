"""The model-based observer (twin.physics.sensing.KalmanObserver) against closed forms: on a
noise-free run that its model explains exactly, its error shrinks at the rate its gain was designed
for (the largest |eigenvalue| of (I - K H) F), and it converges to the true velocity."""

from __future__ import annotations

import numpy as np
import pytest

from twin.exceptions import InvalidParameter
from twin.physics.model import referred_mass
from twin.physics.params import NOMINAL_PARAMS, ObserverParams
from twin.physics.sensing import KalmanObserver

T = 1e-3  # s


def observer(density: float = ObserverParams().disturbance_density) -> KalmanObserver:
    p = NOMINAL_PARAMS
    return KalmanObserver(mass=referred_mass(p), area=p.cylinder.bore_area, viscous=p.friction.viscous,
                          disturbance_density=density, position_noise=p.sensors.position_noise,
                          pressure_noise=p.sensors.pressure_noise, sample_period=T, initial=np.zeros(2))


def constant_velocity_errors(obs: KalmanObserver, velocity: np.ndarray, ticks: int) -> np.ndarray:
    """|v_hat - v| per tick for racks at constant ``velocity`` (n,) from 0, no pressure difference:
    the model explains it exactly (the unmodelled acceleration is the constant F_v v / M)."""
    errors = []
    for k in range(1, ticks + 1):
        v_hat, _ = obs.update(velocity * k * T, np.zeros_like(velocity), np.zeros_like(velocity))
        errors.append(np.abs(v_hat - velocity))
    return np.array(errors)


@pytest.mark.parametrize("density", [1e3, 3e3, 1e5])
def test_kalman_converges_to_a_constant_velocity_at_its_designed_rate(density):
    obs = observer(density)
    rho = obs.rate
    assert 0 < rho < 1
    errors = constant_velocity_errors(obs, np.array([0.02, -0.08]), 400)
    # The eigenvalues may be complex, so the error oscillates inside its envelope: compare the
    # envelope (the largest error in a window) over an interval with rho to that power.
    window = 15
    start = 10
    stop = start + int(np.log(1e-9) / np.log(rho))  # the envelope falls ~1e9: far above round-off
    envelope = lambda k: errors[k:k + window].max(axis=0)  # noqa: E731
    measured = np.log(envelope(stop) / envelope(start)) / (stop - start)
    np.testing.assert_allclose(measured, np.log(rho), rtol=0.1)
    assert np.all(errors[-1] < 1e-12 * 0.08 + 1e-14)  # converged to the true velocity


def test_kalman_reads_the_velocity_a_pressure_difference_drives():
    """Racks pushed from rest by a constant pressure difference, exactly as the nominal model says
    (y'' = u - c y', u = A dP / M, c = F_v / M; nothing unmodelled): the estimates converge to the
    closed-form velocity u/c (1 - e^{-ct}) and acceleration u e^{-ct}."""
    p = NOMINAL_PARAMS
    obs = observer()
    mass = referred_mass(p)  # as the plant's filter (twin.sim.plant_state)
    c = p.friction.viscous / mass
    dp = np.array([50e3, -20e3])  # Pa, P_a - P_b
    u = p.cylinder.bore_area * dp / mass
    obs.update(np.zeros(2), dp, np.zeros(2))  # tick 0: at rest, the pressures applied from here on
    for k in range(1, 300):
        t = k * T
        v_hat, a_hat = obs.update(u / c * (t - (1 - np.exp(-c * t)) / c), dp, np.zeros(2))
    t = 299 * T
    np.testing.assert_allclose(v_hat, u / c * (1 - np.exp(-c * t)), rtol=1e-9)
    np.testing.assert_allclose(a_hat, u * np.exp(-c * t), atol=1e-9 * np.abs(u).max())


def test_observer_kind_is_checked():
    with pytest.raises(InvalidParameter, match="observer kind"):
        ObserverParams(kind="luenberger")
