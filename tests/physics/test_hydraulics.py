"""The valve network and the implicit rack step against closed forms (SPEC §3, §4, eq. 4.4.1)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from twin.physics.hydraulics import circuit, rack_step
from twin.physics.params import FrictionParams

AREA = math.pi * 0.002**2  # m^2, 4 mm bore (§2)
P_WS = 300e3  # Pa
R1 = 1.8372e14 * 100.0**-2.1706  # Pa s/m^3, a valve fully on (eq. 4.4.2)
R4 = 1.8372e14 * 50.0**-2.1706  # Pa s/m^3, the drain valve at 50 %
H = 1e-3  # s

NO_FRICTION = FrictionParams(viscous=0.0, stiction=0.0, coulomb_poly=(0.0,) * 7)


def one(*conductances: float) -> np.ndarray:
    return np.array([conductances], dtype=float)


def test_v1_and_v4_open_give_eq_4_4_1():
    """M y'' = P_ws A - (R1 + R4) A^2 y' - F_l: drive P_ws A, damping (R1 + R4) A^2."""
    c = circuit(one(1 / R1, 0.0, 0.0, 1 / R4), np.array([P_WS]), AREA)
    assert c.drive[0] == pytest.approx(P_WS * AREA, rel=1e-12)
    assert c.damping[0] == pytest.approx((R1 + R4) * AREA**2, rel=1e-12)
    assert not c.sealed[0]


def test_v3_and_v2_open_drive_the_other_way():
    c = circuit(one(0.0, 1 / R4, 1 / R1, 0.0), np.array([P_WS]), AREA)
    assert c.drive[0] == pytest.approx(-P_WS * AREA, rel=1e-12)
    assert c.damping[0] == pytest.approx((R1 + R4) * AREA**2, rel=1e-12)


@pytest.mark.parametrize("g", [
    (0.0, 0.0, 0.0, 0.0),  # every valve shut
    (1 / R1, 0.0, 0.0, 0.0),  # only V1: chamber B sealed
    (0.0, 0.0, 0.0, 1 / R1),  # only V4: chamber A sealed
    (1 / R1, 1 / R1, 0.0, 0.0),  # only side A connected
    (0.0, 0.0, 1 / R1, 1 / R1),  # only side B connected
])
def test_a_sealed_chamber_locks_the_joint(g):
    c = circuit(one(*g), np.array([P_WS]), AREA)
    assert math.isinf(c.damping[0])
    assert c.sealed[0]


def test_all_four_valves_equally_open_balance():
    c = circuit(one(*(4 * [1 / R1])), np.array([P_WS]), AREA)
    assert c.drive[0] == pytest.approx(0.0, abs=1e-12)
    # Each chamber: two valves R1 in parallel to flow, 1/(2/R1) each side.
    assert c.damping[0] == pytest.approx(AREA**2 * R1, rel=1e-12)


def test_batched_circuits_are_independent():
    g = np.array([[1 / R1, 0.0, 0.0, 1 / R4], [0.0, 0.0, 0.0, 0.0]])
    c = circuit(g, np.array([P_WS, 500e3]), AREA)
    assert c.drive[0] == pytest.approx(P_WS * AREA, rel=1e-12)
    assert c.sealed.tolist() == [False, True]


def step(c, *, friction=NO_FRICTION, y=8e-3, v0=0.0, mass=0.04, stuck=False, external=0.0):
    return rack_step(circuit_now=c, friction_params=friction, bore_area=AREA, y=np.array([y]),
                     v0=np.array([v0]), external_force=np.array([external]), stuck=np.array([stuck]),
                     mass=np.array([mass]), h=H)


@pytest.mark.parametrize("v0", [0.0, 0.05, -0.12, 3.0])
def test_sealed_circuit_stops_the_rack_whatever_its_velocity(v0):
    sealed = circuit(one(0.0, 0.0, 0.0, 0.0), np.array([P_WS]), AREA)
    out = step(sealed, v0=v0, friction=FrictionParams())
    assert out.velocity[0] == 0.0
    assert out.stuck[0]


