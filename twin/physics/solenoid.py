"""A solenoid valve as physics: coil current and plunger motion as states, flow through the
opening the plunger uncovers (the valve test's water column adds its inertance).

Per valve, with the coil command s(t) in {0, 1} (the PWM signal) and SolenoidParams ``p``::

    coil (R-L, current as a fraction of V/R):   di/dt = (s - i) / tau     tau = tau_on rising, tau_off falling
    plunger (lift x in [0, 1] of full travel):  x'' = w^2 [ F_m - F_s ] - 2 zeta w x'
        magnetic force over spring preload:     F_m = f_m i^2 / (1 + kappa (1 - x))^2    (grows as the gap closes)
        spring over its preload:                F_s = 1 + k x
        travel stops at 0 (seat) and 1 (open): the plunger rests there while the force holds it
    opening:                                    A = x   (the seat's curtain area, a fraction of full)
    flow, laminar (linear in the pressure drop dP, as the thesis measured) through the water
    column of inertance I:                      I dQ/dt = dP - Q / (G A),   G = 1 / R(100 %)

With the column time constant tau_I = I G this reads tau_I dq/dt = 1 - q / A for q = Q / (G dP):
q = A at steady state, and q = 0 whenever the valve is shut. Nothing here is a delay or a dead
zone: the 5 ms / 2 ms delays, the ~30 % dead zone and the partial openings of short pulses
come out of pull-in (the coil's current must reach (1 + kappa) / sqrt(f_m) before the plunger
moves), drop-out (the closed gap holds it with less current) and travel. Because the
opening does not depend on dP, the period-averaged flow is exactly proportional to dP: the
twin's lines pass through zero, where the thesis's measured ones did not (they missed flows
below 1e-6 m^3/s; the offset is not modelled).

Integrated at a fixed step ``h`` (coil exactly, plunger semi-implicitly, flow implicitly, so a
shut valve stops the flow at once); compiled with numba.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from twin.physics.params import SolenoidParams


def coil_command(duty: float, ticks: int) -> np.ndarray:
    """The PWM coil signal of one period of ``ticks`` steps: on for the first duty % of it."""
    signal = np.zeros(ticks)
    signal[:int(round(duty / 100.0 * ticks))] = 1.0
    return signal


def simulate(params: SolenoidParams, coil: np.ndarray, *, h: float, periods: int = 1,
             inertance_time: float = 0.0, state: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Run the valve through ``coil`` (T,) repeated ``periods`` times from ``state`` (i, x, v, q;
    shut and at rest by default). Returns the last repetition's (T, 4) states and the final state.
    ``inertance_time`` tau_I = I G (s) of the water column; 0: the flow follows the opening (q = A)."""
    start = np.zeros(4) if state is None else np.array(state, dtype=float)
    out = np.empty((len(coil), 4))
    end = _run(np.asarray(coil, dtype=float), periods, h, float(params.coil_time_constant_on),
               float(params.coil_time_constant_off), float(params.force_ratio), float(params.gap_ratio),
               float(params.spring_ratio), float(params.natural_frequency), float(params.damping_ratio),
               float(inertance_time), start, out)
    return out, end


def delays(params: SolenoidParams, *, h: float, limit: float = 30e-3) -> tuple[float, float]:
    """(opening, closing) delay in s: coil on from shut and at rest until fully open; coil off from
    open and steady until shut. nan if it never gets there within ``limit``."""
    ticks = int(round(limit / h))
    opening, _ = simulate(params, np.ones(ticks), h=h)
    closing, _ = simulate(params, np.zeros(ticks), h=h, state=np.array([1.0, 1.0, 0.0, 1.0]))
    open_at = np.flatnonzero(opening[:, 1] >= 1.0)
    shut_at = np.flatnonzero(closing[:, 1] <= 0.0)
    return ((open_at[0] + 1) * h if open_at.size else math.nan, (shut_at[0] + 1) * h if shut_at.size else math.nan)


def mean_flow_fraction(params: SolenoidParams, duty: float, *, period: float, h: float, inertance_time: float,
                       periods: int = 4) -> float:
    """Period-averaged flow over the flow of the valve held open, at PWM ``duty`` %, once the
    valve's cycle has settled (the last of ``periods`` periods)."""
    ticks = int(round(period / h))
    states, _ = simulate(params, coil_command(duty, ticks), h=h, periods=periods, inertance_time=inertance_time)
    return float(states[:, 3].mean())


def largest_lift(params: SolenoidParams, duty: float, *, period: float, h: float, periods: int = 3) -> float:
    """The plunger's largest lift (a fraction of full travel) in the last of ``periods`` PWM periods of
    ``duty`` %, from shut and at rest: 0 for a pulse too short to move it."""
    ticks = int(round(period / h))
    states, _ = simulate(params, coil_command(duty, ticks), h=h, periods=periods)
    return float(states[:, 1].max())


