"""``twin calibrate``: its cost, its box, its determinism, and the committed preset it reproduces."""

from __future__ import annotations

import json
import math

import pytest

from twin.exceptions import InvalidScenario
from twin.experiments import calibrate
from twin.experiments.calibrate import CellResult, cost, values_at
from twin.experiments.reference import THESIS_EXPERIMENT_RMSE_DEG, THESIS_EXPERIMENT_SSE_T1_RANGE_DEG
from twin.plants.as_built import CALIBRATION_FILE, FITTED, as_built_plant, calibrated_values


def exact_cells(scale: dict | None = None) -> list[CellResult]:
    """Cells that hit the experimental table, RMSE times ``scale[(controller, T)]``."""
    scale = scale or {}
    cells = []
    for controller, trajectory in calibrate.CELLS:
        target = THESIS_EXPERIMENT_RMSE_DEG[controller][trajectory][0] * scale.get((controller, trajectory), 1.0)
        sse = THESIS_EXPERIMENT_SSE_T1_RANGE_DEG[controller] if trajectory == 1 else math.nan
        cells.append(CellResult(controller, trajectory, (target, target), (sse, -sse / 2)))
    return cells


def cauchy(r: float) -> float:
    c = math.log(1.2)
    return c * c * math.log(1.0 + (r / c) ** 2)


def test_cost_is_zero_on_the_table_and_cauchy_of_the_log_ratio_off_it():
    assert cost(exact_cells()) == pytest.approx(0.0, abs=1e-12)
    assert cost(exact_cells({("smc", 3): 2.0})) == pytest.approx(cauchy(math.log(2.0)))
    assert cost(exact_cells({("pva", 2): 0.5})) == pytest.approx(cauchy(math.log(2.0)))


def test_cost_is_the_squared_log_ratio_near_the_table_and_grows_slowly_far_out():
    near = cost(exact_cells({("ffpva", 3): 1.01}))
    assert near == pytest.approx(math.log(1.01) ** 2, rel=5e-3)
    far = cost(exact_cells({("pva", 1): 0.25}))
    at_the_bar = cost(exact_cells({("smc", 2): 1.2}))
    assert far > 2 * at_the_bar  # a factor-4 miss still costs more than two cells at the 20 % bar ...
    pull_far = cost(exact_cells({("pva", 1): 0.25 / 1.05})) - far
    pull_at_the_bar = cost(exact_cells({("smc", 2): 1.2 * 1.05})) - at_the_bar
    assert 0 < pull_far < pull_at_the_bar / 3  # ... but a further 5 % there pulls far less than at the bar


def test_cost_is_a_sum_over_cells_so_a_far_miss_does_not_change_the_pull_on_another_cell():
    far, at_the_bar = {("pva", 1): 0.25}, {("smc", 2): 1.2}
    both = cost(exact_cells(far | at_the_bar))
    assert both == pytest.approx(cost(exact_cells(far)) + cost(exact_cells(at_the_bar)))
    nudged = {("smc", 2): 1.26}
    pull_alone = cost(exact_cells(nudged)) - cost(exact_cells(at_the_bar))
    pull_with_far_miss = cost(exact_cells(far | nudged)) - both
    assert pull_with_far_miss == pytest.approx(pull_alone)
    assert pull_alone == pytest.approx(cauchy(math.log(1.26)) - cauchy(math.log(1.2)))


def test_cost_weighs_the_t1_steady_error_range():
    cells = exact_cells()
    ffpva_t1 = next(i for i, c in enumerate(cells) if (c.controller, c.trajectory) == ("ffpva", 1))
    doubled = 2 * THESIS_EXPERIMENT_SSE_T1_RANGE_DEG["ffpva"]
    cells[ffpva_t1] = CellResult("ffpva", 1, cells[ffpva_t1].rmse_deg, (0.1, -doubled))
    assert cost(cells) == pytest.approx(cauchy(math.sqrt(calibrate.SSE_WEIGHT) * math.log(2.0)))


def test_a_failed_run_costs():
    cells = exact_cells()
    cells[0] = CellResult(cells[0].controller, cells[0].trajectory, cells[0].rmse_deg, cells[0].sse_deg,
                          failed_seeds=(0,))
    assert cost(cells) == pytest.approx(1.0)


def test_record_keeps_the_ensemble_and_the_table_and_plot_show_it(tmp_path):
    from viz.calibration_plots import plot_calibration

    result = calibrate.Calibration(values=calibrated_values(), cost=0.0, evaluations=1,
                                   history=[(calibrated_values(), 0.5)], fit_cells=exact_cells(),
                                   check_cells=exact_cells(), ensemble_cells=exact_cells({("smc", 4): 0.75}),
                                   wall_time=1.0, max_evaluations=1, fit_seeds=(0,), check_seeds=(0,),
                                   ensemble_seeds=tuple(range(20)))
    data = calibrate.record(result)
    assert data["ensemble_seeds"] == list(range(20))
    (smc_t4,) = [r for r in data["residuals_ensemble_seeds"] if (r["controller"], r["trajectory"]) == ("smc", 4)]
    assert smc_t4["ratio"] == pytest.approx(0.75)
    table = calibrate.format_residuals(data)
    assert "20 seeds: twin/exp" in table.splitlines()[0]
    assert table.splitlines()[len(calibrate.CELLS)].split()[-1] == "0.75"  # the last cell is sliding mode T4
    plot_calibration(data["residuals_check_seeds"], data["history"], tmp_path / "c.png",
                     data["residuals_ensemble_seeds"], 20, 1)
    assert (tmp_path / "c.png").stat().st_size > 0


