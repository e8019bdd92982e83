"""The MJCF model: named, consistent with the typed parameters, composed by rebuilding."""

from __future__ import annotations

import os
import platform
import subprocess
import sys
from fractions import Fraction

import mujoco
import numpy as np
import pytest

from twin.exceptions import InvalidScenario
from twin.physics.model import (
    MODEL_PATH,
    Orientation,
    _joint_space_inertia,
    compile_joint,
    diagonal_form,
    referred_mass,
)
from twin.physics.params import JointParams

OBJECTS = [mujoco.mjtObj.mjOBJ_BODY, mujoco.mjtObj.mjOBJ_JOINT, mujoco.mjtObj.mjOBJ_GEOM, mujoco.mjtObj.mjOBJ_SITE,
           mujoco.mjtObj.mjOBJ_ACTUATOR, mujoco.mjtObj.mjOBJ_SENSOR, mujoco.mjtObj.mjOBJ_EQUALITY,
           mujoco.mjtObj.mjOBJ_TENDON]


@pytest.mark.parametrize("payload", [0.0, 13.5e-3])
def test_every_element_is_named(payload):
    model = compile_joint(payload_mass=payload).model
    counts = {mujoco.mjtObj.mjOBJ_BODY: model.nbody, mujoco.mjtObj.mjOBJ_JOINT: model.njnt,
              mujoco.mjtObj.mjOBJ_GEOM: model.ngeom, mujoco.mjtObj.mjOBJ_SITE: model.nsite,
              mujoco.mjtObj.mjOBJ_ACTUATOR: model.nu, mujoco.mjtObj.mjOBJ_SENSOR: model.nsensor,
              mujoco.mjtObj.mjOBJ_EQUALITY: model.neq, mujoco.mjtObj.mjOBJ_TENDON: model.ntendon}
    for kind in OBJECTS:
        first = 1 if kind == mujoco.mjtObj.mjOBJ_BODY else 0  # the world body
        for i in range(first, counts[kind]):
            assert mujoco.mj_id2name(model, kind, i), f"unnamed {kind.name} {i}"


def test_the_xml_on_disk_agrees_with_the_typed_parameters():
    raw = mujoco.MjModel.from_xml_path(str(MODEL_PATH))
    built = compile_joint().model  # adds the (empty) payload body
    for name in ("rack_a", "rack_b", "pinion", "spur", "link"):
        for field in ("mass", "inertia", "ipos"):
            np.testing.assert_allclose(getattr(raw.body(name), field), getattr(built.body(name), field),
                                       rtol=1e-5, atol=1e-15, err_msg=f"{name}.{field}")
    for name in ("mesh_rack_b", "mesh_pinion", "mesh_spur"):
        np.testing.assert_allclose(raw.equality(name).data, built.equality(name).data, rtol=1e-9, err_msg=name)
    np.testing.assert_allclose(raw.site("link_tip").pos, built.site("link_tip").pos)


def test_masses_come_from_spec_section_2():
    p = JointParams()
    assert p.cylinder.bore_area == pytest.approx(1.2566e-5, rel=1e-4)
    assert p.masses.link_inertia == pytest.approx(2.45e-7, rel=1e-3)
    assert p.gears.ratio == pytest.approx(2.57, abs=0.005)
    joint = compile_joint()
    assert joint.effective_mass == pytest.approx(
        2 * p.masses.rack_side_mass + p.masses.pinion_inertia / p.gears.pinion_radius**2
        + (p.masses.spur_inertia + p.masses.link_inertia) / p.gears.spur_radius**2, rel=1e-9)


def test_payload_is_rebuilt_into_the_model_at_the_link_tip():
    joint = compile_joint(payload_mass=13.5e-3)
    model = joint.model
    payload = model.body("payload")
    assert payload.mass[0] == pytest.approx(13.5e-3)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    tip = data.site("link_tip").xpos
    np.testing.assert_allclose(data.body("payload").xpos, tip, atol=1e-12)
    spur_axis = data.body("spur").xpos
    assert np.linalg.norm((tip - spur_axis)[:2]) == pytest.approx(35e-3, rel=1e-9)


def test_vertical_orientation_hangs_the_link_down_at_zero():
    model = compile_joint(orientation=Orientation.VERTICAL).model
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    direction = data.site("link_tip").xpos - data.body("spur").xpos
    assert direction[2] == pytest.approx(-35e-3, rel=1e-9)  # straight down (the 2 mm shaft offset is along world y)
    assert direction[0] == pytest.approx(0.0, abs=1e-12)


def test_solref_is_twice_the_timestep():
    for timestep in (1e-3, 5e-4):
        model = compile_joint(timestep=timestep).model
        np.testing.assert_allclose(model.eq_solref[:, 0], 2 * timestep)


