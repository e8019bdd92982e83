"""PVA with dead-zone compensation, the baseline (eq. 5.2.3 - 5.2.4).

    u = K_p e + K_v de/dt + K_a d2e/dt2,   e = y_d - y
    u += 30 % sgn(u)  when |e| > 0.3 mm   (dead-zone compensation)

*Resolution*: the thesis prints ``+K_v y' + K_a y''``, which is positive
velocity feedback; the terms are taken on the error rates (v_d - v_hat,
a_d - a_hat), the stable sign that reduces to -K_v v_hat when holding.
Velocity and acceleration come from the observer. Runs every PWM period (16 ms).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from twin.exceptions import InvalidController
from twin.physics.params import NOMINAL_PARAMS
from twin.physics.ticks import whole_ticks
from twin.sim.control import Measurement, Setpoint

PWM_PERIOD = NOMINAL_PARAMS.valves.pwm_period  # s (16 ms), the controller runs once per PWM period (§6)


@dataclasses.dataclass(frozen=True)
class PVAGains:
    position: float = 80_000.0  # %/m, K_p
    velocity: float = 50.0  # %/(m/s), K_v
    acceleration: float = 1.5  # %/(m/s^2), K_a

    def __post_init__(self) -> None:
        if min(self.position, self.velocity, self.acceleration) < 0:
            raise InvalidController(f"PVA gains must be non-negative, got {self}")


def pva_duty(gains: PVAGains, measurement: Measurement, setpoint: Setpoint) -> np.ndarray:
    """The PVA law without compensation, in %."""
    return (gains.position * (setpoint.position - measurement.position)
            + gains.velocity * (setpoint.velocity - measurement.velocity)
            + gains.acceleration * (setpoint.acceleration - measurement.acceleration))


def check_period(period: float, tick: float) -> int:
    """Ticks per update; rejects a period that is not a whole number of ticks."""
    return whole_ticks(period, tick, what="controller period", error=InvalidController)


@dataclasses.dataclass
class PVA:
    gains: PVAGains
    tick: float  # s
    period: float = PWM_PERIOD  # s
    compensation: float = 30.0  # %, eq. 5.2.4
    compensation_threshold: float = 0.3e-3  # m, eq. 5.2.4

    def __post_init__(self) -> None:
        check_period(self.period, self.tick)

    @classmethod
    def thesis(cls, *, nominal, gain_set: str, tick: float) -> PVA:
        del gain_set  # the baseline has one gain set and no model
        return cls(gains=PVAGains(), tick=tick, period=nominal.valves.pwm_period)

    def reset(self, n: int) -> None:
        del n

    def update(self, t: float, measurement: Measurement, setpoint: Setpoint) -> np.ndarray:
        del t
        u = pva_duty(self.gains, measurement, setpoint)
        far = np.abs(setpoint.position - measurement.position) > self.compensation_threshold
        u = u + np.where(far, self.compensation * np.sign(u), 0.0)
        return np.clip(u, -100.0, 100.0)
