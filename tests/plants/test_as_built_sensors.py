"""As-built Hall reading (eq. 4.2.1 vs calibration points, §5) and stiction map
(§4, future work 2) against closed forms."""

from __future__ import annotations

import math

import numpy as np
import pytest

from twin.exceptions import InvalidParameter
from twin.physics.hall import HallReading, fit_degrees, reading_error, true_volts
from twin.physics.params import HallParams, StictionMapParams
from twin.physics.stiction_map import StictionMap

R_SPUR = 9.525e-3 / 2  # m, spur pitch radius (§2)
A, B, C = -9.122, -25.58, 244.94  # eq. 4.2.1, deg from V
HALL = HallParams(calibration_error=True)
POINTS = HALL.points  # (deg, V)


# --------------------------------------------------------------------------- Hall (eq. 4.2.1, §5)

def test_fit_is_eq_4_2_1_by_hand():
    x = 2.866  # V
    assert float(fit_degrees(HALL, x)) == pytest.approx(A * x**2 + B * x + C, abs=1e-12)


def test_true_volts_pass_through_calibration_points():
    angles, volts = np.array(POINTS).T
    np.testing.assert_allclose(true_volts(HALL, angles), volts, rtol=0, atol=1e-12)


@pytest.mark.parametrize(("deg", "volts"), POINTS)
def test_error_at_each_calibration_point_is_fit_residual(deg, volts):
    by_hand = A * volts**2 + B * volts + C - deg  # deg
    error = math.degrees(float(reading_error(HALL, math.radians(deg))))
    assert error == pytest.approx(by_hand, abs=1e-9)


def test_error_at_94_deg_is_plus_2_70():
    by_hand = A * 2.866**2 + B * 2.866 + C - 94.0  # 96.70 - 94
    error = math.degrees(float(reading_error(HALL, math.radians(94.0))))
    assert error == pytest.approx(by_hand, abs=1e-9)
    assert error == pytest.approx(2.70, abs=0.005)


def test_true_volts_between_points_is_linear():
    (a0, v0), (a1, v1) = POINTS[6], POINTS[7]  # (94, 2.866), (97, 2.828)
    mid = true_volts(HALL, np.array([a0 + 1.0]))
    np.testing.assert_allclose(mid, v0 + (v1 - v0) / (a1 - a0), atol=1e-12)


def test_true_volts_extrapolate_with_end_pairs():
    (a0, v0), (a1, v1) = POINTS[0], POINTS[1]
    (an1, vn1), (an, vn) = POINTS[-2], POINTS[-1]
    got = true_volts(HALL, np.array([-40.0, 220.0]))
    want = [v0 + (-40.0 - a0) * (v1 - v0) / (a1 - a0), vn + (220.0 - an) * (vn - vn1) / (an - an1)]
    np.testing.assert_allclose(got, want, atol=1e-12)


def test_points_are_sorted_by_angle():
    shuffled = HallParams(calibration_error=True, points=tuple(reversed(POINTS)))
    angles = np.linspace(-40, 220, 521)
    np.testing.assert_array_equal(true_volts(shuffled, angles), true_volts(HALL, angles))


def test_true_volts_decrease_with_angle():
    volts = true_volts(HALL, np.linspace(-40, 220, 5201))
    assert np.all(np.diff(volts) < 0)


def test_no_calibration_error_reads_exactly_zero():
    ideal = HallParams()
    assert ideal.calibration_error is False
    theta = np.radians(np.linspace(-40, 220, 101))
    error = reading_error(ideal, theta)
    assert error.shape == theta.shape
    assert np.all(error == 0.0)


def test_ideal_reading_returns_input_itself():
    y = np.linspace(-3e-3, 18e-3, 7)
    assert HallReading(HallParams(), R_SPUR)(y) is y


def test_reading_agrees_with_reading_error():
    y = np.radians(np.linspace(-40, 220, 2601)) * R_SPUR  # m
    theta = y / R_SPUR
    reported = HallReading(HALL, R_SPUR)(y)
    want = (theta + reading_error(HALL, theta)) * R_SPUR
    assert reported.shape == y.shape
    np.testing.assert_allclose(np.degrees((reported - want) / R_SPUR), 0.0, atol=1e-6)


def test_reading_at_94_deg_reports_fit_angle():
    y = np.array([[math.radians(94.0) * R_SPUR]])  # m, (1, 1)
    reported = HallReading(HALL, R_SPUR)(y)
    assert reported.shape == (1, 1)
    assert math.degrees(reported[0, 0] / R_SPUR) == pytest.approx(A * 2.866**2 + B * 2.866 + C, abs=1e-9)


def test_reading_rejects_bad_radius():
    with pytest.raises(InvalidParameter):
        HallReading(HALL, 0.0)


# --------------------------------------------------------------------------- stiction map (§4)

STROKE = (0.0, 20e-3)  # m


def _u(seed: int, n: int) -> np.ndarray:
    return np.random.default_rng(seed).uniform(-1.0, 1.0, n)


def test_knots_span_stroke_at_spacing():
    m = StictionMap(StictionMapParams(scatter=1.0, knot_spacing=1e-3, seed=0), 3.6, STROKE)
    np.testing.assert_allclose(m.knots, np.arange(21) * 1e-3, atol=1e-15)
    uneven = StictionMap(StictionMapParams(scatter=1.0, knot_spacing=1e-3, seed=0), 3.6, (0.0, 2.5e-3))
    np.testing.assert_allclose(uneven.knots, [0.0, 1e-3, 2e-3, 2.5e-3], atol=1e-15)


