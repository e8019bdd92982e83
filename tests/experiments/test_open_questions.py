"""The open-question what-ifs (SPEC §10): pva-rate, observer and next-experiment. Their pieces against
what they must do (the controllers' update periods, the valves untouched, the refit's weights), and
each command end to end on a small ensemble."""

from __future__ import annotations

import csv
import math

import numpy as np
import pytest

from twin.cli import main
from twin.exceptions import InvalidScenario
from twin.experiments.whatifs import next_experiment, observer, pva_rate
from twin.plants import plant


def rows_of(path) -> list[dict]:
    with path.open() as handle:
        return list(csv.DictReader(handle))


@pytest.mark.parametrize("name, field", [("ffpva", "period"), ("smc", "slow_period")])
def test_pva_rate_changes_the_ff_pva_update_alone(name, field):
    base = plant("as-built")
    fast, thesis = pva_rate.controller_at(name, 2, base), pva_rate.controller_at(name, 16, base)
    assert getattr(fast, field) == pytest.approx(2e-3)
    assert getattr(thesis, field) == pytest.approx(base.params.valves.pwm_period)
    if name == "smc":
        assert fast.period == thesis.period == pytest.approx(1e-3)  # the switching term stays at 1 ms
    assert fast.gains == thesis.gains and fast.nominal == thesis.nominal


def test_pva_rate_rates_flag():
    assert pva_rate.parse_rates("1,4") == (1, 4, 16)
    for bad in ("0", "a,b", "65", ""):
        with pytest.raises(InvalidScenario, match="--rates"):
            pva_rate.parse_rates(bad)


def test_observer_variant_changes_only_the_observer():
    base = plant("as-built")
    kalman = observer.with_observer(base, "kalman")
    assert kalman.params.observer.kind == "kalman"
    assert kalman.params == base.params.__class__(**{**base.params.__dict__, "observer": kalman.params.observer})


def test_weighted_band_is_the_inverse_distribution():
    values = np.array([3.0, 1.0, 2.0, 5.0, 4.0])
    assert next_experiment.weighted_band(values, np.ones(5)) == pytest.approx(4.0)  # 1/5 > 10 %: all of them
    assert next_experiment.weighted_band(values, np.array([0, 0, 1, 0, 0.0]) + 1e-12) == pytest.approx(0.0)
    assert next_experiment.weighted_band(values, np.array([0, 1, 1, 0, 0.0])) == pytest.approx(1.0)  # 1 and 2


def test_refit_narrows_with_a_telling_measurement_and_not_with_a_blind_one():
    rng = np.random.default_rng(5)
    members, seeds = 6, 4
    predictions = np.linspace(1.0, 2.0, members)[:, None] * np.ones((1, 3))
    telling = np.arange(members)[:, None] * 10.0 + rng.normal(0, 0.1, (members, seeds))  # members 10 sigma apart
    blind = rng.normal(0, 1.0, (members, seeds))  # the same for every member
    before, after, sigma = next_experiment.refit_widths(telling, predictions)
    assert sigma == pytest.approx(0.1, rel=0.5)
    np.testing.assert_allclose(before, 1.0)
    np.testing.assert_allclose(after, 0.0, atol=1e-9)
    _, after_blind, _ = next_experiment.refit_widths(blind, predictions)
    assert np.all(after_blind > 0.5)


@pytest.mark.slow  # breakaway ladders and a sine on two members: ~10 s on 2 cores
def test_breakaway_map_reads_each_members_breakaway():
    """The virtual map's mean threshold is the member's breakaway over the bore area, to within a step
    and the map's scatter averaged over the positions."""
    from twin.plants.as_built import ensemble_plants

    members = ensemble_plants()[:2]
    step = 10e3
    for member in members:
        runs = next_experiment.breakaway_batch(member, ((step,),), (100, 101))
        expected = member.params.friction.stiction / member.params.cylinder.bore_area
        for s in (100, 101):
            # The first step at or above the breakaway pressure; the 0.5 N map scatter averages over 8
            # positions to a std of ~8 kPa; three of those plus a step.
            assert abs(runs["breakaway-map", s] - expected) < step + 3 * 0.5 / math.sqrt(3 * 8) / 1.2566e-5