@pytest.mark.parametrize("payload", [-1e-3, float("nan"), 1.0, 1e-323, 9.99e-7])
def test_bad_payload_is_rejected(payload):
    """Under 1 mg too (since 2026-12-08): MuJoCo refused 1e-323 kg in the model file in three lines."""
    with pytest.raises(InvalidScenario, match="payload must be 0 or between 0.001 and 200 g, got "):
        compile_joint(payload_mass=payload)


@pytest.mark.parametrize("payload", [0.0, 1e-6, 0.2])
def test_the_payload_range_ends_are_taken(payload):
    compile_joint(payload_mass=payload)


def test_referred_mass_closed_form_is_the_multibody_inertia_along_the_rack():
    """SPEC §2: two rack sides (32.08 g), pinion and spur through their pitch radii, and the link's
    J / r_s^2 = 10.8 g: the compiled model's dq/dy' M dq/dy without payload, to round-off."""
    params = JointParams()
    expected = 2 * (0.46e-3 + 2e-3 + 27.16e-3 / 2) + 4.8e-10 / (3.71e-3 / 2) ** 2 \
        + (1.095e-8 + 2.45e-7) / (9.525e-3 / 2) ** 2
    assert referred_mass(params) == pytest.approx(expected, rel=1e-3)
    assert compile_joint(params=params).effective_mass == pytest.approx(referred_mass(params), rel=1e-9)


# T1 0 g vertical's compiled rack-side manifold and joint-space inertia diagonal, to the last bit (2026-12-06)
VERTICAL_MANIFOLD = [float.fromhex(x) for x in (
    "0x1.0000000000000p+0", "-0x1.0000000000000p+0", "-0x1.0d8ab206e6781p+9", "0x1.a3f28fca3f28fp+7")]
VERTICAL_DIAGONAL = [float.fromhex(x) for x in (
    "0x1.06cca2db61bb0p-6", "0x1.06cca2db61bb0p-6", "0x1.07e1fe91b0b71p-31", "0x1.12d30012807d7p-22")]
VERTICAL_MASS = float.fromhex("0x1.6462a4203bb6fp-5")  # what every kept result ran on
VERTICAL_MASS_PLAIN_ADDS = float.fromhex("0x1.6462a4203bb6ep-5")  # OpenBLAS's Haswell kernel's manifold @ M @ manifold


def test_the_effective_mass_is_one_rounding_sequence_within_its_closed_form():
    """0 g vertical's compiled inputs are the ones pinned above; diagonal_form of them is the exact v' D v within the
    rounding bound of four positive terms (5 u of the sum), and it is the fused sequence: a plain sum in the same
    order lands one bit lower, which is what OpenBLAS's Haswell kernel gave (the plain sum is the nearer to the exact
    value, so only this equality tells the two sequences apart)."""
    joint = compile_joint(orientation=Orientation.VERTICAL)
    assert joint.manifold.tolist() == VERTICAL_MANIFOLD
    assert np.diag(_joint_space_inertia(joint.model)).tolist() == VERTICAL_DIAGONAL
    pairs = list(zip(VERTICAL_MANIFOLD, VERTICAL_DIAGONAL, strict=True))
    exact = sum(Fraction(a) * Fraction(a) * Fraction(b) for a, b in pairs)
    mass = diagonal_form(np.array(VERTICAL_MANIFOLD), np.array(VERTICAL_DIAGONAL))
    assert abs(Fraction(mass) - exact) <= 5 * Fraction(1, 2**53) * exact
    plain = 0.0
    for a, b in pairs:
        plain += (a * b) * a
    assert plain == VERTICAL_MASS_PLAIN_ADDS != mass == VERTICAL_MASS == joint.effective_mass


def test_the_effective_mass_does_not_turn_on_the_blas_kernel():
    """Compiled in a new interpreter with OpenBLAS held to its Haswell kernel, 0 g vertical's effective mass is still
    the bit every kept result ran on. Before diagonal_form it came out one bit lower there, and 20 kept-result reruns
    failed in a shell that set OPENBLAS_CORETYPE=Haswell. A BLAS that does not read that variable (one built without
    run-time kernel choice, or not OpenBLAS) passes this trivially."""
    if platform.machine() not in ("x86_64", "AMD64"):
        pytest.skip("OpenBLAS's Haswell kernel is an x86-64 one")
    code = ("from twin.physics.model import Orientation, compile_joint; "
            "print(compile_joint(orientation=Orientation.VERTICAL).effective_mass.hex())")
    env = dict(os.environ, OPENBLAS_CORETYPE="Haswell")
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True).stdout
    assert float.fromhex(out.strip()) == VERTICAL_MASS
