"""Observer, metrics, trajectories, friction, feed-forward and parameter checks
against closed forms and SPEC numbers (§4 - §7)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from controllers.feedforward import NominalModel, feedforward_duty
from twin.exceptions import InvalidParameter, InvalidScenario
from twin.physics import params as P
from twin.physics.friction import coulomb_force
from twin.physics.params import FrictionParams, GearParams, ObserverParams
from twin.physics.sensing import FirstOrderObserver
from twin.physics.trajectories import trajectory
from twin.sim.metrics import LONGEST_LAG, delay_for_rmse, lagging_metrics, tracking_metrics

DT = 1e-3  # s, sensor sample period (§5)
R_SPUR = 9.525e-3 / 2  # m, spur pitch radius (§2)
AREA = math.pi * 0.002**2  # m^2


# --------------------------------------------------------------------------- observer (eq. 5.2.2)

def _observe(signal: np.ndarray, gain: float = 100.0) -> tuple[np.ndarray, np.ndarray]:
    obs = FirstOrderObserver(gain=ObserverParams(gain=gain).gain, sample_period=DT, initial=np.array([signal[0]]))
    out = [obs.update(np.array([y])) for y in signal]
    return np.array([v[0] for v, _ in out]), np.array([a[0] for _, a in out])


def test_observer_at_rest_estimates_zero_motion():
    v, a = _observe(np.full(200, 7e-3))
    assert np.all(v == 0.0) and np.all(a == 0.0)




def test_observer_velocity_of_a_ramp_converges_to_its_slope():
    """K s / (s + K) applied to y = s t: v_hat -> s with time constant 1/K = 10 ms."""
    slope = 0.01  # m/s
    t = np.arange(300) * DT
    v, _ = _observe(slope * t)
    assert v[200:] == pytest.approx(slope, rel=1e-6)


def test_observer_acceleration_of_a_ramp_converges_to_zero():
    slope = 0.01
    t = np.arange(400) * DT
    _, a = _observe(slope * t)
    # The start-up transient is of order K s = 1 m/s^2; after 30 time constants it is gone.
    assert np.max(np.abs(a[300:])) < 1e-6


def test_observer_acceleration_of_a_parabola_converges_to_its_curvature():
    """The same filter applied to v_hat: for y = c t^2 / 2, v_hat -> c t (lagged) and a_hat -> c."""
    curvature = 0.063  # m/s^2, T1's largest reference acceleration
    t = np.arange(600) * DT
    _, a = _observe(curvature * t**2 / 2)
    assert a[500:] == pytest.approx(curvature, rel=1e-6)


@pytest.mark.parametrize("omega", [math.pi, 100.0])
def test_observer_acceleration_of_a_sine_follows_the_transfer_applied_twice(omega):
    amplitude, gain = 5e-3, 100.0
    t = np.arange(int(round(10.0 / DT))) * DT
    _, a = _observe(amplitude * np.sin(omega * t), gain)
    steady = a[t > 10.0 - 2 * 2 * math.pi / omega - 1e-9]
    expected = abs(gain * 1j * omega / (1j * omega + gain)) ** 2 * amplitude  # (K s / (s + K))^2 on y
    assert np.max(np.abs(steady)) == pytest.approx(expected, rel=0.02)


@pytest.mark.parametrize("omega", [math.pi, 100.0])  # T3's 0.5 Hz, and the corner frequency
def test_observer_sine_amplitude_follows_the_continuous_transfer(omega):
    amplitude, gain = 5e-3, 100.0
    t = np.arange(int(round(10.0 / DT))) * DT
    v, _ = _observe(amplitude * np.sin(omega * t), gain)
    steady = v[t > 10.0 - 2 * 2 * math.pi / omega - 1e-9]  # the last two periods
    # y -> v_hat is K s / (s + K): the velocity amplitude is |K j w / (j w + K)| times the position amplitude.
    expected = abs(gain * 1j * omega / (1j * omega + gain)) * amplitude
    assert np.max(np.abs(steady)) == pytest.approx(expected, rel=0.02)


# --------------------------------------------------------------------------- metrics (§7, eq. 5.2.8)

@pytest.mark.parametrize("c", [0.3, -0.02])
def test_metrics_of_a_constant_error(c):
    desired = np.linspace(0.0, 2.0, 50)
    m = tracking_metrics(desired, desired - c)
    assert m.rmse == pytest.approx(abs(c), rel=1e-12)
    assert m.sse == pytest.approx(c, rel=1e-12)  # signed, e = desired - actual
    assert m.max_error == pytest.approx(abs(c), rel=1e-12)


def test_metrics_by_hand():
    m = tracking_metrics(np.array([0.0, 0.0, 0.0, 1.0]), np.array([-3.0, 4.0, 0.0, 2.0]))
    # e = [3, -4, 0, -1]: rmse = sqrt((9 + 16 + 0 + 1) / 4), final error -1, max |e| 4
    assert m.rmse == pytest.approx(math.sqrt(26.0 / 4.0), rel=1e-12)
    assert m.sse == pytest.approx(-1.0)
    assert m.max_error == pytest.approx(4.0)



@pytest.mark.parametrize("delay", [0.0123, 0.0245, 0.05])
def test_a_joint_lagging_t2s_ramp_by_a_fixed_time_errs_by_the_closed_form(delay):
    """On T2's ramp (omega = 10 mm/s / r_s from rest) a joint that follows tau behind errs by omega t until tau,
    then by omega tau: at ticks t_k = k h, RMSE^2 = omega^2 (h^2 sum_{k<K} k^2 + (N - K) tau^2) / N with K the
    ticks before tau, and sum_{k<K} k^2 = (K - 1) K (2K - 1) / 6; the largest error omega tau."""
    r, h = 4.7625e-3, 1e-3
    omega = 10e-3 / r
    n = 1000  # T2's 1 s
    k = math.ceil(delay / h)  # ticks k h < tau
    squares = (k - 1) * k * (2 * k - 1) / 6
    closed = omega * math.sqrt((h * h * squares + (n - k) * delay * delay) / n)
    m = lagging_metrics(trajectory(2, spur_radius=r), delay, spur_radius=r, timestep=h)
    assert m.rmse == pytest.approx(closed, rel=1e-9)
    assert m.max_error == pytest.approx(omega * delay, rel=1e-9)
    assert math.isnan(m.sse)  # T2 ends moving


def test_the_delay_for_an_rmse_is_the_one_that_gives_it_and_nan_past_the_search():
    r, h = 4.7625e-3, 1e-3
    t3 = trajectory(3, spur_radius=r)
    rmse = lagging_metrics(t3, 0.0187, spur_radius=r, timestep=h).rmse
    assert delay_for_rmse(t3, rmse, spur_radius=r, timestep=h) == pytest.approx(0.0187, abs=1e-8)
    too_much = lagging_metrics(t3, LONGEST_LAG, spur_radius=r, timestep=h).rmse * 1.01
    assert math.isnan(delay_for_rmse(t3, too_much, spur_radius=r, timestep=h))


# --------------------------------------------------------------------------- trajectories (§7)

def _traj(n: int):
    return trajectory(n, spur_radius=GearParams().spur_radius)


def _deg_at(n: int, times) -> np.ndarray:
    ref = _traj(n).sample(np.asarray(times, dtype=float), R_SPUR)
    return np.degrees(ref.position / R_SPUR)


@pytest.mark.parametrize("n, duration", [(1, 3.0), (2, 1.0), (3, 4.0), (4, 6.0)])
def test_trajectory_durations(n, duration):
    assert _traj(n).duration == pytest.approx(duration, abs=1e-12)


def test_t1_rises_120_degrees_to_140_and_holds():
    t = np.arange(3000) * DT
    theta = _deg_at(1, t)
    assert theta[0] == pytest.approx(30.0, abs=1e-9)  # inside the friction fit (SPEC §7)
    assert theta[t >= 1.0] == pytest.approx(150.0, abs=1e-9)


def test_t1_peak_acceleration_is_the_cycloid_amplitude():
    """a = A_max sin(2 pi t / T), A_max = 2 pi H / T^2 (eqs. 5.2.5 - 5.2.7), H = 120 deg of rack travel."""
    t = np.arange(3000) * DT
    ref = _traj(1).sample(t, R_SPUR)
    height = math.radians(120.0) * R_SPUR  # m
    a_max = 2 * math.pi * height / 1.0**2
    assert np.max(ref.acceleration) == pytest.approx(a_max, rel=1e-3)
    assert np.min(ref.acceleration) == pytest.approx(-a_max, rel=1e-3)


def test_t2_ramps_at_10_mm_per_second_to_the_end():
    t = np.arange(1000) * DT
    ref = _traj(2).sample(t, R_SPUR)
    assert _traj(2).duration == 1.0 and not _traj(2).ends_at_rest
    assert ref.velocity == pytest.approx(10e-3, rel=1e-9)
    assert np.diff(ref.position) / DT == pytest.approx(10e-3, rel=1e-6)
    assert np.degrees(ref.position[-1] / R_SPUR) == pytest.approx(30.0 + 0.999 * 10e-3 / R_SPUR * 180 / math.pi)
    assert 0.999 * 10e-3 / R_SPUR * 180 / math.pi == pytest.approx(12.03 * 9.99, rel=1e-3)  # eq. 3.4.1: 12.03 deg/mm


def test_t3_is_a_half_hertz_sine_between_20_and_140_degrees():
    t = np.arange(4000) * DT
    theta = _deg_at(3, t)
    assert theta.max() == pytest.approx(140.0, abs=1e-6)
    assert theta.min() == pytest.approx(20.0, abs=1e-6)
    assert _deg_at(3, [0.5, 1.5, 2.5]) == pytest.approx([140.0, 20.0, 140.0], abs=1e-9)  # period 2 s


def test_t4_visits_150_30_90_30_degrees():
    # moves end at 1, 3, 4 and 5 s (1 + rest 1 + 1 + rest 0.5 + 0.5 + rest 0.5 + 0.5); check at the end
    # of each move and in the rest that follows
    assert _deg_at(4, [1.0, 3.0, 4.0, 5.0]) == pytest.approx([150.0, 30.0, 90.0, 30.0], abs=1e-9)
    assert _deg_at(4, [1.5, 3.25, 4.25, 5.5, 5.999]) == pytest.approx([150.0, 30.0, 90.0, 30.0, 30.0], abs=1e-9)
    assert _deg_at(4, [0.0])[0] == pytest.approx(30.0, abs=1e-9)


@pytest.mark.parametrize("n, end_deg", [(1, 150.0), (2, 30.0 + 10e-3 / R_SPUR * 180 / math.pi), (3, 80.0),
                                         (4, 30.0)])
def test_trajectory_end_is_where_the_reference_holds(n, end_deg):
    """``Trajectory.end`` (the live viewer's target after a replay): a ramp's end, a sine's where its
    last period stops (80 deg after T3's two periods, not start + amplitude), by hand and as sampled."""
    assert math.degrees(_traj(n).end) == pytest.approx(end_deg, abs=1e-9)
    assert _deg_at(n, [_traj(n).duration + 1.0])[0] == pytest.approx(math.degrees(_traj(n).end), abs=1e-12)


@pytest.mark.parametrize("n", [0, 5, 7, -1])
def test_unknown_trajectory_is_rejected(n):
    with pytest.raises(InvalidScenario):
        _traj(n)


# --------------------------------------------------------------------------- friction (eq. 4.5.7)

def f_c_by_hand(y: float) -> float:
    """Eq. 4.5.7, y in metres."""
    return (-3.051e14 * y**6 + 1.587e13 * y**5 - 3.244e11 * y**4 + 3.294e9 * y**3
            - 1.727e7 * y**2 + 4.36e4 * y - 39.551)


def _fc(y) -> np.ndarray:
    y = np.atleast_1d(np.asarray(y, dtype=float))
    return coulomb_force(FrictionParams(), y, np.ones_like(y))


def test_coulomb_force_at_8_mm_is_eq_4_5_7():
    assert _fc(8e-3)[0] == pytest.approx(f_c_by_hand(8e-3), rel=1e-9)
    assert 0.0 < _fc(8e-3)[0] < 2.1  # §4: 0 - 2.1 N on the fitted range


def test_coulomb_force_is_clamped_outside_the_fitted_range():
    assert _fc(1e-3)[0] == pytest.approx(_fc(2e-3)[0], rel=1e-12)
    assert _fc(-5e-3)[0] == pytest.approx(max(f_c_by_hand(2e-3), 0.0), rel=1e-9)
    assert _fc(20e-3)[0] == pytest.approx(_fc(14.5e-3)[0], rel=1e-12)
    assert _fc(30e-3)[0] == pytest.approx(max(f_c_by_hand(14.5e-3), 0.0), rel=1e-9, abs=1e-12)


def test_coulomb_force_broadcasts_and_scales_only_towards_zero_degrees():
    params = FrictionParams(ccw_coulomb_scale=1.4)
    y = np.array([3e-3, 8e-3, 12.5e-3])
    grid = coulomb_force(params, y[:, None], np.array([1.0, -1.0, 0.0]))  # (3, 1) against (3,)
    assert grid.shape == (3, 3)
    assert grid[:, 0] == pytest.approx([max(f_c_by_hand(v), 0.0) for v in y], rel=1e-9, abs=1e-12)
    assert grid[:, 1] == pytest.approx(1.4 * grid[:, 0], rel=1e-12)  # moving towards 0 deg
    assert np.all(grid[:, 2] == grid[:, 0])  # at rest: the fitted value, unscaled
    assert float(coulomb_force(params, 8e-3, -1.0)) == pytest.approx(grid[1, 1], rel=1e-12)


def test_coulomb_level_is_coulomb_force_towards_plus_y_in_plain_numpy():
    from twin.physics.friction import coulomb_level

    y = np.linspace(-10e-3, 30e-3, 4001)  # across the clamps and the dip below zero near 12 mm
    assert coulomb_level(FrictionParams(), y) == pytest.approx(_fc(y), rel=1e-12, abs=1e-12)


def test_coulomb_force_is_never_negative():
    y = np.linspace(-10e-3, 30e-3, 4001)
    assert np.all(_fc(y) >= 0.0)
    # Where the raw fit dips below zero (near 12 mm, §4) the force is exactly zero.
    dips = [v for v in y if 2e-3 <= v <= 14.5e-3 and f_c_by_hand(v) < 0]
    assert dips, "eq. 4.5.7 dips below zero near 12 mm"
    assert np.all(_fc(dips) == 0.0)


# --------------------------------------------------------------------------- feed-forward (eqs. 5.3.2 - 5.3.3)

NOMINAL = NominalModel.thesis()


def _ff(y, v, a) -> float:
    return float(feedforward_duty(NOMINAL, np.array([y]), np.array([v]), np.array([a]))[0])


@pytest.mark.parametrize("a", [0.0, 0.5, -0.5])
def test_feedforward_is_zero_when_the_desired_velocity_is_zero(a):
    assert _ff(8e-3, 0.0, a) == 0.0


def test_feedforward_sign_follows_the_velocity():
    forward, backward = _ff(8e-3, 10e-3, 0.0), _ff(8e-3, -10e-3, 0.0)
    assert forward > 0 > backward
    # One R(d) for all four valves, no direction-dependent friction by default: symmetric.
    assert backward == pytest.approx(-forward, rel=1e-12)


def test_feedforward_round_trip_through_the_steady_velocity():
    """d from the feed-forward, put into v = (P_ws A - F_c) / (F_v + (R1 + R(d)) A^2), gives v_d back."""
    y, v_d = 8e-3, 10e-3
    d = _ff(y, v_d, 0.0)
    assert 0.0 < d < 100.0
    p_ws, f_v = 300e3, 45.9
    r1 = 1.8372e14 * 100.0**-2.1706
    r_d = 1.8372e14 * d**-2.1706
    v = (p_ws * AREA - f_c_by_hand(y)) / (f_v + (r1 + r_d) * AREA**2)
    assert v == pytest.approx(v_d, rel=1e-9)


def test_feedforward_saturates_at_100_percent_for_unreachable_speed():
    # Even fully open (R1 + R1), 300 kPa reaches at most P_ws A / (F_v + 2 R1 A^2) ~ 0.08 m/s.
    assert _ff(8e-3, 0.5, 0.0) == 100.0
    assert _ff(8e-3, -0.5, 0.0) == -100.0


# --------------------------------------------------------------------------- parameter validation

@pytest.mark.parametrize("cls, field", [
    (P.CylinderParams, "bore_diameter"), (P.CylinderParams, "max_stroke"), (P.CylinderParams, "rated_pressure"),
    (P.GearParams, "pinion_pitch_diameter"), (P.GearParams, "spur_pitch_diameter"), (P.GearParams, "diametral_pitch"),
    (P.MassParams, "rack_mass"), (P.MassParams, "piston_mass"), (P.MassParams, "water_mass"),
    (P.MassParams, "pinion_inertia"), (P.MassParams, "spur_inertia"), (P.MassParams, "link_mass"),
    (P.MassParams, "link_length"), (P.MassParams, "thesis_total_mass"),
    (P.ValveParams, "pwm_period"), (P.ValveParams, "resistance_coefficient"),
    (P.SupplyParams, "pressure"), (P.SupplyParams, "max_pressure"),
    (P.SensorParams, "sample_period"), (P.ObserverParams, "gain"),
])
@pytest.mark.parametrize("value", [0.0, -1.0, float("nan")])
def test_non_positive_parameters_are_rejected(cls, field, value):
    with pytest.raises(InvalidParameter):
        cls(**{field: value})


@pytest.mark.parametrize("cls, field", [
    (P.ValveParams, "opening_delay"), (P.ValveParams, "closing_delay"), (P.ValveParams, "dead_zone_duty"),
    (P.FrictionParams, "viscous"), (P.FrictionParams, "stiction"), (P.FrictionParams, "ccw_coulomb_scale"),
    (P.SensorParams, "position_noise"), (P.SensorParams, "pressure_noise"),
])
def test_negative_parameters_are_rejected(cls, field):
    with pytest.raises(InvalidParameter):
        cls(**{field: -1.0})


def test_dead_zone_of_100_percent_or_more_is_rejected():
    with pytest.raises(InvalidParameter):
        P.ValveParams(dead_zone_duty=100.0)


@pytest.mark.parametrize("value", [0.0, -8500.0])
def test_non_positive_payload_density_is_rejected(value):
    with pytest.raises(InvalidParameter):
        P.MassParams(payload_density=value)


def test_valid_defaults_construct():
    joint = P.JointParams()
    assert dataclasses.is_dataclass(joint)
    assert joint.cylinder.bore_area == pytest.approx(AREA, rel=1e-12)
    assert joint.gears.spur_radius == pytest.approx(R_SPUR, rel=1e-12)


def test_feedforward_accounts_for_the_desired_acceleration():
    """d from the feed-forward at v_d and a_d, put into eq. 4.3.6 with every term written out, M a = P_ws A - F_c(y)
    - F_v v - (R1 + R(d)) A^2 v, gives the acceleration back, either way (the round trip above, accelerating)."""
    model = NominalModel.thesis()
    y, v, a = 8e-3, 10e-3, 2.0
    p_ws, f_v = 300e3, 45.9
    r1 = 1.8372e14 * 100.0**-2.1706
    for sign in (1.0, -1.0):
        d = feedforward_duty(model, np.array([y]), np.array([sign * v]), np.array([sign * a]))[0]
        assert 0.0 < sign * d < 100.0
        r_d = 1.8372e14 * abs(d) ** -2.1706
        force = p_ws * AREA - f_c_by_hand(y) - f_v * v - (r1 + r_d) * AREA**2 * v  # N, along the motion
        assert force / model.mass == pytest.approx(a, rel=1e-9)
    accelerating = feedforward_duty(model, np.array([y]), np.array([v]), np.array([a]))[0]
    cruising = feedforward_duty(model, np.array([y]), np.array([v]), np.array([0.0]))[0]
    assert accelerating > cruising  # more force needed: less resistance, more duty


def test_a_contiguous_run_of_scenarios_is_selected_by_a_slice_and_others_by_their_indices():
    from twin.physics.scenario_axis import selector

    assert selector(np.array([3, 4, 5])) == slice(3, 6)
    gappy = selector(np.array([0, 2, 3]))
    assert isinstance(gappy, np.ndarray) and gappy.tolist() == [0, 2, 3]
    values = np.arange(10.0)
    assert values[selector(np.array([3, 4, 5]))].tolist() == values[[3, 4, 5]].tolist()
