"""``twin calibrate``: its cost, its box, its determinism, and the committed preset it reproduces."""

from __future__ import annotations

import dataclasses
import hashlib
import json
import math
import pathlib

import numpy as np
import pytest

from twin.batch.sweep import code_version
from twin.exceptions import InvalidScenario
from twin.experiments import calibrate
from twin.experiments.calibrate import CellResult, cost, values_at
from twin.experiments.reference import (
    THESIS_EXPERIMENT_RMSE_DEG,
    THESIS_EXPERIMENT_SSE_T1_RANGE_DEG,
    THESIS_ROBUSTNESS_T1_DEG,
)
from twin.physics.valves import ValveModel
from twin.plants.as_built import CALIBRATION_FILE, FITTED, as_built_plant, calibrated_values, ensemble_values

ROOT = pathlib.Path(__file__).resolve().parents[2]


def exact_cells(scale: dict | None = None) -> list[CellResult]:
    """Cells that hit every target, RMSE times ``scale[key]`` (key: controller, T, payload g, orientation,
    or just controller and T for the 0 g horizontal cells)."""
    scale = scale or {}
    cells = []
    for t in calibrate.TARGETS:
        factor = scale.get(t.key, scale.get((t.controller, t.trajectory), 1.0) if t.payload_g == 0
                           and t.orientation == "horizontal" else 1.0)
        target = t.rmse_deg * factor
        sse = t.sse_range_deg if t.sse_range_deg is not None else math.nan
        cells.append(CellResult(t.controller, t.trajectory, (target, target), (sse, -sse / 2),
                                payload_g=t.payload_g, orientation=t.orientation))
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
    ffpva_t1 = next(i for i, c in enumerate(cells) if c.key == ("ffpva", 1, 0.0, "horizontal"))
    doubled = 2 * THESIS_EXPERIMENT_SSE_T1_RANGE_DEG["ffpva"]
    cells[ffpva_t1] = CellResult("ffpva", 1, cells[ffpva_t1].rmse_deg, (0.1, -doubled))
    assert cost(cells) == pytest.approx(cauchy(math.sqrt(calibrate.SSE_WEIGHT) * math.log(2.0)))


def test_targets_are_section_8_and_the_chapter_6_t1_cells_each_once_and_no_t3():
    keys = [t.key for t in calibrate.TARGETS]
    assert len(keys) == len(set(keys)) == 11 + 12 - 2  # §9's 0 g horizontal rows are §8's
    assert all(t.trajectory != 3 or t.payload_g == 0 and t.orientation == "horizontal" for t in calibrate.TARGETS)
    for (controller, orientation), row in THESIS_ROBUSTNESS_T1_DEG.items():
        for payload_g, (mean, _, sse) in row.items():
            (t,) = [t for t in calibrate.TARGETS if t.key == (controller, 1, payload_g, orientation)]
            assert (t.rmse_deg, t.sse_range_deg) == (mean, sse)
    for controller, row in THESIS_EXPERIMENT_RMSE_DEG.items():
        for trajectory, (mean, _) in row.items():
            (t,) = [t for t in calibrate.TARGETS if t.key == (controller, trajectory, 0.0, "horizontal")]
            assert t.rmse_deg == mean
    # a vertical 13.5 g cell twice too high costs what any cell does
    assert cost(exact_cells({("smc", 1, 13.5, "vertical"): 2.0})) == pytest.approx(cauchy(math.log(2.0)))


