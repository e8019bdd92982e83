"""Feed-forward + PVA (eqs. 5.3.2 - 5.3.6).

    u = u_FF(y_d, v_d, a_d) + K_p e + K_v de/dt + K_a d2e/dt2
    20 % <= |u| <= 30 %  ->  |u| = 30 %   (dead-zone compensation, eq. 5.3.6)

Runs once per PWM period (16 ms). K_p = 50,000 %/m in simulation, 45,000 in
the experiments; K_v = 50, K_a = 1.5 (velocity terms as in controllers/pva.py).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from controllers.feedforward import NominalModel, feedforward_duty
from controllers.pva import PWM_PERIOD, PVAGains, check_period, pva_duty
from twin.sim.control import Measurement, Setpoint

KP_BY_GAIN_SET = {"simulation": 50_000.0, "experiment": 45_000.0}


@dataclasses.dataclass(frozen=True)
class FeedForwardPVAGains:
    pva: PVAGains
    compensation_band: tuple[float, float] = (20.0, 30.0)  # %, eq. 5.3.6


def compensate(u: np.ndarray, band: tuple[float, float]) -> np.ndarray:
    """Dead-zone compensation (eq. 5.3.6): a command whose magnitude lies in ``band`` = (low, high) %, ends
    included, lifted to ``high`` with its sign; others unchanged."""
    low, high = band
    return np.where((np.abs(u) >= low) & (np.abs(u) <= high), high * np.sign(u), u)


def ffpva_duty(nominal: NominalModel, gains: PVAGains, measurement: Measurement,
               setpoint: Setpoint) -> np.ndarray:
    """u_FF + u_PVA in %, before compensation and clipping."""
    u_ff = feedforward_duty(nominal, setpoint.position, setpoint.velocity, setpoint.acceleration)
    return u_ff + pva_duty(gains, measurement, setpoint)


@dataclasses.dataclass
class FeedForwardPVA:
    nominal: NominalModel
    gains: FeedForwardPVAGains
    tick: float  # s
    period: float = PWM_PERIOD  # s

    def __post_init__(self) -> None:
        check_period(self.period, self.tick)

    @classmethod
    def thesis(cls, *, nominal: NominalModel, gain_set: str, tick: float) -> FeedForwardPVA:
        gains = FeedForwardPVAGains(pva=PVAGains(position=KP_BY_GAIN_SET[gain_set]))
        return cls(nominal=nominal, gains=gains, tick=tick, period=nominal.valves.pwm_period)

    def reset(self, n: int) -> None:
        del n

    def update(self, t: float, measurement: Measurement, setpoint: Setpoint) -> np.ndarray:
        del t
        u = compensate(ffpva_duty(self.nominal, self.gains.pva, measurement, setpoint), self.gains.compensation_band)
        return np.clip(u, -100.0, 100.0)