def test_nearly_free_rack_accelerates_by_h_f_over_m():
    """Huge conductances -> tiny damping; no friction: v1 ~ v0 + h F0 / M."""
    g = 1e3  # m^3/(Pa s)
    c = circuit(one(g, 0.0, 0.0, g), np.array([P_WS]), AREA)
    assert c.damping[0] < 1e-12
    mass, v0 = 10.0, 0.02
    out = step(c, v0=v0, mass=mass)
    assert out.velocity[0] == pytest.approx(v0 + H * P_WS * AREA / mass, rel=1e-9)


@pytest.mark.parametrize("v0", [0.0, 0.03, -0.05])
def test_implicit_euler_step_with_hydraulic_damping(v0):
    """No friction: v1 = (v0 + h F0 / M) / (1 + h c / M), c = (R1 + R4) A^2 (backward Euler of eq. 4.4.1)."""
    c = circuit(one(1 / R1, 0.0, 0.0, 1 / R4), np.array([P_WS]), AREA)
    mass = 0.033
    damping = (R1 + R4) * AREA**2
    expected = (v0 + H * P_WS * AREA / mass) / (1.0 + H * damping / mass)
    out = step(c, v0=v0, mass=mass)
    assert out.velocity[0] == pytest.approx(expected, rel=1e-12)
    assert not out.stuck[0]


def _drive_of(force: float):
    """V1 + V4 open with the supply pressure that makes the drive exactly ``force`` N."""
    return circuit(one(1 / R1, 0.0, 0.0, 1 / R1), np.array([force / AREA]), AREA)


def test_stiction_holds_a_resting_rack_below_3_6_newtons():
    friction = FrictionParams(stiction=3.6, coulomb_poly=(0.0,) * 7)
    c = _drive_of(3.5)
    assert c.drive[0] == pytest.approx(3.5, rel=1e-12)
    out = step(c, friction=friction, v0=0.0, stuck=True)
    assert out.velocity[0] == 0.0
    assert out.stuck[0]


def test_drive_above_stiction_breaks_away():
    friction = FrictionParams(stiction=3.6, coulomb_poly=(0.0,) * 7)
    out = step(_drive_of(3.8), friction=friction, v0=0.0, stuck=True)
    assert out.velocity[0] > 0.0
    assert not out.stuck[0]


def test_scalar_inputs_broadcast_over_the_scenarios():
    """The compiled step reads every per-scenario input at each index: a scalar must mean 'the same for all'."""
    c = circuit(np.repeat(one(1 / R1, 0.0, 0.0, 1 / R4), 3, axis=0), np.array(P_WS), AREA)
    out = rack_step(circuit_now=c, friction_params=NO_FRICTION, bore_area=AREA, y=np.full(3, 8e-3), v0=0.0,
                    external_force=0.0, stuck=False, mass=0.04, h=H, breakaway=0.0)
    assert out.velocity[0] > 0 and np.all(out.velocity == out.velocity[0])


def test_a_circuit_does_not_follow_later_changes_to_its_inputs():
    g = one(1 / R1, 0.0, 0.0, 1 / R4)
    c = circuit(g, np.array([P_WS]), AREA)
    g[:] = 0.0
    assert c.drive[0] == pytest.approx(P_WS * AREA, rel=1e-12) and not c.sealed[0]


def test_a_per_scenario_input_of_the_wrong_length_is_refused():
    c = circuit(np.repeat(one(1 / R1, 0.0, 0.0, 1 / R4), 3, axis=0), np.array(P_WS), AREA)
    with pytest.raises(ValueError, match="one value per scenario"):
        rack_step(circuit_now=c, friction_params=NO_FRICTION, bore_area=AREA, y=np.full(3, 8e-3), v0=0.0,
                  external_force=0.0, stuck=False, mass=np.array([0.04, 0.04]), h=H)