def test_ensemble_is_every_evaluation_within_the_noise_best_first_then_each_profiled_extreme():
    E = calibrate.Evaluation

    def v(f, a=0.01, load=0.2):
        return {"stiction": f, "air_fraction": a, "ccw_coulomb_scale": 1.2, "leak_conductance": 1e-14,
                "load_friction": load, "observer_gain": 100.0, "initial_pressure_fraction": 0.5}

    assert calibrate.PROFILED == ("load_friction", "stiction", "observer_gain", "ccw_coulomb_scale", "air_fraction",
                                  "initial_pressure_fraction")
    history = [E(v(2.0), 1.00, "scan"), E(v(1.2), 1.04, "profile"), E(v(2.4), 1.05, "profile"),
               E(v(1.8), 1.02, "simplex"), E(v(1.8), 1.02, "simplex"), E(v(2.5), 1.30, "profile"),
               E(v(1.9, 0.02), 1.01, "simplex")]
    chosen = calibrate.choose_ensemble(history, history[0], noise=0.06)
    assert [e.values["stiction"] for e in chosen] == [2.0, 1.2, 2.4, 1.9, 1.8]  # 2.5 N costs more than the noise
    assert [e.values["stiction"] for e in calibrate.choose_ensemble(history, history[0], 0.06, limit=3)] == [2.0, 1.2, 2.4]
    assert calibrate.choose_ensemble(history, history[0], noise=0.0) == [history[0]]
    # the load friction's extremes come before the breakaway's; one costing more than the noise never
    loads = history + [E(v(1.8, load=0.1), 1.03, "profile"), E(v(1.8, load=0.5), 1.05, "profile"),
                       E(v(1.8, load=0.6), 1.20, "profile")]
    chosen = calibrate.choose_ensemble(loads, loads[0], 0.06, limit=4)
    assert [(e.values["load_friction"], e.values["stiction"]) for e in chosen] == [(0.2, 2.0), (0.1, 1.8), (0.5, 1.8),
                                                                                   (0.2, 1.2)]
    # round-off is not a value: a set whose observer gain differs from the others' by 1e-13 is no extreme
    # (the simplex leaves such twins), and the cheaper of two sets sharing an extreme is taken
    twins = [E(v(2.0), 1.00, "scan"), E(dict(v(2.0), observer_gain=100.0 + 1e-13), 1.05, "simplex"),
             E(v(2.0, 0.02), 1.02, "simplex")]
    assert [e.cost for e in calibrate.choose_ensemble(twins, twins[0], 0.06, limit=2)] == [1.00, 1.02]
    # the cheapest of the sets sharing an extreme value
    shared = [E(v(2.0), 1.00, "scan"), E(v(1.5, 0.03), 1.04, "simplex"), E(v(1.5, 0.02), 1.02, "simplex")]
    assert [e.cost for e in calibrate.choose_ensemble(shared, shared[0], 0.06, limit=2)] == [1.00, 1.02]


def test_a_failed_run_costs():
    cells = exact_cells()
    cells[0] = CellResult(cells[0].controller, cells[0].trajectory, cells[0].rmse_deg, cells[0].sse_deg,
                          failed_seeds=(0,))
    assert cost(cells) == pytest.approx(1.0)


def test_record_keeps_the_ensemble_and_the_noise_and_the_table_and_plot_show_them(tmp_path):
    from viz.calibration_plots import plot_calibration

    values = calibrated_values()
    other = dict(values, stiction=FITTED[0].low)
    history = [calibrate.Evaluation(values, 1.0, "scan"), calibrate.Evaluation(other, 1.01, "profile")]
    fit = exact_cells({("smc", 4): 0.75})
    result = calibrate.Calibration(values=values, cost=1.0, evaluations=2, history=history, fit_cells=fit,
                                   check_cells=exact_cells(), noise_costs=[1.0, 1.02, 0.98],
                                   ensemble=history, wall_time=1.0, max_evaluations=2, fit_seeds=(0, 1),
                                   check_seeds=(0,), noise_seed_sets=((2, 3), (4, 5)))
    data = calibrate.record(result)
    # the file names its own preset: the sweep store's version of the code once it is installed (here it is)
    assert data["code_version"] == code_version()
    other_fit = dataclasses.replace(result, values=other)
    assert calibrate.record(other_fit)["code_version"] == code_version(plants=calibrate.fit_presets(other))
    assert calibrate.record(other_fit)["code_version"] != code_version()  # not the preset installed when it ran
    assert data["noise"]["std"] == pytest.approx(0.02) and data["noise"]["seed_sets"] == [[0, 1], [2, 3], [4, 5]]
    assert [m["values"] for m in data["ensemble"]] == [values, other]
    (smc_t4,) = [r for r in data["residuals_fit_seeds"] if (r["controller"], r["trajectory"]) == ("smc", 4)]
    assert smc_t4["ratio"] == pytest.approx(0.75)
    table = calibrate.format_residuals(data)
    assert "2 seeds: twin/exp" in table.splitlines()[0]
    smc_line = next(line for line in table.splitlines() if line.startswith("smc") and " 4 " in line[:14])
    assert smc_line.split()[-1] == "0.75"
    assert "ensemble of 2" in table
    path = tmp_path / "as_built.json"
    calibrate.write(data, tmp_path)
    assert [m["stiction"] for m in ensemble_values(path)] == [values["stiction"], FITTED[0].low]
    plot_calibration(data, tmp_path / "c.png")
    assert (tmp_path / "c.png").stat().st_size > 0


