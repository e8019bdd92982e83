"""The twin's physics against closed-form answers (SPEC §2, §4)."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from controllers import make_controller
from controllers.feedforward import NominalModel
from tests.conftest import AREA, R_SPUR, custom_plant, open_loop
from twin.envs.runner import thesis_controllers
from twin.physics.friction import coulomb_force
from twin.physics.model import Orientation, compile_joint
from twin.physics.params import FrictionParams, JointParams
from twin.sim.scenario import Scenario
from twin.sim.simulation import simulate

PARAMS = JointParams()
G = PARAMS.gravity
LINK_MASS, LENGTH = PARAMS.masses.link_mass, PARAMS.masses.link_length


def test_gear_kinematics_12_03_deg_per_mm_and_ratio():
    result = open_loop(60.0)
    moving = (result.trace.rack_position > 3e-3) & (result.trace.rack_position < 14e-3)
    slope = np.polyfit(result.trace.rack_position[moving] * 1e3, np.degrees(result.trace.angle[moving]), 1)[0]
    assert slope == pytest.approx(360.0 / (math.pi * 9.525), abs=1e-6)  # eq. 3.4.1
    assert slope == pytest.approx(12.03, abs=0.005)


def test_pinion_turns_2_57_times_the_output():
    joint = compile_joint()
    model, data = joint.model, mujoco.MjData(joint.model)
    data.ctrl[0] = 0.1  # N along y: about 3 mm in 50 ms, inside the stroke
    for _ in range(50):
        mujoco.mj_step(model, data)
    pinion, spur = data.qpos[joint.pinion_dof], data.qpos[joint.spur_dof]
    assert -pinion / spur == pytest.approx(9.525 / 3.71, rel=1e-6)  # 2.57:1, opposite senses
    assert 1e-3 < data.qpos[joint.rack_a_dof] < 10e-3
    assert data.qpos[joint.rack_b_dof] == pytest.approx(-data.qpos[joint.rack_a_dof], abs=1e-8)  # 0.01 um


def _damping(duty: float) -> float:
    valves = PARAMS.valves
    return PARAMS.friction.viscous + (valves.open_resistance + valves.resistance(duty)) * AREA**2


@pytest.mark.parametrize("duty", [50.0, 100.0])  # whole ticks of the 16 ms period
@pytest.mark.parametrize("supply", [300e3, 700e3])
def test_steady_velocity_at_constant_duty(duty, supply):
    """v = (P_ws A - F_c) / (F_v + (R1 + R4(d)) A^2), eq. 4.4.1 at steady state (constant F_c = 1 N)."""
    flat = custom_plant("flat-friction", friction=FrictionParams(coulomb_poly=(1.0,), stiction=0.0))
    tr = open_loop(duty, plant=flat, supply=supply).trace
    v = np.diff(tr.rack_position) / 1e-3
    expected = (supply * AREA - 1.0) / _damping(duty)
    settled = v[30:60]  # 25 ms after the valves open (time constant M / c < 1 ms), before the stroke end
    assert tr.rack_position[60] < 14e-3
    np.testing.assert_allclose(settled, expected, rtol=1e-6)


@pytest.mark.parametrize("duty", [50.0, 100.0])  # whole ticks of the 16 ms period
def test_motion_obeys_eq_4_4_1_with_the_position_dependent_friction(duty):
    """M y'' = P_ws A - (R1 + R4) A^2 y' - F_c(y) - F_v y' along the run, M = 43.5 g (multibody)."""
    result = open_loop(duty)
    y = result.trace.rack_position
    v = np.diff(y) / 1e-3  # velocity over each step (semi-implicit Euler)
    a = np.diff(v) / 1e-3
    moving = (y[1:-1] > 3e-3) & (y[1:-1] < 14e-3) & (v[1:] > 0)
    mass = compile_joint().effective_mass
    assert mass == pytest.approx(43.5e-3, abs=0.1e-3)  # SPEC §2: link inertia via r_s, not the thesis's 32.9 g
    friction = coulomb_force(PARAMS.friction, y[1:-1], np.ones(len(y) - 2))
    residual = mass * a + _damping(duty) * v[1:] + friction - 300e3 * AREA
    assert moving.sum() > 50
    assert np.max(np.abs(residual[moving])) < 1e-3 * 300e3 * AREA


def test_reverse_pair_drives_the_other_way():
    forward = open_loop(100.0, trajectory=3)
    backward = open_loop(-100.0, trajectory=3)
    assert forward.trace.angle[200] > forward.trace.angle[0]
    assert backward.trace.angle[200] < backward.trace.angle[0]


def _gravity_along_rack(payload: float, theta: float, orientation: Orientation) -> float:
    joint = compile_joint(payload_mass=payload, orientation=orientation)
    data = mujoco.MjData(joint.model)
    y = theta * R_SPUR
    data.qpos[[joint.rack_a_dof, joint.rack_b_dof, joint.pinion_dof, joint.spur_dof]] = (
        y, -y, -y / PARAMS.gears.pinion_radius, theta)
    mujoco.mj_forward(joint.model, data)
    return float(-data.qfrc_bias @ joint.manifold)


@pytest.mark.parametrize("theta_deg", [0.0, 30.0, 90.0, 140.0])
@pytest.mark.parametrize("payload", [0.0, 6.5e-3, 13.5e-3])
def test_vertical_gravity_torque_reaches_the_rack_through_r_spur(theta_deg, payload):
    """F_y = -(m L + m_link L / 2) g sin(theta) / r_s; theta = 0 hangs down (§9)."""
    theta = math.radians(theta_deg)
    expected = -(payload * LENGTH + LINK_MASS * LENGTH / 2) * G * math.sin(theta) / R_SPUR
    assert _gravity_along_rack(payload, theta, Orientation.VERTICAL) == pytest.approx(expected, abs=1e-9)


def test_horizontal_gravity_is_along_the_shaft():
    assert _gravity_along_rack(13.5e-3, math.radians(90), Orientation.HORIZONTAL) == pytest.approx(0.0, abs=1e-12)


def test_stall_torque_is_42_mNm_at_700_kPa(frictionless):
    """tau = P A D_spur / 2 (eq. 3.4.2): a tip mass just under the stall load rises, just over it falls."""
    stall_torque = 700e3 * AREA * R_SPUR
    assert stall_torque == pytest.approx(0.0419, abs=5e-4)
    theta0 = math.radians(80.0)  # T3 starts here
    stall_mass = (stall_torque / (G * math.sin(theta0)) - LINK_MASS * LENGTH / 2) / LENGTH
    for factor, rises in ((0.97, True), (1.03, False)):
        result = open_loop(100.0, plant=frictionless, trajectory=3, payload=factor * stall_mass,
                           orientation=Orientation.VERTICAL, supply=700e3)
        moved = result.trace.angle[100] - result.trace.angle[0]
        assert (moved > 0) == rises, (factor, moved)
        assert result.warnings == ()


def test_stiction_holds_when_supply_force_is_below_it():
    sticky = custom_plant("sticky", friction=FrictionParams(stiction=3.6))
    below = 0.98 * 3.6 / AREA  # P_ws A = 3.53 N < 3.6 N
    held = open_loop(100.0, plant=sticky, trajectory=3, supply=below)
    assert np.ptp(held.trace.rack_position) < 1e-7  # 0.1 um: the gear constraints' elastic give
    above = 1.05 * 3.6 / AREA
    moved = open_loop(100.0, plant=sticky, trajectory=3, supply=above)
    assert np.ptp(moved.trace.rack_position) > 1e-3


def test_no_open_path_locks_the_joint_against_gravity():
    result = open_loop(0.0, trajectory=3, payload=13.5e-3, orientation=Orientation.VERTICAL)
    angle = np.degrees(result.trace.angle)
    assert np.ptp(angle) < 1e-4  # the gear constraints settle under the load once ...
    assert np.ptp(angle[1000:]) < 1e-9  # ... then nothing creeps
    assert result.warnings == ()


def test_closing_the_valves_stops_a_moving_joint_within_the_closing_delay():
    close_at = 0.208  # s, a PWM period boundary (13 x 16 ms)
    result = open_loop(lambda t: 100.0 if t < close_at else 0.0)
    y = result.trace.rack_position
    stop = int(round(close_at / 1e-3)) + 2 + 1  # closing delay 2 ms, then one tick of motion
    assert y[stop - 5] < y[stop - 1]  # it was moving
    assert np.ptp(y[stop:]) < 1e-7


@pytest.mark.parametrize("name, calls", [("pva", 188), ("ffpva", 188), ("smc", 3000)])
def test_controller_update_count_is_duration_over_period(name, calls):
    controller = make_controller(name, nominal=NominalModel.thesis(), gain_set="simulation", tick=1e-3)
    counted = []
    update = controller.update

    def counting_update(*args):
        counted.append(args[0])
        return update(*args)

    controller.update = counting_update
    simulate([Scenario(name, 1)], controllers=[controller])  # T1: 3 s
    assert len(counted) == calls  # ceil(3 s / period)
    assert counted[1] - counted[0] == pytest.approx(controller.period)


def test_sliding_mode_refreshes_its_ffpva_part_every_pwm_period(monkeypatch):
    import controllers.smc as smc

    slow = []
    original = smc.ffpva_duty
    monkeypatch.setattr(smc, "ffpva_duty", lambda *a: slow.append(1) or original(*a))
    simulate([Scenario("smc", 1)], controllers=thesis_controllers([Scenario("smc", 1)]))
    assert len(slow) == 188


@pytest.mark.parametrize("plant", ["thesis", "thesis-pwm"])
def test_random_valve_commands_raise_no_mujoco_warning(plant):
    rng = np.random.default_rng(7)
    commands = rng.uniform(-100, 100, size=5000)
    result = open_loop(lambda t: commands[int(round(t * 1e3))], plant=plant, trajectory=3, payload=13.5e-3,
                       orientation=Orientation.VERTICAL, period=1e-3)
    assert result.warnings == ()
    assert np.all(np.isfinite(result.trace.angle))
    assert np.max(np.abs(np.degrees(result.trace.coupling_error))) < 0.01


def test_a_mujoco_warning_is_reported_on_its_own_scenario_only(monkeypatch):
    """The smoke test above can only pass if warnings are read: a non-finite piston force in one scenario
    of a batch must come back as a MuJoCo warning on that scenario and not on its neighbour."""
    from twin.sim.plant_state import PlantState

    real = PlantState.actuate

    def poisoned(self, k, duty, y, v, external):
        force_a, force_b = real(self, k, duty, y, v, external)
        if k == 100:
            force_a[1] = np.nan
        return force_a, force_b

    monkeypatch.setattr(PlantState, "actuate", poisoned)
    scenarios = [Scenario("ffpva", 1, seed=0), Scenario("ffpva", 1, seed=1)]
    clean, poisoned_run = simulate(scenarios, controllers=thesis_controllers(scenarios))
    assert clean.warnings == ()
    assert any(w.startswith("mjWARN_BADCTRL") for w in poisoned_run.warnings), poisoned_run.warnings
