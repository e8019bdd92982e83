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

Delays act on the coil signal: a shut valve opens once its coil has been on
for ``opening_delay``, an open valve shuts once its coil has been off for
``closing_delay`` (a state machine per valve). So a coil pulse shorter than the
opening delay never opens the valve, and a gap shorter than the closing delay
never shuts it (>= 7 ms per on/off cycle, §3). While open, a valve has the
conductance of its coil's latest command.
"""

from __future__ import annotations

import enum

import numpy as np

from twin.exceptions import InvalidScenario
from twin.params import ValveParams
from twin.ticks import whole_ticks

SUPPLY_A, DRAIN_A, SUPPLY_B, DRAIN_B = range(4)  # V1, V2, V3, V4


class ValveModel(enum.Enum):
    AVERAGED = "averaged"
    PWM = "pwm"


class ValveBank:
    """Four valves for each of ``n`` scenarios; call :meth:`update` once per tick.

    State: the coil conductance history (n, 4, n_open + 1) in m^3/(Pa s).
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
        elif model is ValveModel.PWM:
            raise InvalidScenario("the time-resolved PWM valve needs a switching period")
        else:
            self.duty_steps = 0  # continuous duty
        self._on_run = np.zeros((n, 4), dtype=np.int64)  # ticks the coil has been on, this one included
        self._off_run = np.full((n, 4), 1 << 30, dtype=np.int64)
        self._open = np.zeros((n, 4), dtype=bool)
        self._conductance = np.zeros((n, 4))

    def reset(self) -> None:
        self._on_run[:] = 0
        self._off_run[:] = 1 << 30
        self._open[:] = False
        self._conductance[:] = 0.0

    def _coil_conductance(self, tick: int, duty: np.ndarray) -> np.ndarray:
        """Conductance each valve would have with no delay, (n, 4)."""
        magnitude = np.minimum(np.abs(duty), 100.0)
        if self.duty_steps:  # the coil switches on the DAQ's tick: a period of S ticks realises duties in 100/S % steps
            realised = np.rint(magnitude / 100.0 * self.duty_steps) * (100.0 / self.duty_steps)
        else:
            realised = magnitude
        energised = (realised > 0) & (magnitude >= self.params.dead_zone_duty)
        if self.model is ValveModel.AVERAGED:
            drain = np.where(energised, 1.0 / self.params.resistance(np.maximum(realised, 1e-9)), 0.0)
        else:
            in_pulse = (tick % self.period_ticks) < np.rint(realised / 100.0 * self.period_ticks)
            drain = np.where(energised & in_pulse, self.full_conductance, 0.0)
        supply = np.where(energised, self.full_conductance, 0.0)
        forward, backward = duty > 0, duty < 0
        coil = np.zeros((self.n, 4))
        coil[:, SUPPLY_A] = np.where(forward, supply, 0.0)
        coil[:, DRAIN_B] = np.where(forward, drain, 0.0)
        coil[:, SUPPLY_B] = np.where(backward, supply, 0.0)
        coil[:, DRAIN_A] = np.where(backward, drain, 0.0)
        return coil

    def update(self, tick: int, duty: np.ndarray) -> np.ndarray:
        """Valve conductances (n, 4) in m^3/(Pa s) at integer ``tick`` for signed ``duty`` (n,) in %."""
        coil = self._coil_conductance(tick, duty)
        on = coil > 0.0
        self._on_run = np.where(on, self._on_run + 1, 0)
        self._off_run = np.where(on, 0, self._off_run + 1)
        opens = ~self._open & (self._on_run > self.open_ticks)
        shuts = self._open & (self._off_run > self.close_ticks)
        self._open = (self._open | opens) & ~shuts
        self._conductance = np.where(on, coil, self._conductance)
        return np.where(self._open, self._conductance, 0.0)
