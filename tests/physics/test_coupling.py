"""The gear couplings: bounded error, and the two design choices that keep it small."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from tests.conftest import open_loop
from twin.physics.model import Orientation, build_mjcf, compile_joint

LIMIT_DEG = 0.01
PAYLOAD = 13.5e-3


@pytest.mark.parametrize("duty", [100.0, -100.0])
def test_coupling_error_under_full_pressure_with_13_5_g_vertical(duty):
    result = open_loop(duty, trajectory=3, payload=PAYLOAD, orientation=Orientation.VERTICAL, supply=700e3)
    assert np.ptp(np.degrees(result.trace.angle)) > 90  # it really moved, into the stroke end
    assert result.warnings == ()
    assert np.max(np.abs(np.degrees(result.trace.coupling_error))) < LIMIT_DEG


def _model(*, spur_on_pinion: bool = False, rack_damping: float = 0.0) -> mujoco.MjModel:
    root = build_mjcf(payload_mass=PAYLOAD, orientation=Orientation.VERTICAL)
    if spur_on_pinion:  # the literal chain: spur = -pinion r_p / r_s
        mesh = root.find("equality", "mesh_spur")
        mesh.joint2 = "pinion"
        gears = compile_joint().params.gears
        mesh.polycoef = (0.0, -gears.pinion_radius / gears.spur_radius, 0.0, 0.0, 0.0)
    root.find("joint", "rack_a").damping = rack_damping
    return mujoco.MjModel.from_xml_string(root.to_xml_string())


def _worst_coupling_error(model: mujoco.MjModel, *, stop: bool, speed: float = 0.05, steps: int = 200):
    """Start at y = 8 mm moving at ``speed``; if ``stop``, apply at the racks the one-step stopping force
    a shut valve applies (twin/hydraulics.py). Returns (max |spur - y / r_s| in deg, MuJoCo warnings)."""
    joint = compile_joint(payload_mass=PAYLOAD, orientation=Orientation.VERTICAL)
    data = mujoco.MjData(model)
    dofs = [joint.rack_a_dof, joint.rack_b_dof, joint.pinion_dof, joint.spur_dof]
    data.qpos[dofs] = joint.manifold[dofs] * 8e-3
    data.qvel[dofs] = joint.manifold[dofs] * speed
    r_s = joint.params.gears.spur_radius
    worst = 0.0
    for _ in range(steps):
        mujoco.mj_forward(model, data)
        if stop:
            external = float((data.qfrc_passive - data.qfrc_bias) @ joint.manifold)
            force = -joint.effective_mass * data.qvel[joint.rack_a_dof] / model.opt.timestep - external
            data.ctrl[:] = (force / 2, -force / 2)  # piston A pushes +y, piston B -y
        mujoco.mj_step(model, data)
        error = math.degrees(data.qpos[joint.spur_dof] - data.qpos[joint.rack_a_dof] / r_s)
        worst = max(worst, abs(error)) if math.isfinite(error) else math.inf
    warnings = tuple(i for i in range(int(mujoco.mjtWarning.mjNWARNING)) if data.warning[i].number)
    return worst, warnings


def test_stopping_force_at_the_racks_keeps_the_gears_together():
    worst, warnings = _worst_coupling_error(_model(), stop=True)
    assert warnings == ()
    assert worst < LIMIT_DEG / 10


def test_spur_coupled_through_the_pinion_would_be_too_soft():
    """Why models/joint.xml couples the spur to rack A: the pinion's tiny inertia softens the constraint."""
    sag, _ = _worst_coupling_error(_model(spur_on_pinion=True), stop=False, speed=0.0, steps=300)
    assert sag > LIMIT_DEG
    worst, warnings = _worst_coupling_error(_model(spur_on_pinion=True), stop=True)
    assert warnings or worst > 10 * LIMIT_DEG


def test_valve_resistance_as_mujoco_damping_would_tear_the_couplings():
    """Why twin/hydraulics.py integrates the resistance itself: implicitfast damps rack A alone."""
    worst, _ = _worst_coupling_error(_model(rack_damping=1e4), stop=False)
    assert worst > LIMIT_DEG
