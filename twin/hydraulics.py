"""The hydraulic actuator: valve conductances -> forces on the racks.

Water is incompressible (thesis plant), so the flow into cylinder A is
``Q = A v`` with ``v`` the velocity of rack A (the mechanism coordinate y).
Each chamber joins the supply and the tank through two valves of conductance
g = 1/R, so its pressure follows from the flow balance::

    A v = g1 (P_ws - P_a) - g2 P_a          -A v = g3 (P_ws - P_b) - g4 P_b

and the net force on the rack is affine in v::

    A (P_a - P_b) = F_0 - c_h v
    F_0 = A P_ws [g1/(g1+g2) - g3/(g3+g4)],   c_h = A^2 [1/(g1+g2) + 1/(g3+g4)]

With V1 + V4 open this is eq. 4.3.6 / 4.4.1: ``F_0 = P_ws A`` and
``c_h = (R1 + R4) A^2``. A chamber with both valves shut is sealed: c_h is
infinite and the joint is locked.

The rack equation along the gear-coupled coordinate,

    M dv/dt = F_0 - (c_h + F_v) v - F_c(y) sgn(v) + F_ext,

is stiff (M / c down to 0.2 ms), so it is integrated implicitly over one
step h, with Coulomb friction and stiction as a velocity-level complementarity
(stick when the force needed to stop is within the friction limit):

    v1 = (v0 + h (F_0 + F_ext + F_f) / M) / (1 + h (c_h + F_v) / M)

The resulting *bounded* forces act where they do on the real joint: each
piston pushes its rack with its chamber pressure times the bore area (half the
force loss each), and the gear couplings carry the loads to the output, so
their constraint forces are the tooth loads. Putting c into MuJoCo as damping
on rack A instead would not work: ``implicitfast`` applies it to that joint
alone after the constraint solve and tears the couplings apart.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from twin import friction
from twin.params import FrictionParams


@dataclasses.dataclass(frozen=True)
class Circuit:
    """The circuit for n scenarios at one instant; arrays are (n,)."""

    drive: np.ndarray  # N, F_0
    damping: np.ndarray  # N s/m, c_h (inf when a chamber is sealed)
    idle_pressure_a: np.ndarray  # Pa, chamber A pressure at zero flow (nan if sealed)
    idle_pressure_b: np.ndarray  # Pa
    conductance_a: np.ndarray  # m^3/(Pa s), g1 + g2
    conductance_b: np.ndarray  # m^3/(Pa s), g3 + g4

    @property
    def sealed(self) -> np.ndarray:
        return ~np.isfinite(self.damping)


def circuit(conductances: np.ndarray, supply_pressure: np.ndarray, bore_area: float) -> Circuit:
    """Solve the valve network; ``conductances`` (n, 4) for V1..V4, pressure (n,) in Pa."""
    g1, g2, g3, g4 = conductances.T
    g_a, g_b = g1 + g2, g3 + g4
    with np.errstate(divide="ignore", invalid="ignore"):
        idle_a = np.where(g_a > 0, g1 * supply_pressure / g_a, np.nan)
        idle_b = np.where(g_b > 0, g3 * supply_pressure / g_b, np.nan)
        damping = np.where((g_a > 0) & (g_b > 0), bore_area**2 * (1.0 / g_a + 1.0 / g_b), np.inf)
    drive = np.where(np.isfinite(damping), bore_area * (idle_a - idle_b), 0.0)
    return Circuit(drive=drive, damping=damping, idle_pressure_a=idle_a, idle_pressure_b=idle_b,
                   conductance_a=g_a, conductance_b=g_b)


@dataclasses.dataclass(frozen=True)
class RackForces:
    """One implicit step of the rack; arrays are (n,)."""

    cylinder_a: np.ndarray  # N, piston A on rack A, towards +y
    cylinder_b: np.ndarray  # N, piston B on rack B, towards -y
    pressure_a: np.ndarray  # Pa
    pressure_b: np.ndarray  # Pa
    velocity: np.ndarray  # m/s, rack velocity at the end of the step
    force_loss: np.ndarray  # N, friction force along +y (opposes motion)
    stuck: np.ndarray  # bool: friction or the sealed circuit holds the rack


def rack_step(*, circuit_now: Circuit, friction_params: FrictionParams, bore_area: float,
              y: np.ndarray, v0: np.ndarray, external_force: np.ndarray, stuck: np.ndarray,
              mass: np.ndarray, h: float, breakaway: np.ndarray | None = None) -> RackForces:
    """Forces on the racks over one step ``h`` from rack position ``y`` (m) and velocity ``v0`` (m/s).

    ``external_force`` (N) is everything else along +y (gravity through the gears);
    ``stuck`` says whether the rack was at rest (stiction applies); ``mass`` (kg)
    is the train's inertia referred to the rack; ``breakaway`` (N) the static
    friction at ``y`` if it varies along the stroke (default: the constant
    ``friction_params.stiction``).
    """
    sealed = circuit_now.sealed
    c_h = np.where(sealed, 0.0, circuit_now.damping)
    c_total = c_h + friction_params.viscous
    drive = circuit_now.drive
    momentum_force = mass * v0 / h
    # Friction force that would stop the rack in this step (damping vanishes at v1 = 0).
    to_stop = -(momentum_force + drive + external_force)
    coulomb = friction.coulomb_force(friction_params, y, -np.sign(to_stop))
    static = friction_params.stiction if breakaway is None else breakaway
    limit = np.where(stuck, np.maximum(coulomb, static), coulomb)
    sticks = sealed | (np.abs(to_stop) <= limit)
    dry = np.where(sealed, 0.0, np.where(sticks, to_stop, np.sign(to_stop) * limit))
    v1 = np.where(sticks, 0.0, (v0 + h * (drive + external_force + dry) / mass) / (1.0 + h * c_total / mass))

    hydraulic = np.where(sealed, to_stop, drive - c_h * v1)  # A (P_a - P_b)
    with np.errstate(invalid="ignore", divide="ignore"):
        flowing_a = circuit_now.idle_pressure_a - bore_area * v1 / circuit_now.conductance_a
        flowing_b = circuit_now.idle_pressure_b + bore_area * v1 / circuit_now.conductance_b
    load = hydraulic / bore_area
    a_shut = circuit_now.conductance_a <= 0
    b_shut = circuit_now.conductance_b <= 0
    pressure_a = np.where(a_shut, np.where(b_shut, np.maximum(load, 0.0), flowing_b + load), flowing_a)
    pressure_b = np.where(b_shut, np.where(a_shut, np.maximum(-load, 0.0), flowing_a - load), flowing_b)

    loss = dry - friction_params.viscous * v1
    return RackForces(
        cylinder_a=bore_area * pressure_a + 0.5 * loss,
        cylinder_b=bore_area * pressure_b - 0.5 * loss,
        pressure_a=pressure_a, pressure_b=pressure_b, velocity=v1, force_loss=loss, stuck=sticks,
    )