def _starts(package_file) -> list[dict]:
    """A package copy of a trial's sets that twin calibrate takes as further starts (calibrate's
    START_PRESSURE_REFITS_FILE: starts 3-6; START_ANGLE_REFITS_FILE: 7-16; PROFILE_REFITS_FILE: 17-19)."""
    return json.loads(package_file.read_text())["starts"]


def _same_fit_but_for_the_new_starts(new: dict, old: dict, starts: list[dict]) -> None:
    """The calibration file ``new`` is ``old`` with the further starts ``starts`` (values) added to its history,
    every other row value for value and cost for cost in order, so with the same fitted values, cost and noise."""
    assert [h for h in new["history"] if not (h["stage"] == "previous" and h["values"] in starts)] == old["history"]
    assert (new["fitted"], new["cost"], new["noise"]) == (old["fitted"], old["cost"], old["noise"])


def test_the_further_starts_are_the_earlier_fits_as_fitted_inside_the_box_and_one_outside_is_refused():
    """The ninth and tenth refits' fitted values, with the chambers at half the supply as then assumed, then the four
    start-pressure trial refits' at their fractions, then the ten start-angle trial members under the eleventh refit's
    cut, then the three load-friction profile refits under the twelfth's, each to the last bit of its kept file (the
    package's copies of the trial sets are held to those files by their SHA-256)."""
    from twin.plants.as_built import (
        ELEVENTH_REFIT_FILE,
        NINTH_REFIT_FILE,
        TENTH_REFIT_FILE,
        TWELFTH_REFIT_FILE,
        calibration_cost_line,
        preset_digest,
    )

    ninth, tenth = (json.loads(f.read_text()) for f in (NINTH_REFIT_FILE, TENTH_REFIT_FILE))
    assert preset_digest(NINTH_REFIT_FILE) == "57ff10bf5b36"  # the ninth refit's file, as committed on 2026-11-26
    assert preset_digest(TENTH_REFIT_FILE) == "1c2dcd8c9f7f"  # the tenth's, as committed on 2026-11-27
    kept = _starts(calibrate.START_PRESSURE_REFITS_FILE)
    trials = []
    for start, fraction in zip(kept, (0.0, 0.25, 0.75, 1.0), strict=True):
        source = ROOT / start["source"]
        assert hashlib.sha256(source.read_bytes()).hexdigest() == start["source_sha256"]
        fit = json.loads(source.read_text())
        assert fit["assumed"]["initial_pressure_fraction"].startswith(f"both chambers start at {fraction:g} of")
        assert start["cost"] == fit["cost"]
        trials.append({**fit["fitted"], "initial_pressure_fraction": fraction})
    angles, cut = [], sum(calibration_cost_line(ELEVENTH_REFIT_FILE))  # the eleventh refit's best + noise
    angle_starts, profile_starts = _starts(calibrate.START_ANGLE_REFITS_FILE), _starts(calibrate.PROFILE_REFITS_FILE)
    for start in angle_starts:  # its members under that cut from 30 deg, at their exact values
        source = ROOT / start["source"]
        assert hashlib.sha256(source.read_bytes()).hexdigest() == start["source_sha256"]
        member = json.loads(source.read_text())["ensemble"][start["member"]]
        assert start["values"] == member["values"] and start["cost_from_30_deg"] <= cut
        angles.append(member["values"])
    assert [(s["source"][-7:-5], s["member"]) for s in angle_starts] == [
        *(("20", m) for m in (4, 5, 6, 7, 8, 10, 11, 12)), ("25", 11), ("25", 12)]
    profiles, cut = [], sum(calibration_cost_line(TWELFTH_REFIT_FILE))  # the twelfth refit's best + noise
    for start in profile_starts:  # the profile trial's refits under that cut, at their exact values
        source = ROOT / start["source"]
        assert hashlib.sha256(source.read_bytes()).hexdigest() == start["source_sha256"]
        (result,) = [r for r in json.loads(source.read_text())["results"] if r["at"] == start["load_friction"]]
        assert start["values"] == result["values"] and start["cost"] == result["cost"] <= cut
        assert start["values"]["load_friction"] == start["load_friction"]
        profiles.append(result["values"])
    assert [s["load_friction"] for s in profile_starts] == [0.40, 0.45, 0.05]
    half = {"initial_pressure_fraction": 0.5}
    assert calibrate.previous_fits() == ({**ninth["fitted"], **half}, {**tenth["fitted"], **half}, *trials, *angles,
                                         *profiles)
    box = {f.name: f for f in FITTED}
    assert all(box[n].low <= v <= box[n].high for start in calibrate.previous_fits() for n, v in start.items())
    assert box["air_fraction"].high == 0.08 and ninth["bounds"]["air_fraction"]["high"] == 0.03
    ninth = {"fitted": {**ninth["fitted"], **half}}
    outside = dict(ninth["fitted"], air_fraction=0.09)
    with pytest.raises(ValueError, match="air_fraction lies outside the box"):
        calibrate.calibrate(workers=1, previous=[outside])
    short = {k: v for k, v in ninth["fitted"].items() if k != "leak_conductance"}
    with pytest.raises(ValueError, match="exactly the fitted parameters"):
        calibrate.calibrate(workers=1, previous=[short])
    with pytest.raises(ValueError, match="exactly the fitted parameters"):
        calibrate.calibrate(workers=1, previous=[dict(ninth["fitted"], extra=1.0)])


