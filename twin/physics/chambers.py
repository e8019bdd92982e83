"""Compressible chambers and a dynamic supply (the ``as-built`` plant, §3, §4).

The thesis's water is incompressible: a chamber's pressure follows from the
flow balance at once and a sealed chamber locks the joint. Here the chamber
pressures P_a, P_b and the supply's state are integrated in time::

    dP_a/dt = beta(P_a) / V_a(y) (g1 (P_s - P_a) - (g2 + g_leak) P_a - A v)
    dP_b/dt = beta(P_b) / V_b(y) (g3 (P_s - P_b) - (g4 + g_leak) P_b + A v)
    M dv/dt = A (P_a - P_b) - F_v v - F_dry + F_ext
    L dq/dt = P_0 - P_s - R q,      C dP_s/dt = q - g1 (P_s - P_a) - g3 (P_s - P_b)

with V_a = V_0 + A (y - y_min), V_b = V_0 + A (y_max - y), free air lowering
beta at low pressure (:class:`twin.physics.params.ChamberParams`), and the supply line of
:class:`twin.physics.params.SupplyLineParams` (``constant``: P_s = P_0).

Integration: the hydraulic natural frequency reaches about 1 kHz (air-free
water, 0.3 mL dead volume), above the 1 ms physics tick, so each tick is split into ``substeps`` implicit-Euler steps of
the rack along the gear-coupled coordinate together with the two chamber
pressures (one linear 3x3 system, solved in closed form: each pressure is
affine in the new velocity), with the friction complementarity of
:func:`twin.physics.hydraulics.rack_step`; the supply line is stepped implicitly after
each sub-step with that sub-step's flow (its time constants are far longer).
MuJoCo then steps once with the sub-steps' mean piston forces, which gives the
rack the sub-steps' final velocity. The pressures integrate the sub-steps'
own displacement (so they stay consistent with the motion that made them);
MuJoCo's semi-implicit step moves the rack h v_end instead, a difference that
telescopes over ticks (at most h |dv| / 2, 0.1 mm at 0.15 m/s) rather than
accumulating. (Correcting the pressures for it each tick would inject
megapascal jumps: beta A / V is 6e10 Pa/m for air-free water.)
``tests/test_as_built.py`` compares the default (100 sub-steps, 10 us) with 2000.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

import numba
import numpy as np

from twin.physics import friction
from twin.physics.params import ChamberParams, FrictionParams, SupplyLineParams

VAPOUR_MARGIN = 2e3  # Pa above absolute zero: the lowest chamber pressure (cavitation)


@dataclasses.dataclass
class ChamberState:
    """The hydraulic state of n scenarios between ticks; arrays are (n,)."""

    pressure_a: np.ndarray  # Pa gauge
    pressure_b: np.ndarray  # Pa gauge
    supply_pressure: np.ndarray  # Pa gauge, at the valve block
    line_flow: np.ndarray  # m^3/s into the valve block from the supply cylinder


@dataclasses.dataclass(frozen=True)
class TickForces:
    cylinder_a: np.ndarray  # N, mean over the tick
    cylinder_b: np.ndarray  # N
    velocity: np.ndarray  # m/s at the end of the tick
    stuck: np.ndarray  # bool


class CompressibleCircuit:
    """Chambers, rack and supply line of n scenarios that share one plant's parameters."""

    def __init__(self, *, chambers: ChamberParams, line: SupplyLineParams, friction_params: FrictionParams,
                 bore_area: float, stroke: tuple[float, float], supply: np.ndarray, initial_pressure: np.ndarray):
        self.chambers, self.friction = chambers, friction_params
        self.area, self.stroke = bore_area, stroke
        self.source = np.asarray(supply, dtype=float)  # P_0, Pa
        self.state = ChamberState(
            pressure_a=np.array(initial_pressure, dtype=float), pressure_b=np.array(initial_pressure, dtype=float),
            supply_pressure=self.source.copy(), line_flow=np.zeros_like(self.source))
        compliance = line.compliance + (line.accumulator_compliance if line.model == "accumulator" else 0.0)
        self._line = None if line.model == "constant" else (compliance, line.inertance, line.resistance)
        self._every = np.ones(len(self.source), dtype=np.bool_)  # ``live`` when every scenario is

    def volumes(self, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Chamber volumes (m^3) at rack position ``y``; never below a tenth of the dead volume."""
        v0, (low, high) = self.chambers.dead_volume, self.stroke
        return (np.maximum(v0 + self.area * (y - low), 0.1 * v0),
                np.maximum(v0 + self.area * (high - y), 0.1 * v0))

    def step_supply(self, delta: float, outflow: np.ndarray) -> None:
        """Advance the supply line by ``delta`` with ``outflow`` (m^3/s) into the chambers."""
        if self._line is None:
            return
        s = self.state
        for i in range(len(s.supply_pressure)):
            s.supply_pressure[i], s.line_flow[i] = _line_step(
                s.supply_pressure[i], s.line_flow[i], self.source[i], float(outflow[i]), delta, *self._line)

    def tick(self, *, conductance: np.ndarray, y: np.ndarray, v0: np.ndarray, external_force: np.ndarray,
             stuck: np.ndarray, mass: np.ndarray, h: float,
             breakaway: Callable[[np.ndarray], np.ndarray], live: np.ndarray | None = None) -> TickForces:
        """Advance one physics tick ``h``; ``conductance`` (n, 4) for V1..V4 in m^3/(Pa s),
        ``breakaway(y)`` the static friction (N) at rack positions y. Scenarios whose ``live`` (n,) is
        False (runs that have ended) are not advanced: their state stays, their forces are 0, their
        velocity and stuck flag those given; None: every scenario is advanced.

        Chamber volumes, Coulomb friction and breakaway are taken at the tick's start
        position (the rack moves at most 0.15 mm in a tick: 0.5 % of a chamber); both carry the load
        friction of ``external_force`` (:func:`twin.physics.friction.load_friction`)."""
        s, ch, fp = self.state, self.chambers, self.friction
        va, vb = self.volumes(y)
        forward, backward, static = friction.dry_limits(fp, y, external_force, np.asarray(breakaway(y), dtype=float))
        line = self._line if self._line is not None else (1.0, 1.0, 0.0)
        out = np.empty((4, len(y)))
        _substeps(
            s.pressure_a, s.pressure_b, s.supply_pressure, s.line_flow, np.ascontiguousarray(conductance, dtype=float),
            va, vb, np.asarray(y, dtype=float), self.stroke[0], self.stroke[1],
            forward, backward,
            static, np.asarray(v0, dtype=float), np.asarray(stuck, dtype=np.bool_),
            np.asarray(mass, dtype=float), np.asarray(external_force, dtype=float), self.source,
            self.area, fp.viscous, h / ch.substeps, ch.substeps, ch.leak_conductance,
            ch.air_fraction * ch.atmospheric_pressure, 1.0 / ch.water_bulk_modulus, ch.atmospheric_pressure,
            VAPOUR_MARGIN - ch.atmospheric_pressure, self._line is not None, *line,
            self._every if live is None else np.asarray(live, dtype=np.bool_), out)
        return TickForces(cylinder_a=out[0], cylinder_b=out[1], velocity=out[2], stuck=out[3] > 0.5)


@numba.njit(cache=True)
def _line_step(pressure, flow, source, outflow, delta, compliance, inertance, resistance):  # pragma: no cover
    """Implicit Euler of L dq/dt = P_0 - P_s - R q, C dP_s/dt = q - outflow: the new (P_s, q)."""
    a, b, c = delta / inertance, delta * resistance / inertance, delta / compliance
    pressure = (pressure - c * outflow + c * (flow + a * source) / (1.0 + b)) / (1.0 + c * a / (1.0 + b))
    return pressure, (flow + a * (source - pressure)) / (1.0 + b)


@numba.njit(cache=True)
def _rack_solve(momentum, v, push, damping, forward, backward, static, stuck):  # pragma: no cover - compiled
    """Implicit rack velocity with Coulomb friction and stiction (as :func:`twin.physics.hydraulics.rack_step`):
    (v_new, dry friction force, stuck)."""
    to_stop = -(momentum * v + push)
    limit = backward if to_stop > 0 else forward  # friction opposes what to_stop resists
    if stuck:
        limit = max(limit, static)
    if abs(to_stop) <= limit:
        return 0.0, to_stop, True
    dry = limit if to_stop > 0 else -limit
    return (momentum * v + push + dry) / (momentum + damping), dry, False


@numba.njit(cache=True)
def _substeps(pa, pb, ps, q, conductance, va, vb, y, low, high, forward, backward, static, v0, stuck0, mass,
              external, source, area, viscous, delta, n_sub, leak, air, inverse_water, p_atm, floor, has_line,
              compliance, inertance, resistance, live, out):  # pragma: no cover - compiled
    """The sub-steps of one tick for every scenario whose ``live`` is True, in place on pa, pb, ps, q;
    ``out`` rows: mean piston force A, mean piston force B, final velocity, stuck (0/1); a scenario that
    is not live keeps its state, with forces 0 and its v0 and stuck. See :class:`CompressibleCircuit`.

    A pressure that would fall below the vapour floor is held there and the step re-solved with it
    fixed (so the forces stay consistent with the velocity); at a stroke end the rack does not move
    outwards (MuJoCo's joint limit holds it), so no flow is invented there."""
    for i in range(pa.shape[0]):
        if not live[i]:
            out[0, i], out[1, i], out[2, i], out[3, i] = 0.0, 0.0, v0[i], 1.0 if stuck0[i] else 0.0
            continue
        g1, g2, g3, g4 = conductance[i, 0], conductance[i, 1], conductance[i, 2], conductance[i, 3]
        fill_a, fill_b = g1 + g2 + leak, g3 + g4 + leak
        momentum = mass[i] / delta
        v, stuck, position = v0[i], stuck0[i], y[i]
        sum_pa = sum_pb = sum_loss = 0.0
        for _ in range(n_sub):
            a0, b0, s0 = pa[i], pb[i], ps[i]
            ka = delta / (va[i] * (inverse_water + air / (a0 + p_atm) ** 2))  # delta beta(P) / V
            kb = delta / (vb[i] * (inverse_water + air / (b0 + p_atm) ** 2))
            den_a, den_b = 1.0 + ka * fill_a, 1.0 + kb * fill_b
            alpha_a, gamma_a = (a0 + ka * g1 * s0) / den_a, ka * area / den_a
            alpha_b, gamma_b = (b0 + kb * g3 * s0) / den_b, kb * area / den_b
            start_v, start_stuck = v, stuck
            for _attempt in range(3):  # at most two pressures to pin to the floor
                v, dry, stuck = _rack_solve(momentum, start_v, area * (alpha_a - alpha_b) + external[i],
                                            area * (gamma_a + gamma_b) + viscous, forward[i], backward[i],
                                            static[i], start_stuck)
                if (position >= high and v > 0.0) or (position <= low and v < 0.0):
                    v, dry = 0.0, 0.0
                if alpha_a - gamma_a * v < floor and gamma_a != 0.0:
                    alpha_a, gamma_a = floor, 0.0
                elif alpha_b + gamma_b * v < floor and gamma_b != 0.0:
                    alpha_b, gamma_b = floor, 0.0
                else:
                    break
            pa[i] = max(alpha_a - gamma_a * v, floor)
            pb[i] = max(alpha_b + gamma_b * v, floor)
            sum_pa += pa[i]
            sum_pb += pb[i]
            sum_loss += dry - viscous * v
            position += delta * v
            if has_line:
                ps[i], q[i] = _line_step(s0, q[i], source[i], g1 * (s0 - pa[i]) + g3 * (s0 - pb[i]), delta,
                                         compliance, inertance, resistance)
        mean_loss = sum_loss / n_sub
        out[0, i] = area * sum_pa / n_sub + 0.5 * mean_loss
        out[1, i] = area * sum_pb / n_sub - 0.5 * mean_loss
        out[2, i] = v
        out[3, i] = 1.0 if stuck else 0.0
