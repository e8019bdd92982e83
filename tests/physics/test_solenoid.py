"""The solenoid valve against closed forms, and its replica of the thesis's valve test (§4.4.3)."""

from __future__ import annotations

import csv
import dataclasses
import math
from fractions import Fraction

import numpy as np
import pytest

from twin.cli import main
from twin.experiments.studies import valve
from twin.physics import solenoid
from twin.physics.params import NOMINAL_PARAMS, SolenoidParams, ValveTestRigParams

P = SolenoidParams()
RIG = ValveTestRigParams()
H = P.step


def test_coil_current_rises_and_decays_exponentially():
    ticks = 2000
    on, _ = solenoid.simulate(P, np.ones(ticks), h=H)
    t = np.arange(1, ticks + 1) * H
    assert np.allclose(on[:, 0], 1 - np.exp(-t / P.coil_time_constant_on), atol=1e-12)
    off, _ = solenoid.simulate(P, np.zeros(ticks), h=H, state=np.array([1.0, 1.0, 0.0, 1.0]))
    assert np.allclose(off[:, 0], np.exp(-t / P.coil_time_constant_off), atol=1e-12)


def test_the_plunger_moves_once_the_magnetic_force_beats_the_preload():
    """Pull-in: f_m i^2 / (1 + kappa)^2 = 1 with i = 1 - exp(-t / tau_on)."""
    pull_in = -P.coil_time_constant_on * math.log(1 - (1 + P.gap_ratio) / math.sqrt(P.force_ratio))
    states, _ = solenoid.simulate(P, np.ones(3000), h=H)
    first_lift = (np.flatnonzero(states[:, 1] > 0)[0] + 1) * H
    assert first_lift == pytest.approx(pull_in, abs=2 * H)


def test_largest_lift_is_none_for_a_pulse_that_ends_before_pull_in_and_full_for_a_held_coil():
    """Pull-in as above: a coil pulse that ends before it cannot move the plunger; one held on the
    whole period lifts it to the travel stop."""
    period = NOMINAL_PARAMS.valves.pwm_period
    pull_in = -P.coil_time_constant_on * math.log(1 - (1 + P.gap_ratio) / math.sqrt(P.force_ratio))
    assert solenoid.largest_lift(P, (pull_in - 2 * H) / period * 100, period=period, h=H) == 0.0
    assert solenoid.largest_lift(P, (pull_in + 20 * H) / period * 100, period=period, h=H) > 0.0
    assert solenoid.largest_lift(P, 100.0, period=period, h=H) == 1.0


def test_held_open_it_passes_the_open_valve_flow_after_the_column_accelerates():
    """tau_I dq/dt = 1 - q with the valve open: q = 1 - exp(-t / tau_I) (implicit Euler, within 0.5 %)."""
    ticks = 3000
    states, _ = solenoid.simulate(P, np.ones(ticks), h=H, inertance_time=RIG.inertance_time,
                                  state=np.array([1.0, 1.0, 0.0, 0.0]))
    t = np.arange(1, ticks + 1) * H
    assert np.allclose(states[:, 3], 1 - np.exp(-t / RIG.inertance_time), atol=5e-3)
    assert states[-1, 3] == pytest.approx(1.0, abs=1e-4)  # 10 time constants in


def test_shut_it_passes_nothing_and_coil_off_keeps_it_shut():
    states, _ = solenoid.simulate(P, np.zeros(5000), h=H, inertance_time=RIG.inertance_time)
    assert not states[:, 1:].any()


def test_a_full_pulse_gives_the_thesis_delays_within_1_ms():
    """The issue's bar. The delays are among what ``valve_fit`` aimed the parameters at, so this checks that the
    committed values still reach the fit's targets; it is not a prediction of the valve."""
    opening, closing = solenoid.delays(P, h=H)
    assert abs(opening - 5e-3) <= 1e-3 and abs(closing - 2e-3) <= 1e-3


def test_a_pulse_under_the_dead_zone_lifts_nothing_and_passes_no_flow():
    """The issue's bar; no lift from a 25 % pulse is one of ``valve_fit``'s targets (see the delays' test)."""
    ticks = int(round(NOMINAL_PARAMS.valves.pwm_period / H))
    states, _ = solenoid.simulate(P, solenoid.coil_command(25.0, ticks), h=H, periods=5,
                                  inertance_time=RIG.inertance_time)
    assert states[:, 1].max() == 0.0 and states[:, 3].max() == 0.0
    assert 25.0 < valve.emergent_dead_zone() <= 30.0


def test_the_replica_follows_eq_4_4_2_within_15_percent_from_35_to_100_percent():
    """The issue's bar, on the duties ``valve_fit`` fitted R(d) at (see the delays' test)."""
    outcome = valve.valve_study()
    ratios = {r["duty_pct"]: r["resistance_twin_pa_s_per_m3"] / r["resistance_eq442_pa_s_per_m3"]
              for r in outcome.rows}
    assert [d for d, x in ratios.items() if d >= 35 and abs(x - 1) > 0.15] == []
    assert ratios[100.0] == pytest.approx(1.0, rel=1e-9)  # the open valve: by construction


def test_the_replica_is_converged_in_the_integration_step():
    halved = dataclasses.replace(P, step=P.step / 2)
    for duty in (35.0, 50.0, 80.0, 95.0):
        coarse, fine = (solenoid.mean_flow_fraction(p, duty, period=16e-3, h=p.step, inertance_time=RIG.inertance_time)
                        for p in (P, halved))
        assert fine == pytest.approx(coarse, rel=0.01)