def test_the_committed_file_holds_the_further_starts_as_evaluated_and_its_ensemble_by_the_rule():
    """The thirteenth refit's file: its nineteen "previous" rows, after the simplex and before the profiles, are the
    further starts at exactly their values. The six earlier fits each cost what its own file says (to 1e-12: machines
    differ in the last bits) and are members; the ten start-angle sets cost what the trial printed (4 digits), the
    three profile refits what the trial's file keeps (to 1e-12), all within the noise. The ensemble is the rule's choice from the whole history (so which of the ten are members is the
    rule's, not picked by hand); made_by says so, and the file is of this version."""
    committed = json.loads(CALIBRATION_FILE.read_text())
    from twin.plants.as_built import NINTH_REFIT_FILE, TENTH_REFIT_FILE

    stages = [h["stage"] for h in committed["history"]]
    rows = [h for h in committed["history"] if h["stage"] == "previous"]
    first = stages.index("previous")
    assert stages[first:first + 19] == ["previous"] * 19 and "simplex" not in stages[first:] and "profile" not in stages[:first]
    assert [r["values"] for r in rows] == list(calibrate.previous_fits())
    kept = [json.loads(f.read_text())["cost"] for f in (NINTH_REFIT_FILE, TENTH_REFIT_FILE)] + [
        t["cost"] for t in _starts(calibrate.START_PRESSURE_REFITS_FILE)]
    assert [r["cost"] for r in rows[:6]] == pytest.approx(kept, rel=1e-12)
    printed = [t["cost_from_30_deg"] for t in _starts(calibrate.START_ANGLE_REFITS_FILE)]
    assert [r["cost"] for r in rows[6:16]] == pytest.approx(printed, abs=5e-5)
    assert [r["cost"] for r in rows[16:]] == pytest.approx([t["cost"] for t in _starts(calibrate.PROFILE_REFITS_FILE)], rel=1e-12)
    assert all(r["cost"] <= committed["cost"] + committed["noise"]["std"] for r in rows)  # within the noise
    members = [m["values"] for m in committed["ensemble"]]
    assert all(r["values"] in members for r in rows[:6])
    history = [calibrate.Evaluation(h["values"], h["cost"], h["stage"]) for h in committed["history"]]
    best = min(history, key=lambda e: e.cost)
    chosen = calibrate.choose_ensemble(history, best, committed["noise"]["std"])
    assert [(m["values"], m["cost"], m["stage"]) for m in committed["ensemble"]] == [
        (e.values, e.cost, e.stage) for e in chosen]
    assert committed["version"] == calibrate.FILE_VERSION == 11 and "further starts" in committed["made_by"]


