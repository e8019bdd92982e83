"""The four solenoid valves: from a signed duty command to flow conductances.

V1 supplies cylinder A, V2 drains A, V3 supplies B, V4 drains B (§3). A
command ``u > 0`` (percent) opens the pair V1 + V4 (rack A extends, theta
grows), ``u < 0`` the pair V3 + V2. The supply valve of the pair is fully on;
only the discharge valve is modulated. ``|u|`` above 100 % is clipped to 100 %
(a valve cannot be more than always open).

Two named valve models, both with the opening and closing delays of §3:

``averaged`` (the thesis's model)
    The discharge valve is a steady resistance R(|u|) of eq. 4.4.2 for the
    whole PWM period: the PWM is averaged out. Commands with |u| below
    ``dead_zone_duty`` leave the valve shut.
Both realise the duty in whole switching periods (``switching_period``, the
DAQ's 1 ms output tick: 6.25 % steps of a 16 ms period); a duty under half a
step sends no pulse. ``switching_period = 0`` makes the averaged valve
continuous (a sensitivity variant).

``pwm`` (time-resolved)
    Each valve is either shut or fully open (R(100 %)); the discharge valve's
    coil is on for the first |u| x period of each period. A pulse shorter than
    ``dead_zone_duty`` x period is not sent: the real valve does not open (§3).

``solenoid`` (physical, :mod:`twin.physics.solenoid`)
    The coils get the same signals as ``pwm`` (the discharge coil on while the
    period's elapsed time is below the duty in force, so a controller updating
    every 1 ms acts inside the period; the pair's supply coil on while any duty
    is commanded), but no delay or dead zone is imposed: each valve's coil
    current and plunger are integrated through the tick, and its conductance is
    R(100 %)^-1 times the tick's mean opening. ``dead_zone_duty`` and the delays
    are not used; they come out of the physics.

In ``averaged`` and ``pwm``, while the discharge valve gets no pulse (|u| below the dead zone, or
under half a switching step), the pair's supply valve shuts with it, or stays
on if ``supply_held_in_dead_zone`` (§3: the supply valve of the pair "stays
fully on"; only a compressible plant moves differently).

Delays act on the coil signal: a shut valve opens once its coil has been on
for ``opening_delay``, an open valve shuts once its coil has been off for
``closing_delay`` (a state machine per valve). So a coil pulse shorter than the
opening delay never opens the valve, and a gap shorter than the closing delay
never shuts it (>= 7 ms per on/off cycle, §3). While open, a valve has the
conductance of its coil's latest command. The per-tick update is one compiled
loop over the scenarios (numba), like the hydraulics it feeds.
"""

from __future__ import annotations

import enum

import numba
import numpy as np

from twin.exceptions import InvalidScenario
from twin.physics import solenoid
from twin.physics.params import ValveParams
from twin.physics.scenario_axis import per_scenario
from twin.physics.ticks import whole_ticks

SUPPLY_A, DRAIN_A, SUPPLY_B, DRAIN_B = range(4)  # V1, V2, V3, V4


class ValveModel(enum.Enum):
    AVERAGED = "averaged"
    PWM = "pwm"
    SOLENOID = "solenoid"


class ValveBank:
    """Four valves for each of ``n`` scenarios; call :meth:`update` once per tick.

    State, (n, 4) arrays updated in place every tick: how many ticks each coil has been on and off,
    whether each valve is open, and each coil's latest conductance in m^3/(Pa s).
    """

    def __init__(self, *, params: ValveParams, model: ValveModel, n: int, tick: float):
        self.params = params
        self.model = model
        self.n = n
        self.period_ticks = whole_ticks(params.pwm_period, tick, what="PWM period")
        self.open_ticks = round(params.opening_delay / tick)
        self.close_ticks = round(params.closing_delay / tick)
        if abs(self.open_ticks * tick - params.opening_delay) > 1e-12 or abs(self.close_ticks * tick - params.closing_delay) > 1e-12:
            raise InvalidScenario("valve delays must be whole numbers of ticks")
        self.full_conductance = 1.0 / params.open_resistance
        if params.switching_period > 0:
            self.duty_steps = whole_ticks(params.pwm_period, params.switching_period, what="PWM period")
            whole_ticks(params.switching_period, tick, what="valve switching period")
        elif model in (ValveModel.PWM, ValveModel.SOLENOID):
            raise InvalidScenario(f"the {model.value} valve needs a switching period")
        else:
            self.duty_steps = 0  # continuous duty
        self.tick = tick
        self.substeps = max(1, round(tick / params.solenoid.step))
        self._plunger = np.zeros((n, 4, 3))  # solenoid model: coil current, lift, lift speed of each valve
        self._on_run = np.zeros((n, 4), dtype=np.int64)  # ticks the coil has been on, this one included
        self._off_run = np.full((n, 4), 1 << 30, dtype=np.int64)
        self._open = np.zeros((n, 4), dtype=bool)
        self._conductance = np.zeros((n, 4))
        self._every = np.ones(n, dtype=np.bool_)  # ``live`` when every scenario is

    def reset(self) -> None:
        self._plunger[:] = 0.0
        self._on_run[:] = 0
        self._off_run[:] = 1 << 30
        self._open[:] = False
        self._conductance[:] = 0.0

    def update(self, tick: int, duty: np.ndarray, live: np.ndarray | None = None) -> np.ndarray:
        """Valve conductances (n, 4) in m^3/(Pa s) at integer ``tick`` for signed ``duty`` (n,) in %.
        ``live`` (n,) bool: the solenoid valves of scenarios where it is False are not advanced (runs that
        have ended; their conductance is 0); None: every scenario is."""
        p = self.params
        out = np.empty((self.n, 4))
        duty = per_scenario(duty, self.n)  # read unchecked when compiled
        if self.model is ValveModel.SOLENOID:
            s = p.solenoid
            coil = np.empty((self.n, 4))
            _solenoid_coils(duty, int(tick), self.duty_steps, self.period_ticks, coil)
            solenoid.tick_openings(coil, self.substeps, self.tick / self.substeps, s.coil_time_constant_on,
                                   s.coil_time_constant_off, s.force_ratio, s.gap_ratio, s.spring_ratio,
                                   s.natural_frequency, s.damping_ratio, self._plunger, out,
                                   self._every if live is None else live)
            return out * self.full_conductance
        _valve_tick(duty, int(tick), self.duty_steps, self.period_ticks, self.model is ValveModel.AVERAGED,
                    float(p.dead_zone_duty), bool(p.supply_held_in_dead_zone),
                    float(p.resistance_coefficient), float(p.resistance_exponent),
                    float(self.full_conductance), self.open_ticks, self.close_ticks,
                    self._on_run, self._off_run, self._open, self._conductance, out)
        return out