def test_values_at_knots_are_base_plus_scatter_u():
    p = StictionMapParams(scatter=1.5, knot_spacing=1e-3, seed=7)
    m = StictionMap(p, 3.6, STROKE)
    want = 3.6 + 1.5 * _u(7, 21)
    np.testing.assert_allclose(m.values, want, rtol=0, atol=1e-12)
    np.testing.assert_allclose(m(m.knots), want, rtol=0, atol=1e-12)


def test_linear_between_knots_and_held_outside():
    m = StictionMap(StictionMapParams(scatter=1.5, knot_spacing=1e-3, seed=3), 3.6, STROKE)
    v = m.values
    y = np.array([0.25e-3, 4.5e-3, 19.9e-3])
    want = [0.75 * v[0] + 0.25 * v[1], 0.5 * v[4] + 0.5 * v[5], 0.1 * v[19] + 0.9 * v[20]]
    np.testing.assert_allclose(m(y), want, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(m(np.array([-5e-3, 30e-3])), [v[0], v[-1]])


def test_zero_scatter_is_base_exactly():
    m = StictionMap(StictionMapParams(scatter=0.0, seed=0), 3.6, STROKE)
    y = np.linspace(-5e-3, 25e-3, 31).reshape(1, 31)
    out = m(y)
    assert out.shape == y.shape
    assert np.all(out == 3.6)


def test_clipped_at_zero_when_scatter_exceeds_base():
    m = StictionMap(StictionMapParams(scatter=5.0, knot_spacing=0.5e-3, seed=1), 1.0, STROKE)
    raw = 1.0 + 5.0 * _u(1, m.knots.size)
    assert np.any(raw < 0)
    np.testing.assert_allclose(m.values, np.maximum(raw, 0.0), atol=1e-12)
    assert np.all(m(np.linspace(*STROKE, 401)) >= 0.0)


def test_same_seed_same_map_other_seed_different():
    y = np.linspace(*STROKE, 201)
    first = StictionMap(StictionMapParams(scatter=1.0, seed=11), 3.6, STROKE)(y)
    again = StictionMap(StictionMapParams(scatter=1.0, seed=11), 3.6, STROKE)(y)
    other = StictionMap(StictionMapParams(scatter=1.0, seed=12), 3.6, STROKE)(y)
    np.testing.assert_array_equal(first, again)
    assert not np.allclose(first, other)


@pytest.mark.parametrize(("base", "stroke", "said"), [(-1.0, STROKE, "base stiction"),
                                                     (3.6, (5e-3, 5e-3), "stroke must be"),
                                                     (3.6, (0.0, math.inf), "stroke must be")])
def test_stiction_map_rejects_bad_arguments(base, stroke, said):
    # seeded, so that the refusal is the one for the bad argument, not the one for a missing seed
    with pytest.raises(InvalidParameter, match=said):
        StictionMap(StictionMapParams(scatter=1.0, seed=0), base, stroke)


def test_a_stiction_map_without_a_seed_is_refused():
    with pytest.raises(InvalidParameter, match="needs a seed"):
        StictionMap(StictionMapParams(scatter=1.0), 3.6, STROKE)


def test_stiction_maps_evaluate_each_runs_own_map():
    from twin.physics.stiction_map import StictionMaps

    params = StictionMapParams(scatter=1.0, knot_spacing=1e-3)
    maps = StictionMaps(params, 2.0, STROKE, seeds=[(0, 1), (1, 1), (0, 1)])
    y = np.array([3.3e-3, 3.3e-3, 7.75e-3])
    own = [StictionMap(StictionMapParams(scatter=1.0, knot_spacing=1e-3, seed=s), 2.0, STROKE)(yi)
           for s, yi in zip([(0, 1), (1, 1), (0, 1)], y, strict=True)]
    np.testing.assert_allclose(maps(y), own, rtol=1e-12)
    assert maps(y)[0] != maps(y)[1]  # two runs, two joints
    with pytest.raises(InvalidParameter, match="needs a seed"):
        StictionMap(params, 2.0, STROKE)


def test_run_plot_shows_the_scored_reading_beside_the_true_angle(tmp_path, monkeypatch):
    """On a plant scored on the Hall reading the figure must show what was scored, not only the true angle."""
    import matplotlib.figure

    from twin.envs.runner import run
    from twin.sim.scenario import Scenario
    from viz.plots import plot_run

    drawn = []
    monkeypatch.setattr(matplotlib.figure.Figure, "savefig",
                        lambda fig, path, **kw: drawn.append([[ln.get_label() for ln in ax.lines] for ax in fig.axes]))
    plot_run(run(Scenario("smc", 1, plant="as-built", seed=0)), tmp_path / "run.png")
    plot_run(run(Scenario("smc", 1, plant="thesis", seed=0)), tmp_path / "run.png")
    as_built, thesis = drawn
    assert "Hall reading" in as_built[0] and "reading (scored)" in as_built[1]
    assert "Hall reading" not in thesis[0] and len(thesis[1]) == 2  # the true error and the zero line
