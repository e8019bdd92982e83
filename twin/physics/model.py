"""Compile the joint's MJCF with a payload and an orientation.

``models/joint.xml`` is the mechanism; this module writes every mass,
inertia, length and gear coupling into it from :class:`twin.physics.params.JointParams`
(the one place those numbers live), adds the payload body at the link tip and
turns the housing for the vertical orientation, all with ``dm_control.mjcf``,
then recompiles. Nothing here writes ``body_mass`` into a compiled model.

The mechanism has four joints coupled by three equality constraints::

    rack_b = -y          pinion = -y / r_p          spur = -pinion r_p / r_s = y / r_s

(the spur's coupling is written against rack A; see models/joint.xml)
so its one degree of freedom is the rack position ``y`` (rack A, metres). The
*manifold vector* ``dq/dy`` maps it to the four joint velocities.
"""

from __future__ import annotations

import dataclasses
import enum
import fractions
import importlib.resources
import math
import os

import mujoco
import numpy as np

from twin.exceptions import InvalidScenario
from twin.physics.params import NOMINAL_PARAMS, JointParams

MODEL_PATH = importlib.resources.files("models") / "joint.xml"  # package data of the top-level models/ folder

MECHANISM_JOINTS = ("rack_a", "rack_b", "pinion", "spur")
MAX_PAYLOAD = 0.2  # kg; far past what 700 kPa can lift, a guard against unit mistakes
MIN_PAYLOAD = 1e-6  # kg; a payload is 0 or at least 1 mg: MuJoCo refuses a mass as small as 1e-323 kg in the model file
PAYLOAD_RANGE = f"0 or between {MIN_PAYLOAD * 1e3:g} and {MAX_PAYLOAD * 1e3:g} g"  # as the errors say it


def payload_allowed(mass: float) -> bool:
    """Whether ``mass`` (kg, a real number) is a payload the model takes: 0, or MIN_PAYLOAD to MAX_PAYLOAD."""
    return math.isfinite(mass) and (mass == 0.0 or MIN_PAYLOAD <= mass <= MAX_PAYLOAD)
THESIS_PAYLOADS = (6.5e-3, 13.5e-3)  # kg at the link tip: the thesis's two payloads (SPEC §2, §9)


class Orientation(enum.Enum):
    """HORIZONTAL: gravity along the output shaft. VERTICAL: gravity in the
    plane of rotation, theta = 0 hanging straight down (§9, *inferred*)."""

    HORIZONTAL = "horizontal"
    VERTICAL = "vertical"


# The housing is turned +90 deg about x: its -y (the link at theta = 0) points down.
_HOUSING_QUAT = {
    Orientation.HORIZONTAL: (1.0, 0.0, 0.0, 0.0),
    Orientation.VERTICAL: (math.cos(math.pi / 4), math.sin(math.pi / 4), 0.0, 0.0),
}


@dataclasses.dataclass(frozen=True)
class JointModel:
    """A compiled joint model with named indices into its arrays."""

    model: mujoco.MjModel
    params: JointParams
    payload_mass: float  # kg
    orientation: Orientation
    rack_a_dof: int
    rack_b_dof: int
    pinion_dof: int
    spur_dof: int
    manifold: np.ndarray  # (nv,) dq/dy
    effective_mass: float  # kg, inertia of the whole train referred to the rack, dq/dy' M dq/dy

    @property
    def timestep(self) -> float:
        return float(self.model.opt.timestep)  # s


def _mjcf():
    # dm_control picks a GL backend on import; without a display its default (GLFW)
    # prints a warning. The twin never renders through dm_control, so default to EGL.
    os.environ.setdefault("MUJOCO_GL", "egl")
    from dm_control import mjcf  # imported late: dm_control is slow to import

    return mjcf


