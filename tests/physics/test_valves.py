"""The valve bank tick by tick against the delays, dead zone and PWM of SPEC §3.

Ticks are 1 ms; ``update(k, duty)`` is called at k = 0, 1, 2, ... with the coils
off before tick 0. The delays of §3: a valve opens 5 ms (5 ticks) after its coil
turns on and shuts 2 ms (2 ticks) after its coil turns off.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from twin.physics.params import CylinderParams, ValveParams
from twin.physics.valves import ValveBank, ValveModel

TICK = 1e-3  # s
V1, V2, V3, V4 = range(4)  # supply A, drain A, supply B, drain B (§3)
R_COEFF, R_EXP = 1.8372e14, -2.1706  # eq. 4.4.2, Pa s/m^3


def r_of(duty_percent: float) -> float:
    """Eq. 4.4.2 written out: R(d) = 1.8372e14 d^-2.1706."""
    return R_COEFF * duty_percent**R_EXP


FULL = 1.0 / r_of(100.0)  # conductance of a fully open valve, m^3/(Pa s)


def drive(model: ValveModel, commands, *, dead_zone: float = 30.0, hold_supply: bool = False) -> np.ndarray:
    """Conductances (ticks, 4) for one scenario given the command at each tick."""
    bank = ValveBank(params=ValveParams(dead_zone_duty=dead_zone, supply_held_in_dead_zone=hold_supply),
                     model=model, n=1, tick=TICK)
    return np.array([bank.update(k, np.array([float(u)]))[0] for k, u in enumerate(commands)])


def test_full_command_opens_supply_a_and_drain_b_after_exactly_5_ms():
    g = drive(ValveModel.PWM, [100.0] * 20)
    is_open = g > 0
    assert not is_open[:5].any()  # ticks 0..4: opening delay of 5 ms
    assert is_open[5:, V1].all() and is_open[5:, V4].all()
    assert not is_open[:, V2].any() and not is_open[:, V3].any()
    assert g[5:, V1] == pytest.approx(FULL, rel=1e-12)  # a fully open valve is R(100 %)
    assert g[5:, V4] == pytest.approx(FULL, rel=1e-12)


def test_valves_shut_exactly_2_ms_after_the_command_drops():
    g = drive(ValveModel.PWM, [100.0] * 20 + [0.0] * 10)
    is_open = g > 0
    # Coil off from tick 20: still open at 20 and 21, shut from tick 22 (2 ms closing delay).
    assert is_open[20:22, V1].all() and is_open[20:22, V4].all()
    assert not is_open[22:].any()


def test_negative_command_uses_the_other_pair():
    g = drive(ValveModel.PWM, [-100.0] * 20)
    is_open = g > 0
    assert not is_open[:5].any()
    assert is_open[5:, V3].all() and is_open[5:, V2].all()
    assert not is_open[:, V1].any() and not is_open[:, V4].any()


@pytest.mark.parametrize("model", [ValveModel.PWM, ValveModel.AVERAGED])
@pytest.mark.parametrize("command", [25.0, -25.0])
def test_command_inside_the_30_percent_dead_zone_never_opens_anything(model, command):
    g = drive(model, [command] * 100, dead_zone=30.0)
    assert not (g > 0).any()


@pytest.mark.parametrize("model", [ValveModel.PWM, ValveModel.AVERAGED])
@pytest.mark.parametrize(("command", "supply", "others"), [(25.0, V1, [V2, V3, V4]), (-25.0, V3, [V1, V2, V4])])
def test_held_supply_valve_opens_inside_the_dead_zone_and_the_drain_stays_shut(model, command, supply, others):
    """§3: the pair's supply valve "stays fully on"; only the discharge valve's pulses are too short."""
    g = drive(model, [command] * 40, dead_zone=30.0, hold_supply=True)
    assert not (g[:5] > 0).any()  # the supply valve has its opening delay too
    assert g[5:, supply] == pytest.approx(FULL, rel=1e-12)
    assert not (g[:, others] > 0).any()


def test_held_supply_shuts_at_zero_command_and_switches_pair_with_the_sign():
    g = drive(ValveModel.AVERAGED, [20.0] * 10 + [0.0] * 10 + [-20.0] * 10, dead_zone=30.0, hold_supply=True)
    is_open = g > 0
    assert is_open[5:12, V1].all() and not is_open[12:, V1].any()  # coil off at tick 10, shut 2 ms later
    assert not is_open[:25, V3].any() and is_open[25:, V3].all()
    assert not is_open[:, [V2, V4]].any()


def test_held_supply_changes_nothing_above_the_dead_zone():
    commands = [50.0] * 40 + [-80.0] * 40 + [100.0] * 20
    for model in ValveModel:
        np.testing.assert_array_equal(drive(model, commands, hold_supply=True), drive(model, commands))


def test_half_duty_pwm_opens_the_drain_valve_5_of_16_ticks():
    """50 % of the 16-tick period: the drain coil is on for ticks m = 0..7 of each period
    (m = k mod 16) and off for m = 8..15. The valve opens 5 ticks after the coil turns on
    (m = 5) and shuts 2 ticks after it turns off (m = 10), so it is open for m = 5..9:
    5 ticks = 8 on - 5 opening delay + 2 closing delay. (The rule in the first version of
    twin/valves.py, open[k] = coil[k - 5] and coil[k - 2], gives the same: coil[k-5] on
    <=> m in 5..12, coil[k-2] on <=> m in 2..9, both <=> m in 5..9.)
    The supply valve's coil is on all the time, so it stays open after the first 5 ticks."""
    g = drive(ValveModel.PWM, [50.0] * (16 * 8), dead_zone=30.0)
    is_open = g > 0
    steady = is_open[32:]  # whole periods after start-up
    drain = steady[:, V4].reshape(-1, 16)
    expected_period = np.zeros(16, dtype=bool)
    expected_period[5:10] = True
    assert (drain == expected_period).all()
    assert drain.sum(axis=1).tolist() == [5] * drain.shape[0]
    assert steady[:, V1].all()
    assert not steady[:, V2].any() and not steady[:, V3].any()