def test_unit_box_maps_onto_the_plausible_bounds():
    assert values_at([0.0] * len(FITTED)) == {f.name: f.low for f in FITTED}
    assert values_at([1.0] * len(FITTED)) == {f.name: f.high for f in FITTED}
    assert values_at([2.0, -1.0, 0.5, 0.5, 0.5])[FITTED[0].name] == FITTED[0].high  # clipped, never outside


def test_committed_preset_is_inside_its_bounds_and_is_the_as_built_plant():
    values = calibrated_values()
    for f in FITTED:
        assert f.low <= values[f.name] <= f.high
    plant = as_built_plant()
    assert plant.params.friction.stiction == values["stiction"]
    assert plant.params.valves.dead_zone_duty == values["dead_zone_duty"]
    assert plant.params.chambers.air_fraction == values["air_fraction"]
    assert plant.params.friction.ccw_coulomb_scale == values["ccw_coulomb_scale"]
    assert plant.params.chambers.leak_conductance == values["leak_conductance"]
    assert plant.params.valves.supply_held_in_dead_zone


def test_a_value_outside_its_bounds_is_refused(tmp_path):
    record = json.loads(CALIBRATION_FILE.read_text())
    record["fitted"]["air_fraction"] = 0.5
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(record))
    with pytest.raises(InvalidScenario, match="air_fraction = 0.5 is outside"):
        calibrated_values(path)


def test_sse_range_is_the_largest_of_five_runs_averaged_over_groups_of_five():
    five = CellResult("ffpva", 1, (1.0,) * 5, (0.1, -0.4, 0.2, math.nan, 0.3))
    assert five.sse_range == pytest.approx(0.4)  # the thesis's "+-": the largest |SSE| of the five
    ten = CellResult("ffpva", 1, (1.0,) * 10, (0.1, -0.4, 0.2, 0.0, 0.3, 0.9, 0.1, 0.1, -0.2, 0.0))
    assert ten.sse_range == pytest.approx((0.4 + 0.9) / 2)  # not 0.9, the largest of ten
    assert CellResult("smc", 1, (1.0,) * 3, (0.2, -0.5, 0.1)).sse_range == pytest.approx(0.5)  # fewer than 5
    seven = CellResult("smc", 1, (1.0,) * 7, (0.1, 0.2, 0.3, 0.4, 0.5, 9.0, 9.0))
    assert seven.sse_range == pytest.approx(0.5)  # the two runs past the whole group are left out
    moving = CellResult("smc", 1, (1.0,) * 10, (math.nan,) * 5 + (0.1, 0.2, 0.3, -0.6, 0.0))
    assert moving.sse_range == pytest.approx(0.6)  # a group whose runs all end moving has no range
    assert math.isnan(CellResult("smc", 1, (1.0,) * 5, (math.nan,) * 5).sse_range)


def test_cells_of_picks_the_runs_of_the_wanted_seeds():
    cell = CellResult("pva", 2, (1.0, 2.0, 3.0, 4.0), (0.1, 0.2, 0.3, 0.4), failed_seeds=(1, 3),
                      seeds=(0, 1, 2, 3))
    (picked,) = calibrate._cells_of([cell], (3, 0))
    assert picked.seeds == (0, 3) and picked.rmse_deg == (1.0, 4.0) and picked.sse_deg == (0.1, 0.4)
    assert picked.failed == 1 and picked.failed_seeds == (3,)
    assert calibrate._cells_of([cell], (0, 4)) == []  # seed 4 was not run: the caller runs them
    assert calibrate._cells_of([cell], ()) == []
    (twice,) = calibrate._cells_of([cell], (3, 3))
    assert twice.rmse_deg == (4.0,) and twice.failed == 1  # a seed asked for twice is one run


@pytest.mark.slow  # over ~2.5 s on 2 cores
def test_same_seeds_same_fit_whatever_the_workers(monkeypatch):
    small = dict(max_evaluations=2, fit_seeds=(0, 1, 2), check_seeds=(0,), ensemble_seeds=(1,))
    def no_new_runs(*args):
        raise AssertionError("the check and ensemble seeds are fit seeds: their runs are the fit's")

    monkeypatch.setattr(calibrate, "_cells_once", no_new_runs)
    one = calibrate.calibrate(workers=1, **small)
    two = calibrate.calibrate(workers=2, **small)
    assert one.values == two.values and one.cost == two.cost
    assert [c.rmse_deg for c in one.check_cells] == [c.rmse_deg for c in two.check_cells]
    assert [c.rmse_deg for c in one.ensemble_cells] == [c.rmse_deg for c in two.ensemble_cells]
    assert len(one.ensemble_cells) == len(calibrate.CELLS)
    # The check seed 0 is one of the fit's: its cells are cut from the fit's runs, and equal a run of seed 0
    # alone; the ensemble seed 1 is too.
    alone = calibrate.Evaluator(seeds=(0, 1), workers=1).cells(one.values)
    assert [c.rmse_deg for c in one.check_cells] == [c.rmse_deg[:1] for c in alone]
    assert [c.rmse_deg for c in one.ensemble_cells] == [c.rmse_deg[1:] for c in alone]


@pytest.mark.slow  # over ~2.5 s on 2 cores
def test_calibrate_retraces_the_committed_fit():
    """The same seeds give the same numbers: the fit's first evaluations (the fixed starting simplex) cost
    exactly what the committed file says. The whole fit (100 evaluations, about 8 min on 2 cores) is
    ``twin calibrate --out DIR``; its file equals the committed one (see docs/as-built.md)."""
    committed = json.loads(CALIBRATION_FILE.read_text())
    result = calibrate.calibrate(workers=2, max_evaluations=3, check_seeds=(), ensemble_seeds=())
    for (values, cost_now), expected in zip(result.history, committed["history"][:3], strict=True):
        assert values == expected["values"]
        assert cost_now == expected["cost"]