def build_mjcf(*, params: JointParams = NOMINAL_PARAMS, payload_mass: float = 0.0,
               orientation: Orientation = Orientation.HORIZONTAL, timestep: float = 1e-3):
    """The joint as a ``dm_control.mjcf`` element tree, ready to compile."""
    if not payload_allowed(payload_mass):
        raise InvalidScenario(f"payload must be {PAYLOAD_RANGE}, got {payload_mass * 1e3:.10g} g")
    if not (0 < timestep <= 2e-3):
        raise InvalidScenario(f"timestep must be in (0, 2 ms], got {timestep}")
    with importlib.resources.as_file(MODEL_PATH) as path:
        root = _mjcf().from_path(str(path))
    root.option.timestep = timestep
    # solref below 2 x timestep is clamped by MuJoCo (a smaller one diverged when tried): use the stiffest allowed.
    root.default.equality.solref = (2.0 * timestep, 1.0)

    masses, gears = params.masses, params.gears
    for side in ("rack_a", "rack_b"):
        root.find("body", side).inertial.mass = masses.rack_side_mass
    pinion = root.find("body", "pinion").inertial
    pinion.diaginertia = (masses.pinion_inertia,) * 3
    spur = root.find("body", "spur").inertial
    spur.diaginertia = (masses.spur_inertia,) * 3

    length = masses.link_length
    link = root.find("body", "link")
    link.inertial.mass = masses.link_mass
    link.inertial.pos = (0.0, -length / 2.0, 0.0)
    transverse = masses.link_mass * length**2 / 12.0
    link.inertial.diaginertia = (transverse, 1e-12, transverse)
    root.find("site", "link_tip").pos = (0.0, -length, 0.0)

    root.find("equality", "mesh_pinion").polycoef = (0.0, -1.0 / gears.pinion_radius, 0.0, 0.0, 0.0)
    root.find("equality", "mesh_spur").polycoef = (0.0, 1.0 / gears.spur_radius, 0.0, 0.0, 0.0)

    # The payload body always exists (massless and hidden when empty) so that every
    # variant shares one memory layout and can run in one mujoco.batch.Batch.
    payload = link.add("body", name="payload", pos=(0.0, -length, 0.0))
    if payload_mass > 0.0:
        radius = (3.0 * payload_mass / (4.0 * math.pi * masses.payload_density)) ** (1.0 / 3.0)
        payload.add("inertial", pos=(0.0, 0.0, 0.0), mass=payload_mass,
                    diaginertia=(0.4 * payload_mass * radius**2,) * 3)
        payload.add("geom", name="payload_mass", dclass=root.default.find("default", "visual"),
                    type="sphere", size=(radius,), material="payload")
    else:
        payload.add("geom", name="payload_mass", dclass=root.default.find("default", "visual"),
                    type="sphere", size=(1e-4,), rgba=(0, 0, 0, 0))
    root.find("body", "housing").quat = _HOUSING_QUAT[orientation]
    root.option.gravity = (0.0, 0.0, -params.gravity)
    return root


def compile_joint(*, params: JointParams = NOMINAL_PARAMS, payload_mass: float = 0.0,
                  orientation: Orientation = Orientation.HORIZONTAL, timestep: float = 1e-3) -> JointModel:
    """Compile the joint; see :func:`build_mjcf`. ``payload_mass`` in kg."""
    root = build_mjcf(params=params, payload_mass=payload_mass, orientation=orientation, timestep=timestep)
    try:
        model = mujoco.MjModel.from_xml_string(root.to_xml_string(), root.get_assets())
    except ValueError as error:
        raise InvalidScenario(f"MuJoCo rejected the joint model: {error}") from None
    dofs = [int(model.jnt_dofadr[model.joint(name).id]) for name in MECHANISM_JOINTS]
    r_p, r_s = params.gears.pinion_radius, params.gears.spur_radius
    manifold = np.zeros(model.nv)
    manifold[dofs] = (1.0, -1.0, -1.0 / r_p, 1.0 / r_s)
    inertia = _joint_space_inertia(model)
    if np.count_nonzero(inertia - np.diag(np.diag(inertia))):
        raise InvalidScenario("the mechanism's joint-space inertia must be diagonal (one joint per body)")
    effective_mass = diagonal_form(manifold, np.diag(inertia))
    return JointModel(
        model=model, params=params, payload_mass=payload_mass, orientation=orientation,
        rack_a_dof=dofs[0], rack_b_dof=dofs[1], pinion_dof=dofs[2], spur_dof=dofs[3],
        manifold=manifold, effective_mass=effective_mass,
    )


def referred_mass(params: JointParams = NOMINAL_PARAMS) -> float:
    """The train's inertia referred to the rack without payload, in closed form (kg): both rack sides,
    the pinion and spur and the link through their pitch radii (SPEC §2's note: 43.5 g, where the
    thesis's lumped M is 32.9 g). The compiled model's ``effective_mass`` gives the same number."""
    m, g = params.masses, params.gears
    return (2.0 * m.rack_side_mass + m.pinion_inertia / g.pinion_radius**2
            + (m.spur_inertia + m.link_inertia) / g.spur_radius**2)


def diagonal_form(vector: np.ndarray, diagonal: np.ndarray) -> float:
    """``vector @ diag(diagonal) @ vector`` by one fixed sequence of roundings, whatever BLAS is loaded: each
    ``vector[i] * diagonal[i]`` rounded, then summed by fused multiply-adds with ``vector[i]`` in index order, each
    rounded once (exact rationals stand in for the fused multiply-add, which Python has only from 3.13). It is the
    sequence OpenBLAS's SkylakeX kernel gave the effective mass when it was ``manifold @ inertia @ manifold``, on
    which every kept result ran; its Haswell kernel gives another last bit (docs/testing.md)."""
    total = 0.0
    for v, d in zip(vector.tolist(), diagonal.tolist(), strict=True):
        total = float(fractions.Fraction(v * d) * fractions.Fraction(v) + fractions.Fraction(total))
    return total


def _joint_space_inertia(model: mujoco.MjModel) -> np.ndarray:
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    inertia = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, inertia)
    return inertia