def test_the_twelfth_refit_is_the_eleventh_with_ten_more_starts():
    """What the docs say of the twelfth refit against the eleventh's kept file: the same history but for the ten new
    "previous" rows (value for value, cost for cost, in order), so the same fitted values, cost and noise; two members
    differ, and they are the 25-deg fit's members 11 and 12."""
    from twin.plants.as_built import ELEVENTH_REFIT_FILE, TWELFTH_REFIT_FILE

    twelfth, eleventh = (json.loads(f.read_text()) for f in (TWELFTH_REFIT_FILE, ELEVENTH_REFIT_FILE))
    angles = [s["values"] for s in _starts(calibrate.START_ANGLE_REFITS_FILE)]
    _same_fit_but_for_the_new_starts(twelfth, eleventh, angles)
    new = [m["values"] for m in twelfth["ensemble"] if m not in eleventh["ensemble"]]
    assert new == [angles[8], angles[9]] and len(twelfth["ensemble"]) == len(eleventh["ensemble"]) == 13


def test_the_thirteenth_refit_is_the_twelfth_with_three_more_starts():
    """What the docs say of the thirteenth refit against the twelfth's kept file: the same history but for the three
    new "previous" rows, which come right after the twelfth's sixteen (value for value, cost for cost, in order), so
    the same fitted values, cost and noise; the members that differ are the rule's choice, among them the profile
    trial's sets at both ends of the load friction."""
    from twin.plants.as_built import TWELFTH_REFIT_FILE

    thirteenth, twelfth = (json.loads(f.read_text()) for f in (CALIBRATION_FILE, TWELFTH_REFIT_FILE))
    profiles = [s["values"] for s in _starts(calibrate.PROFILE_REFITS_FILE)]
    history = thirteenth["history"]
    _same_fit_but_for_the_new_starts(thirteenth, twelfth, profiles)
    first = [h["stage"] for h in history].index("previous")
    assert [h["values"] for h in history[first + 16:first + 19]] == profiles
    members = [m["values"] for m in thirteenth["ensemble"]]
    assert profiles[1] in members and profiles[2] in members  # the highest load friction under the cut, the lowest
    lows = [m["load_friction"] for m in members]
    assert (min(lows), max(lows)) == (0.05, 0.45) and len(members) == 13


def test_unit_box_maps_onto_the_plausible_bounds():
    assert values_at([0.0] * len(FITTED)) == {f.name: f.low for f in FITTED}
    assert values_at([1.0] * len(FITTED)) == {f.name: f.high for f in FITTED}
    assert values_at([2.0, -1.0, 0.5, 0.5, 0.5, 0.5, 0.5])[FITTED[0].name] == FITTED[0].high  # clipped, never outside
    u = (0.25, 0.5, 0.75, 1.0, 0.1, 0.6, 0.3)
    assert calibrate.unit_of(values_at(u)) == pytest.approx(u)


def test_the_breakaway_bound_is_what_245_kpa_could_start_from_rest():
    """§4.5.1: the joint broke away at 245 kPa with the pair at 100 %: every point of the map is below P A."""
    from twin.plants.as_built import STICTION_SCATTER
    from twin.plants.preset import THESIS_PARAMS

    (breakaway,) = [f for f in FITTED if f.name == "stiction"]
    assert breakaway.high + STICTION_SCATTER == pytest.approx(245e3 * THESIS_PARAMS.cylinder.bore_area)
    assert breakaway.high == pytest.approx(2.5788, abs=1e-4)