def test_short_coil_gap_does_not_make_the_valve_chatter():
    """Coil on for ticks 0..19, off at tick 20 only, on again from tick 21: a gap shorter
    than the 2 ms closing delay never shuts an open valve (§3), so it stays open throughout."""
    g = drive(ValveModel.PWM, [100.0] * 20 + [0.0] + [100.0] * 15)
    drain_open = g[:, V4] > 0
    assert drain_open[5:].all(), drain_open.astype(int).tolist()
    assert not drain_open[:5].any()


def test_coil_pulse_shorter_than_the_opening_delay_never_opens_the_drain():
    """25 % of 16 ticks = a 4 ms coil pulse per period, shorter than the 5 ms opening delay
    (§3): with no dead zone the pulse is sent, but the drain valve never opens.
    The supply valve of the pair is on all the time and does open."""
    g = drive(ValveModel.PWM, [25.0] * 160, dead_zone=0.0)
    assert not (g[:, V4] > 0).any()
    assert (g[5:, V1] > 0).all()


def test_averaged_model_below_half_a_tick_of_duty_opens_nothing():
    """With a 16-tick period the coil realises duties in steps of 100/16 = 6.25 %;
    3 % is under half a step and rounds to 0 ticks: no valve is energised."""
    g = drive(ValveModel.AVERAGED, [3.0] * 40, dead_zone=0.0)
    assert not (g > 0).any()


def test_averaged_model_quantises_duty_to_whole_ticks():
    """10 % of 16 ticks is 1.6 ticks -> 2 ticks = 12.5 %: the drain conductance is 1/R(12.5 %)."""
    g = drive(ValveModel.AVERAGED, [10.0] * 40, dead_zone=0.0)
    assert not (g[:5] > 0).any()
    assert g[5:, V4] == pytest.approx(1.0 / r_of(12.5), rel=1e-9)
    assert g[5:, V1] == pytest.approx(FULL, rel=1e-9)  # the supply valve of the pair is fully on
    assert not (g[:, [V2, V3]] > 0).any()


def test_open_valve_damping_is_about_1_3_newton_seconds_per_metre():
    """SPEC §4: R(100 %) A^2 ~ 1.3 N s/m per valve (R in Pa s/m^3)."""
    area = CylinderParams().bore_area
    assert area == pytest.approx(math.pi * 0.002**2, rel=1e-12)
    assert ValveParams().resistance(100.0) * area**2 == pytest.approx(1.3, abs=0.05)
    assert ValveParams().resistance(100.0) == pytest.approx(r_of(100.0), rel=1e-12)
