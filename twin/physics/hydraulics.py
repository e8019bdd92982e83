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

The network and the step run as one compiled loop over the scenarios (numba):
as numpy they were ~80 array calls per tick, as much as MuJoCo's own step for a
batch of 90. The loop does the same float operations in the same order as the
numpy form did, so the numbers did not change (checked bit for bit). The
Coulomb force of eq. 4.5.7 comes in from :mod:`twin.physics.friction`, its one home.
"""

from __future__ import annotations

import dataclasses
import functools
import math

import numba
import numpy as np

from twin.physics import friction
from twin.physics.params import FrictionParams, JointParams
from twin.physics.scenario_axis import per_scenario


@numba.njit(cache=True)
def _network(g1, g2, g3, g4, supply, area):  # pragma: no cover - compiled
    """(F_0, c_h, idle P_a, idle P_b) of one scenario; c_h = inf and idle pressure nan where sealed."""
    g_a, g_b = g1 + g2, g3 + g4
    idle_a = g1 * supply / g_a if g_a > 0 else np.nan
    idle_b = g3 * supply / g_b if g_b > 0 else np.nan
    if g_a > 0 and g_b > 0:
        damping = area**2 * (1.0 / g_a + 1.0 / g_b)
        return area * (idle_a - idle_b), damping, idle_a, idle_b
    return 0.0, np.inf, idle_a, idle_b


@numba.njit(cache=True)
def _networks(conductances, supply, area, out):  # pragma: no cover - compiled
    for i in range(conductances.shape[0]):
        out[0, i], out[1, i], out[2, i], out[3, i] = _network(
            conductances[i, 0], conductances[i, 1], conductances[i, 2], conductances[i, 3], supply[i], area)


@dataclasses.dataclass(frozen=True)
class Circuit:
    """The valve network of n scenarios at one instant: conductances (n, 4) of V1..V4 in
    m^3/(Pa s) and the supply pressure (n,) in Pa; the solved quantities are (n,)."""

    conductances: np.ndarray
    supply_pressure: np.ndarray
    bore_area: float  # m^2

    @functools.cached_property
    def _solved(self) -> np.ndarray:
        out = np.empty((4, len(self.supply_pressure)))
        _networks(self.conductances, self.supply_pressure, self.bore_area, out)
        return out

    @property
    def drive(self) -> np.ndarray:
        return self._solved[0]  # N, F_0

    @property
    def damping(self) -> np.ndarray:
        return self._solved[1]  # N s/m, c_h (inf when a chamber is sealed)

    @property
    def idle_pressure_a(self) -> np.ndarray:
        return self._solved[2]  # Pa, chamber A pressure at zero flow (nan if its valves are shut)

    @property
    def idle_pressure_b(self) -> np.ndarray:
        return self._solved[3]  # Pa

    @property
    def sealed(self) -> np.ndarray:
        return ~np.isfinite(self.damping)


def circuit(conductances: np.ndarray, supply_pressure: np.ndarray, bore_area: float) -> Circuit:
    """The valve network; ``conductances`` (n, 4) for V1..V4, pressure (n,) in Pa."""
    g = np.array(conductances, dtype=float)  # a copy: the circuit is solved when first read
    return Circuit(conductances=g, supply_pressure=np.array(per_scenario(supply_pressure, len(g))),
                   bore_area=float(bore_area))


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


@numba.njit(cache=True)
def _rack_steps(conductances, supply, area, viscous, forward, backward, v0, external, stuck, mass, h,
                breakaway, out, stuck_out):  # pragma: no cover - compiled
    """:func:`rack_step` for every scenario; ``forward``/``backward`` the Coulomb force moving towards
    +y / -y; ``out`` rows: cylinder A, cylinder B, P_a, P_b, v1, loss."""
    for i in range(v0.shape[0]):
        g1, g2, g3, g4 = conductances[i, 0], conductances[i, 1], conductances[i, 2], conductances[i, 3]
        drive, damping, idle_a, idle_b = _network(g1, g2, g3, g4, supply[i], area)
        g_a, g_b = g1 + g2, g3 + g4
        sealed = not np.isfinite(damping)
        c_h = 0.0 if sealed else damping
        # Friction force that would stop the rack in this step (damping vanishes at v1 = 0).
        to_stop = -(mass[i] * v0[i] / h + drive + external[i])
        coulomb = backward[i] if to_stop > 0 else forward[i]  # friction opposes what to_stop resists
        limit = max(coulomb, breakaway[i]) if stuck[i] else coulomb
        sticks = sealed or abs(to_stop) <= limit
        if sealed:
            dry = 0.0
        elif sticks:
            dry = to_stop
        else:
            dry = np.sign(to_stop) * limit
        v1 = 0.0 if sticks else (v0[i] + h * (drive + external[i] + dry) / mass[i]) / (1.0 + h * (c_h + viscous) / mass[i])
        load = (to_stop if sealed else drive - c_h * v1) / area  # A (P_a - P_b) / A
        if g_a <= 0:
            pressure_a = max(load, 0.0) if g_b <= 0 else idle_b + area * v1 / g_b + load
        else:
            pressure_a = idle_a - area * v1 / g_a
        if g_b <= 0:
            pressure_b = max(-load, 0.0) if g_a <= 0 else idle_a - area * v1 / g_a - load
        else:
            pressure_b = idle_b + area * v1 / g_b
        loss = dry - viscous * v1
        out[0, i] = area * pressure_a + 0.5 * loss
        out[1, i] = area * pressure_b - 0.5 * loss
        out[2, i], out[3, i], out[4, i], out[5, i] = pressure_a, pressure_b, v1, loss
        stuck_out[i] = sticks


def rack_step(*, circuit_now: Circuit, friction_params: FrictionParams, bore_area: float,
              y: np.ndarray, v0: np.ndarray, external_force: np.ndarray, stuck: np.ndarray,
              mass: np.ndarray, h: float, breakaway: np.ndarray | None = None) -> RackForces:
    """Forces on the racks over one step ``h`` from rack position ``y`` (m) and velocity ``v0`` (m/s).

    ``external_force`` (N) is everything else along +y (gravity through the gears);
    ``stuck`` says whether the rack was at rest (stiction applies); ``mass`` (kg)
    is the train's inertia referred to the rack; ``breakaway`` (N) the static
    friction at ``y`` if it varies along the stroke (default: the constant
    ``friction_params.stiction``). Coulomb friction is eq. 4.5.7 as
    :func:`twin.physics.friction.coulomb_force` gives it, in the direction it acts; the load friction of
    ``external_force`` (:func:`twin.physics.friction.load_friction`) adds to it and to the breakaway.
    """
    n = len(y)

    def each(x, dtype=float):  # (n,) contiguous: the compiled loop reads x[i] unchecked
        return per_scenario(x, n, dtype)

    forward, backward, static = (each(f) for f in friction.dry_limits(  # eq. 4.5.7 and the load friction
        friction_params, y, external_force, friction_params.stiction if breakaway is None else breakaway))
    out, stuck_out = np.empty((6, n)), np.empty(n, dtype=np.bool_)
    _rack_steps(circuit_now.conductances, circuit_now.supply_pressure, float(bore_area),
                float(friction_params.viscous), forward, backward, each(v0), each(external_force),
                each(stuck, np.bool_), each(mass), float(h), static, out, stuck_out)
    return RackForces(cylinder_a=out[0], cylinder_b=out[1], pressure_a=out[2], pressure_b=out[3],
                      velocity=out[4], force_loss=out[5], stuck=stuck_out)


def full_duty_speed(params: JointParams, supply_pressure: float, window: tuple[float, float],
                    coulomb_scale: float = 1.0) -> float:
    """The rack's mean speed (m/s) over ``window`` (m of rack travel) with both valves of the pair at 100 %,
    in eq. 4.3.6's quasi-steady state (the rack's mass too small to matter):
    ``v(y) = (P_ws A - s F_c(y)) / (F_v + 2 R(100) A^2)``, the mean being the travel over the integral of
    dy / v(y); ``s`` scales eq. 4.5.7's Coulomb level (``coulomb_scale``, as the CCW variant does). 0 if the
    drive cannot overcome the friction somewhere in the window. The thesis's model only: it takes F_c
    towards +y (not ``params.friction.ccw_coulomb_scale``) and no stiction, load friction, compressibility or
    supply line. The trapezoid's sum is exactly rounded (math.fsum) and every other step elementwise, so the
    result does not depend on the machine's summation order (a bound worked out from it is a box's edge)."""
    low, high = window
    y = np.linspace(low, high, 2001)
    area = params.cylinder.bore_area
    drive = supply_pressure * area - coulomb_scale * friction.coulomb_level(params.friction, y)
    if np.min(drive) <= 0.0:
        return 0.0
    slowness = (params.friction.viscous + 2.0 * params.valves.open_resistance * area**2) / drive  # dt/dy
    return float((high - low) / math.fsum(((slowness[1:] + slowness[:-1]) * np.diff(y) / 2.0).tolist()))
