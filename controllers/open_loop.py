"""Open-loop duty: a commanded duty as a function of time.

:class:`OpenLoop` ignores measurements (closed-form tests: constant duty ->
steady velocity). :class:`ReversingSine` is the thesis's open-loop validation
input (§4.6): a sine of duty that looks at the measured position only to stop
and turn back at soft motion limits.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

import numpy as np

from controllers.pva import PWM_PERIOD, check_period
from twin.exceptions import InvalidController
from twin.sim.control import Measurement, Setpoint


@dataclasses.dataclass
class OpenLoop:
    """u(t) in % from ``schedule(t)``, updated every ``period`` (s)."""

    schedule: Callable[[float], float]
    tick: float  # s
    period: float = PWM_PERIOD  # s
    calls: int = 0

    def __post_init__(self) -> None:
        check_period(self.period, self.tick)

    def reset(self, n: int) -> None:
        self._n = n
        self.calls = 0

    def update(self, t: float, measurement: Measurement, setpoint: Setpoint) -> np.ndarray:
        del measurement, setpoint
        self.calls += 1
        return np.full(self._n, float(np.clip(self.schedule(t), -100.0, 100.0)))


def constant_duty(duty: float, *, tick: float = 1e-3) -> OpenLoop:
    return OpenLoop(schedule=lambda t: duty, tick=tick)


@dataclasses.dataclass
class ReversingSine:
    """The thesis's open-loop duty (§4.6), updated every ``period`` (s), for n scenarios at once:

        u_k = s · A · sin(2π t_k / T),   t_k = k · period,   s ∈ {+1, −1} per scenario, s = +1 at reset

    so u = 0 at t = 0. u > 0 extends rack A (y and θ grow, §3). Soft motion limits:
    when the measured rack position y is at or above ``upper`` and u_k > 0 (which
    would push it further), or at or below ``lower`` and u_k < 0, the duty is 0 for
    that period and s flips, so the sine carries on away from the limit.
    """

    lower: float  # m, soft limit on the measured rack position
    upper: float  # m
    tick: float  # s
    amplitude: float = 45.0  # %, A
    sine_period: float = 1.6  # s, T
    period: float = PWM_PERIOD  # s, the duty is held this long
    calls: int = 0

    def __post_init__(self) -> None:
        check_period(self.period, self.tick)
        if not self.lower < self.upper:
            raise InvalidController(f"soft limits need lower < upper, got {self.lower} and {self.upper} m")
        if not 0 < self.amplitude <= 100 or self.sine_period <= 0:
            raise InvalidController(f"need 0 < amplitude <= 100 % and a positive sine period, "
                                    f"got {self.amplitude} % and {self.sine_period} s")

    def reset(self, n: int) -> None:
        self._sign = np.ones(n)
        self.calls = 0

    def update(self, t: float, measurement: Measurement, setpoint: Setpoint) -> np.ndarray:
        del setpoint
        self.calls += 1
        u = self._sign * self.amplitude * np.sin(2 * np.pi * t / self.sine_period)
        y = measurement.position
        at_limit = ((y >= self.upper) & (u > 0)) | ((y <= self.lower) & (u < 0))
        self._sign = np.where(at_limit, -self._sign, self._sign)
        return np.where(at_limit, 0.0, u)
