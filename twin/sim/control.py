"""What a controller sees and returns: the protocol ``controllers/`` implements.

A controller is called by the simulation loop every ``period`` seconds (a
whole number of sensor ticks) and returns the signed duty command in percent
(sign = direction, §6), held until its next call. Arrays are (n,), one entry
per scenario the controller drives.
"""

from __future__ import annotations

import dataclasses
from typing import Protocol

import numpy as np


@dataclasses.dataclass(frozen=True)
class Measurement:
    position: np.ndarray  # m, measured rack position (Hall sensor)
    velocity: np.ndarray  # m/s, observer estimate
    acceleration: np.ndarray  # m/s^2, observer estimate
    supply_pressure: np.ndarray  # Pa, measured

    def subset(self, idx: np.ndarray) -> Measurement:
        """The measurements of the scenarios ``idx``."""
        return Measurement(position=self.position[idx], velocity=self.velocity[idx],
                           acceleration=self.acceleration[idx], supply_pressure=self.supply_pressure[idx])


@dataclasses.dataclass(frozen=True)
class Setpoint:
    position: np.ndarray  # m
    velocity: np.ndarray  # m/s
    acceleration: np.ndarray  # m/s^2


class Controller(Protocol):
    period: float  # s

    def reset(self, n: int) -> None:
        """Forget all state; ``n`` scenarios follow."""

    def update(self, t: float, measurement: Measurement, setpoint: Setpoint) -> np.ndarray:
        """Duty command in % (n,), clipped to [-100, 100]."""