def test_the_ccw_scale_bound_is_what_the_slowest_full_duty_speed_allows():
    """§4.5.1: the rack ran at no less than 0.03 m/s (printed to 0.01, so 25 mm/s) with the pair at 100 % from
    245 kPa, both ways. Eq. 4.3.6's steady state, written out here from the thesis's equations (4.4.2, 4.5.5,
    4.5.7, 4 mm bore), not through the twin's code, runs the rack at 25 mm/s over 5-11 mm with the Coulomb level
    scaled by the box's top, faster below it and slower above."""
    from twin.plants.as_built import CCW_SCALE_BOUND, FULL_DUTY_WINDOW

    area = math.pi * 2e-3**2
    damping = 45.9 + 2 * 1.8372e14 * 100.0**-2.1706 * area**2  # F_v + R1 + R4 at 100 %, N s/m
    y = np.linspace(5e-3, 11e-3, 60001)
    coulomb = np.maximum(np.polyval((-3.051e14, 1.587e13, -3.244e11, 3.294e9, -1.727e7, 4.36e4, -39.551), y), 0.0)

    def speed(scale):
        return 6e-3 / np.trapezoid(damping / (245e3 * area - scale * coulomb), y)

    (ccw,) = [f for f in FITTED if f.name == "ccw_coulomb_scale"]
    assert ccw.high == CCW_SCALE_BOUND and FULL_DUTY_WINDOW == (5e-3, 11e-3)
    assert speed(ccw.high) == pytest.approx(0.025, rel=1e-4)
    assert speed(1.0) == pytest.approx(0.035, abs=5e-4) and speed(1.5) < 0.015  # the old top: 13 mm/s
    assert ccw.high == pytest.approx(1.269, abs=1e-3)


def test_committed_preset_is_inside_its_bounds_and_is_the_as_built_plant():
    from twin.plants.preset import THESIS_PARAMS

    values = calibrated_values()
    for f in FITTED:
        assert f.low <= values[f.name] <= f.high
    plant = as_built_plant()
    assert plant.params.friction.stiction == values["stiction"]
    assert plant.params.chambers.air_fraction == values["air_fraction"]
    assert plant.params.friction.ccw_coulomb_scale == values["ccw_coulomb_scale"]
    assert plant.params.chambers.leak_conductance == values["leak_conductance"]
    assert plant.params.friction.load_friction == values["load_friction"]
    assert plant.params.observer.gain == values["observer_gain"]
    assert as_built_plant(without=["experiment_gains"]).params.observer.gain == THESIS_PARAMS.observer.gain
    assert plant.valve_model is ValveModel.SOLENOID
    members = ensemble_values()
    assert members[0] == values and all(all(f.low <= m[f.name] <= f.high for f in FITTED) for m in members)


def test_a_value_outside_its_bounds_is_refused(tmp_path):
    record = json.loads(CALIBRATION_FILE.read_text())
    record["fitted"]["air_fraction"] = 0.5
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(record))
    with pytest.raises(InvalidScenario, match="air_fraction = 0.5 is outside"):
        calibrated_values(path)
    record = json.loads(CALIBRATION_FILE.read_text())
    record["ensemble"][-1]["values"]["stiction"] = 3.0  # past what 245 kPa could start
    path.write_text(json.dumps(record))
    calibrated_values(path)  # the fitted values are fine
    with pytest.raises(InvalidScenario, match=r"stiction = 3.0 is outside .*ensemble member"):
        ensemble_values(path)


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


def _moves_on_the_round_trip(values: dict[str, float]) -> bool:
    """Whether ``values`` come back other than they went in through the unit box (:func:`calibrate.unit_of`,
    then :func:`calibrate.values_at`): a start evaluated through the box would then not be evaluated as given."""
    return calibrate.values_at(calibrate.unit_of(values)) != values


class _SumOfSquares:
    """A stand-in for :class:`calibrate.Evaluator`: one "cell", the squared distance of the values from a point
    inside the unit box, so a fit's stages run in a blink. It appends the values it is asked for to ``asked``."""

    def __init__(self, asked: list[dict[str, float]]):
        self.asked = asked

    def __enter__(self):
        return self

    def __exit__(self, *error):
        pass

    def cells(self, values, *, seeds=None):
        self.asked.append(dict(values))
        return [float(np.sum((np.array(calibrate.unit_of(values)) - 0.3) ** 2))]