def test_the_line_fit_gives_the_closed_form_least_squares_line_exactly():
    # (0, 1), (1, 3), (2, 2): x mean 1, y mean 2, slope (-1 * -1 + 1 * 0) / 2 = 1/2, intercept 2 - 1/2 = 3/2
    assert valve.line_fit([0.0, 1.0, 2.0], [1.0, 3.0, 2.0]) == (Fraction(1, 2), Fraction(3, 2))
    # the rig's drops with flows exactly proportional to them (k a power of two): slope k, intercept 0, no rounding
    k = 2.0 ** -40
    assert valve.line_fit(RIG.pressure_drops, [k * d for d in RIG.pressure_drops]) == (Fraction(k), 0)


def test_the_replica_fits_its_line_without_blas(monkeypatch):
    """R(d) must not turn on which BLAS kernel numpy loads (see docs/testing.md): the fit calls neither of numpy's
    least-squares routines, which go to it."""
    def refused(*args, **kwargs):
        raise AssertionError("a BLAS least-squares fit")

    monkeypatch.setattr(np, "polyfit", refused)
    monkeypatch.setattr(np.linalg, "lstsq", refused)
    resistance, flows = valve.replica(60.0)
    slope, _ = valve.line_fit(RIG.pressure_drops, flows)
    assert resistance == float(1 / slope) and math.isfinite(resistance)


def test_cli_writes_the_valve_table_and_plot(tmp_path):
    assert main(["study", "valve", "--out", str(tmp_path / "v")]) == 0
    with open(tmp_path / "v" / "valve.csv") as handle:
        rows = list(csv.DictReader(handle))
    assert list(rows[0]) == ["duty_pct", "resistance_eq442_pa_s_per_m3", "resistance_twin_pa_s_per_m3"]
    assert [float(r["duty_pct"]) for r in rows] == list(range(30, 101, 5))
    assert (tmp_path / "v" / "valve.png").read_bytes()[:4] == b"\x89PNG"


def _bank(n: int = 1):
    from twin.physics.params import ValveParams
    from twin.physics.valves import ValveBank, ValveModel

    return ValveBank(params=ValveParams(dead_zone_duty=0.0), model=ValveModel.SOLENOID, n=n, tick=1e-3)


def test_in_the_plant_a_pulse_under_the_dead_zone_never_opens_the_drain():
    bank = _bank()
    drains = [bank.update(k, np.array([20.0]))[0, 3] for k in range(160)]  # 20 %: 3.2 ms pulses, ten periods
    assert max(drains) == 0.0
    bank.reset()
    supply = [bank.update(k, np.array([20.0]))[0, 0] for k in range(160)]
    assert supply[-1] == pytest.approx(bank.full_conductance)  # the pair's supply valve is held on


def test_in_the_plant_a_full_command_opens_after_the_opening_delay():
    bank = _bank()
    drain = np.array([bank.update(k, np.array([100.0]))[0, 3] for k in range(12)]) / bank.full_conductance
    assert drain[3] == 0.0 and drain[5] > 0.0 and drain[6] == pytest.approx(1.0)  # 5 ms, as the replica's
    assert all(bank.update(k, np.array([100.0]))[0, [1, 2]].max() == 0.0 for k in range(12, 20))  # V2, V3 shut


def test_the_drain_coil_follows_the_duty_in_force_inside_the_period():
    """Sliding mode's 1 ms updates: the discharge coil is on while the period's elapsed ticks are below
    the duty now in force (the thesis's hardware)."""
    from twin.physics.valves import _solenoid_coils

    coil = np.zeros((1, 4))
    on = []
    for k, duty in enumerate([50.0] * 4 + [10.0] * 4 + [90.0] * 8):  # one 16 ms period
        _solenoid_coils(np.array([duty]), k, 16, 16, coil)
        on.append(coil[0, 3])
    assert on == [1.0] * 4 + [0.0] * 4 + [1.0] * 6 + [0.0] * 2


def test_the_solenoid_preset_runs_without_warnings():
    from twin.envs.runner import run
    from twin.sim.scenario import Scenario

    result = run(Scenario("smc", 1, plant="thesis-solenoid"))
    assert not result.warnings and math.degrees(result.metrics.rmse) < 10.0


def test_the_plant_kernel_equals_stepping_every_sub_step_bit_for_bit():
    """``tick_openings`` skips the plunger's arithmetic for a valve held on its stop, and every step
    once the coil current has settled to its last bit; over holds long enough for both (coil on 0.3 s,
    off 2 s: the off current takes ~1.3 s to reach its smallest value), then pulses, its states and
    each tick's mean opening must be the bits that :func:`solenoid.simulate` gives step by step."""
    substeps = int(round(1e-3 / H))
    coil = [1.0] * 300 + [0.0] * 2000 + ([1.0] * 6 + [0.0] * 10) * 20
    ticks = np.repeat(np.array(coil), substeps)
    stepped, _ = solenoid.simulate(P, ticks, h=H)
    state = np.zeros((1, 1, 3))
    opening = np.empty((1, 1))
    live = np.ones(1, dtype=np.bool_)
    for k, s in enumerate(coil):
        solenoid.tick_openings(np.array([[s]]), substeps, H, P.coil_time_constant_on, P.coil_time_constant_off,
                               P.force_ratio, P.gap_ratio, P.spring_ratio, P.natural_frequency, P.damping_ratio,
                               state, opening, live)
        lifts = stepped[k * substeps:(k + 1) * substeps, 1]
        total = 0.0
        for x in lifts:  # the kernel's order of addition
            total += x
        assert opening[0, 0] == total / substeps, k
        assert tuple(state[0, 0]) == tuple(stepped[(k + 1) * substeps - 1, :3]), k
    current = stepped[:, 0]
    for start, end in ((0, 300), (300, 2300)):  # each hold's current settled well before its end: the shortcut ran
        assert current[(end - 100) * substeps] == current[end * substeps - 1]
        assert current[start * substeps] != current[end * substeps - 1]