@pytest.mark.slow  # loaded breakaway ladders on two members: ~5 s on 2 cores
def test_loaded_breakaway_map_reads_breakaway_plus_the_load_and_its_friction():
    """With 13.5 g on the vertical link the pair must break away and lift: at each rest position theta
    the threshold is (F_s + (1 + mu_L) G(theta)) / A, G = (m L + m_link L / 2) g sin(theta) / r_s, so
    members that differ only in their load friction read apart by (mu_1 - mu_2) mean(G) / A."""
    from twin.plants.as_built import as_built_plant, calibrated_values

    step = 5e3
    theta = np.radians(next_experiment.MAP_ANGLES_DEG)
    readings = {}
    for mu in (0.0, 0.45):
        member = as_built_plant({**calibrated_values(), "load_friction": mu}, name=f"as-built mu {mu}")
        p = member.params
        gravity = ((next_experiment.LOADED_PAYLOAD + p.masses.link_mass / 2) * p.masses.link_length * p.gravity
                   * np.sin(theta) / p.gears.spur_radius)
        expected = np.mean((p.friction.stiction + (1 + mu) * gravity) / p.cylinder.bore_area)
        runs = next_experiment.breakaway_batch(member, ((step,),), (100, 101), loaded=True)
        readings[mu] = np.array([runs["loaded-breakaway-map", s] for s in (100, 101)])
        for reading in readings[mu]:
            # the first step at or above it; the map's 0.5 N scatter averages over 8 positions to ~6 kPa
            assert abs(reading - expected) < step + 3 * 0.5 / math.sqrt(3 * 8) / p.cylinder.bore_area
    gap = 0.45 * np.mean(gravity) / p.cylinder.bore_area  # the same seeds: the same maps
    np.testing.assert_allclose(readings[0.45] - readings[0.0], gap, atol=step)


@pytest.mark.slow  # three commands on a small ensemble: ~40 s on 2 cores
def test_open_question_commands_write_csv_plot_and_answer(tmp_path, capsys):
    assert main(["whatif", "pva-rate", "--out", str(tmp_path / "rate"), "--members", "2", "--seeds", "1",
                 "--rates", "2"]) == 0
    rows = rows_of(tmp_path / "rate" / "pva-rate.csv")
    assert list(rows[0]) == list(pva_rate.COLUMNS)
    assert len(rows) == 2 * 14 * 2  # two controllers, 14 cells, 2 and 16 ms
    assert all(float(r["band_p10"]) <= float(r["band_p90"]) for r in rows)
    assert "sliding mode unnecessary" in (tmp_path / "rate" / "pva-rate.txt").read_text()

    assert main(["whatif", "observer", "--out", str(tmp_path / "obs"), "--members", "2", "--seeds", "1"]) == 0
    rows = rows_of(tmp_path / "obs" / "observer.csv")
    assert list(rows[0])[:7] == ["controller", "trajectory", "observer", "velocity_rms_error_mm_s", "rmse_mean_deg",
                                 "band_p10", "band_p90"]
    assert {r["observer"] for r in rows} == {"first-order", "kalman"} and len(rows) == 16
    assert all(float(r["velocity_rms_error_mm_s"]) > 0 for r in rows)

    assert main(["whatif", "next-experiment", "--out", str(tmp_path / "next"), "--members", "2", "--seeds", "2",
                 "--prediction-seeds", "1"]) == 0
    rows = rows_of(tmp_path / "next" / "next-experiment.csv")
    assert list(rows[0])[:4] == ["experiment", "cell", "band_width_before_deg", "band_width_after_deg"]
    assert {r["experiment"] for r in rows} == set(next_experiment.EXPERIMENTS)
    assert all(float(r["band_width_after_deg"]) <= float(r["band_width_before_deg"]) + 1e-9 for r in rows)
    out = capsys.readouterr().out
    assert "Answer: run the" in out
    for name in ("rate/pva-rate.png", "obs/observer.png", "next/next-experiment.png"):
        assert (tmp_path / name).stat().st_size > 10_000


@pytest.mark.parametrize("argv, flag", [
    (["whatif", "pva-rate", "--rates", "0"], "--rates"),
    (["whatif", "observer", "--members", "99"], "--members"),
    (["whatif", "next-experiment", "--seeds", "1"], "--seeds"),
    (["whatif", "next-experiment", "--pressure-step", "0.1"], "--pressure-step"),
])
def test_open_question_commands_refuse_bad_input_and_write_nothing(tmp_path, capsys, argv, flag):
    out = tmp_path / "out"
    assert main([*argv, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert flag in err and len(err.strip().splitlines()) == 1
    assert not out.exists() or not any(out.iterdir())
