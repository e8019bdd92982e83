"""Feed-forward + PVA + sliding mode (§6, controller 3).

    sigma = de/dt + lambda e,   e = y_d - y
    u = u_FF+PVA + 100 % sat(sigma / phi)

u_FF+PVA is recomputed once per PWM period (16 ms) and held; the switching
term every 1 ms inside the period, so the valve can close early, stay open
longer or switch pair. No dead-zone compensation. Simulation gains:
K_p = 50,000 %/m, lambda = 80 1/s; the thesis lost phi for the simulation, so
the experiment's phi = 0.3 m/s is used for both (*resolution*). Experiment:
K_p = 50,000, lambda = 40 1/s, phi = 0.3 m/s.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from controllers.feedforward import NominalModel
from controllers.ffpva import ffpva_duty
from controllers.pva import PWM_PERIOD, PVAGains, check_period
from twin.exceptions import InvalidController
from twin.sim.control import Measurement, Setpoint

SWITCHING_PERIOD = 1e-3  # s
LAMBDA_BY_GAIN_SET = {"simulation": 80.0, "experiment": 40.0}  # 1/s


@dataclasses.dataclass(frozen=True)
class SlidingModeGains:
    pva: PVAGains
    surface_slope: float  # 1/s, lambda
    boundary_layer: float = 0.3  # m/s, phi
    switching_amplitude: float = 100.0  # %

    def __post_init__(self) -> None:
        if self.surface_slope <= 0 or self.boundary_layer <= 0:
            raise InvalidController(f"lambda and phi must be positive, got {self}")


@dataclasses.dataclass
class SlidingMode:
    nominal: NominalModel
    gains: SlidingModeGains
    tick: float  # s
    period: float = SWITCHING_PERIOD  # s, the loop calls update this often
    slow_period: float = PWM_PERIOD  # s, u_FF+PVA is refreshed this often

    def __post_init__(self) -> None:
        check_period(self.period, self.tick)
        self._slow_every = check_period(self.slow_period, self.period)
        self._calls = 0
        self._held = np.zeros(0)

    @classmethod
    def thesis(cls, *, nominal: NominalModel, gain_set: str, tick: float) -> SlidingMode:
        gains = SlidingModeGains(pva=PVAGains(position=50_000.0), surface_slope=LAMBDA_BY_GAIN_SET[gain_set])
        return cls(nominal=nominal, gains=gains, tick=tick, slow_period=nominal.valves.pwm_period)

    def reset(self, n: int) -> None:
        self._calls = 0
        self._held = np.zeros(n)

    def update(self, t: float, measurement: Measurement, setpoint: Setpoint) -> np.ndarray:
        del t
        if self._calls % self._slow_every == 0:
            self._held = ffpva_duty(self.nominal, self.gains.pva, measurement, setpoint)
        self._calls += 1
        return np.clip(self._held + self.switching(measurement, setpoint), -100.0, 100.0)

    def switching(self, measurement: Measurement, setpoint: Setpoint) -> np.ndarray:
        """The switching term, % (n,): 100 % sat(sigma / phi), sigma = de/dt + lambda e."""
        error = setpoint.position - measurement.position
        sigma = (setpoint.velocity - measurement.velocity) + self.gains.surface_slope * error
        return self.gains.switching_amplitude * np.clip(sigma / self.gains.boundary_layer, -1.0, 1.0)