def test_a_fit_evaluates_every_further_start_at_exactly_its_values_by_default(monkeypatch):
    """With no ``previous`` given, the fit evaluates all of :func:`calibrate.previous_fits`, in order and as given
    (not through the unit box), after the simplex and before the noise and the profiles. The slow test below runs
    the real cells on two of them only."""
    asked: list[dict[str, float]] = []
    monkeypatch.setattr(calibrate, "Evaluator", lambda *, seeds, workers: _SumOfSquares(asked))
    monkeypatch.setattr(calibrate, "cost", lambda cells: cells[0])
    result = calibrate.calibrate(workers=1, fit_seeds=(0,), check_seeds=(), noise_seed_sets=((1,),), scan_points=1,
                                 simplex_evaluations=1, profile_points=2)
    starts = list(calibrate.previous_fits())
    n = len(starts)
    # "exactly" has teeth only if some start's values move on the unit box's round trip
    assert any(_moves_on_the_round_trip(s) for s in starts)
    assert [e.stage for e in result.history] == ["scan", "scan", "simplex"] + ["previous"] * n + ["profile"] * 12
    assert [e.values for e in result.history[3:3 + n]] == starts == asked[3:3 + n]
    # then the noise (not in the history) at the best values so far, then the profiles
    assert asked[3 + n] == min(result.history[:3 + n], key=lambda e: e.cost).values
    assert result.evaluations == 3 + n + 12 and len(asked) == 3 + n + 1 + 12


@pytest.mark.slow  # 67 s alone on 2 cores with two further starts, 128 s with all nineteen (stop 57's machine)
def test_same_seeds_same_fit_whatever_the_workers():
    """One worker or two, the same fit, through every stage: two of the further starts, the first and the first
    whose values move on the unit box's round trip (the fast test above holds all of them, in order and at
    exactly their values, with a stand-in for the cells)."""
    starts = calibrate.previous_fits()
    two_starts = (starts[0], next(s for s in starts[1:] if _moves_on_the_round_trip(s)))
    small = dict(fit_seeds=(0, 1), check_seeds=(0,), noise_seed_sets=((2, 3),), scan_points=1,
                 simplex_evaluations=1, profile_points=2, previous=two_starts)
    one = calibrate.calibrate(workers=1, **small)
    two = calibrate.calibrate(workers=2, **small)
    assert one.values == two.values and one.cost == two.cost and one.noise_costs == two.noise_costs
    assert [e.values for e in one.history] == [e.values for e in two.history]
    # the two further starts, evaluated at exactly their values, then two points along each profiled parameter
    # (the load friction, the breakaway, the observer gain, the CCW scale, the air, the start pressure)
    assert [e.stage for e in one.history] == ["scan", "scan", "simplex"] + ["previous"] * 2 + ["profile"] * 12
    assert [e.values for e in one.history[3:5]] == list(two_starts) and one.evaluations == 17
    assert one.ensemble[0].values == one.values
    # The check seed 0 is one of the fit's: its cells are cut from the fit's runs and equal a run of seed 0.
    alone = calibrate.Evaluator(seeds=(0,), workers=1).cells(one.values)
    assert [c.rmse_deg for c in one.check_cells] == [c.rmse_deg for c in alone]


@pytest.mark.slow  # over ~2.5 s on 2 cores
def test_calibrate_retraces_the_committed_fit():
    """The same seeds give the same numbers: the fit's first evaluation (the centre of the box) costs
    what the committed file says. The whole fit (8 min on 2 cores on 2026-11-25's machine, 14.5 min on
    2026-11-26's) is ``twin calibrate --out DIR``; its file is the committed one (see docs/as-built.md). On
    2026-11-26's machine (the same numpy 2.4.6, numba 0.68.1 and mujoco 3.17.0, another CPU) the eighth
    refit's file, written on the other machine, cost 0.9140406738291886 against its 0.914040673829233: the
    last bits of floating point differ between machines. So the cost is held to 1e-12 of itself (a change to
    the model or the cost moves it by far more); the values stay exact."""
    committed = json.loads(CALIBRATION_FILE.read_text())
    result = calibrate.calibrate(workers=2, scan_points=0, simplex_evaluations=0, profile_points=0,
                                 noise_seed_sets=(), check_seeds=(), previous=())
    (first,) = result.history
    assert first.values == committed["history"][0]["values"]
    assert first.cost == pytest.approx(committed["history"][0]["cost"], rel=1e-12, abs=0.0)

