"""Open-loop duty: a commanded duty as a function of time, ignoring measurements.

Used for the thesis's open-loop validation (§4.6) and for closed-form tests
(constant duty -> steady velocity).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

import numpy as np

from controllers.pva import PWM_PERIOD, check_period
from twin.control import Measurement, Setpoint


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