@numba.njit(cache=True, inline="always")
def _step(s, i, x, v, h, rise, fall, force_ratio, gap_ratio, spring_ratio, omega, zeta):  # pragma: no cover
    """One step of coil and plunger (the module docstring's equations); returns (i, x, v)."""
    i += (s - i) * (rise if s > i else fall)
    gap = 1.0 + gap_ratio * (1.0 - x)
    force = force_ratio * i * i / (gap * gap) - (1.0 + spring_ratio * x)
    v += h * (omega * omega * force - 2.0 * zeta * omega * v)
    x += h * v
    if x <= 0.0:
        x = 0.0
        v = max(v, 0.0) if force > 0.0 else 0.0
    elif x >= 1.0:
        x = 1.0
        v = min(v, 0.0) if force < 0.0 else 0.0
    return i, x, v


@numba.njit(cache=True)
def _run(coil, periods, h, tau_on, tau_off, force_ratio, gap_ratio, spring_ratio, omega, zeta, tau_i, state,
         out):  # pragma: no cover - compiled
    i, x, v, q = state[0], state[1], state[2], state[3]
    rise, fall = 1.0 - math.exp(-h / tau_on), 1.0 - math.exp(-h / tau_off)
    for _ in range(periods):
        for k in range(coil.shape[0]):
            i, x, v = _step(coil[k], i, x, v, h, rise, fall, force_ratio, gap_ratio, spring_ratio, omega, zeta)
            if x <= 0.0:
                q = 0.0
            elif tau_i > 0.0:
                q = (q + h / tau_i) / (1.0 + h / (tau_i * x))
            else:
                q = x
            out[k, 0], out[k, 1], out[k, 2], out[k, 3] = i, x, v, q
    state_out = np.empty(4)
    state_out[0], state_out[1], state_out[2], state_out[3] = i, x, v, q
    return state_out


@numba.njit(cache=True)
def tick_openings(coil, substeps, h, tau_on, tau_off, force_ratio, gap_ratio, spring_ratio, omega, zeta, state,
                  opening, live):  # pragma: no cover - compiled
    """Every valve through one control tick of ``substeps`` steps of ``h`` with its coil ``coil`` (n, 4)
    held; ``state`` (n, 4, 3) = (i, x, v) in place; ``opening`` (n, 4) = the tick's mean lift x (its
    mean opening area, a fraction of full). The plant's own inertia stands in for the water column.
    Scenarios whose ``live`` (n,) is False are left as they are, with an opening of 0 (a run that has
    ended: nobody reads them).

    A valve at rest on the stop its coil holds it to (shut with the coil off, open with it on) stays
    there while the magnetic force keeps holding it: those steps advance only the coil current, the
    same arithmetic as :func:`_step`, so the numbers are identical and idle or held valves cost little."""
    rise, fall = 1.0 - math.exp(-h / tau_on), 1.0 - math.exp(-h / tau_off)
    for a in range(coil.shape[0]):
        if not live[a]:
            opening[a, :] = 0.0
            continue
        for b in range(coil.shape[1]):
            s = coil[a, b]
            i, x, v = state[a, b, 0], state[a, b, 1], state[a, b, 2]
            total = 0.0
            k = 0
            if v == 0.0 and ((s == 0.0 and x == 0.0) or (s == 1.0 and x == 1.0)):
                # At rest on the stop its coil holds it to: while the force keeps holding it there, a step
                # only moves the current (the rest of _step leaves x and v as they are), so only that is
                # done. The same numbers as _step, without the plunger's arithmetic.
                gap = 1.0 + gap_ratio * (1.0 - x)
                while k < substeps:
                    i_next = i + (s - i) * (rise if s > i else fall)
                    force = force_ratio * i_next * i_next / (gap * gap) - (1.0 + spring_ratio * x)
                    if (x == 0.0 and force > 0.0) or (x == 1.0 and force < 0.0):
                        break
                    if i_next == i:
                        # The current has stopped changing (it has settled to its last bit): every step
                        # left would repeat this one exactly, so they are added at once. total is k x with
                        # x 0 or 1, a whole number, so this sum is exact: the same bits as stepping on.
                        total += x * (substeps - k)
                        k = substeps
                        break
                    i = i_next
                    total += x
                    k += 1
            for _ in range(k, substeps):
                i, x, v = _step(s, i, x, v, h, rise, fall, force_ratio, gap_ratio, spring_ratio, omega, zeta)
                total += x
            state[a, b, 0], state[a, b, 1], state[a, b, 2] = i, x, v
            opening[a, b] = total / substeps