@numba.njit(cache=True)
def _coil(magnitude, tick, duty_steps, period_ticks, averaged, dead_zone, hold_supply, coefficient, exponent,
          full):  # pragma: no cover - compiled
    """(supply, drain) coil conductance of the open pair with no delay, for |duty| ``magnitude`` <= 100 %."""
    if duty_steps:  # the coil switches on the DAQ's tick: a period of S ticks realises duties in 100/S % steps
        realised = np.rint(magnitude / 100.0 * duty_steps) * (100.0 / duty_steps)
    else:
        realised = magnitude
    if not (realised > 0 and magnitude >= dead_zone):
        return (full if hold_supply and magnitude > 0 else 0.0), 0.0
    if averaged:  # eq. 4.4.2 for the whole period
        return full, 1.0 / (coefficient * max(realised, 1e-9) ** exponent)
    in_pulse = (tick % period_ticks) < np.rint(realised / 100.0 * period_ticks)
    return full, full if in_pulse else 0.0


@numba.njit(cache=True)
def _valve_tick(duty, tick, duty_steps, period_ticks, averaged, dead_zone, hold_supply, coefficient, exponent, full,
                open_ticks, close_ticks, on_run, off_run, is_open, conductance, out):  # pragma: no cover - compiled
    """One tick of every valve, in place on the delay state; ``out`` (n, 4) the conductances in force."""
    for i in range(duty.shape[0]):
        supply, drain = _coil(min(abs(duty[i]), 100.0), tick, duty_steps, period_ticks, averaged, dead_zone,
                              hold_supply, coefficient, exponent, full)
        coil = (supply if duty[i] > 0 else 0.0, drain if duty[i] < 0 else 0.0,
                supply if duty[i] < 0 else 0.0, drain if duty[i] > 0 else 0.0)  # V1..V4
        for j in range(4):
            on = coil[j] > 0.0
            on_run[i, j] = on_run[i, j] + 1 if on else 0
            off_run[i, j] = 0 if on else off_run[i, j] + 1
            opens = not is_open[i, j] and on_run[i, j] > open_ticks
            shuts = is_open[i, j] and off_run[i, j] > close_ticks
            is_open[i, j] = (is_open[i, j] or opens) and not shuts
            if on:
                conductance[i, j] = coil[j]
            out[i, j] = conductance[i, j] if is_open[i, j] else 0.0


@numba.njit(cache=True)
def _solenoid_coils(duty, tick, duty_steps, period_ticks, coil):  # pragma: no cover - compiled
    """Coil signals (n, 4) of the solenoid model: V1..V4, 1.0 on. The pair's supply coil is on while
    the realised duty is not zero; its discharge coil while the period's elapsed ticks are below the
    duty in force."""
    for i in range(duty.shape[0]):
        magnitude = min(abs(duty[i]), 100.0)
        on = np.rint(magnitude / 100.0 * duty_steps) * (100.0 / duty_steps) > 0.0
        in_pulse = on and (tick % period_ticks) < np.rint(magnitude / 100.0 * period_ticks)
        supply = 1.0 if on else 0.0
        drain = 1.0 if in_pulse else 0.0
        coil[i, 0] = supply if duty[i] > 0 else 0.0
        coil[i, 1] = drain if duty[i] < 0 else 0.0
        coil[i, 2] = supply if duty[i] < 0 else 0.0
        coil[i, 3] = drain if duty[i] > 0 else 0.0
