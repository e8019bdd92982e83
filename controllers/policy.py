"""A controller as a policy for :mod:`twin.env`: observation in, duty out.

The controller is called every time the policy is, so build the environment
with ``action_period`` equal to the controller's period (16 ms for PVA and
FF + PVA, 1 ms for sliding mode).
"""

from __future__ import annotations

import dataclasses

import dm_env
import numpy as np

from twin.control import Controller, Measurement, Setpoint


@dataclasses.dataclass
class ControllerPolicy:
    controller: Controller
    spur_radius: float  # m, to turn the desired angle into a rack position
    _t: float = 0.0

    def reset(self) -> None:
        self.controller.reset(1)
        self._t = 0.0

    def __call__(self, timestep: dm_env.TimeStep) -> np.ndarray:
        if timestep.first():
            self.reset()
        obs = timestep.observation
        measurement = Measurement(position=obs["rack_position"], velocity=obs["velocity"],
                                  acceleration=obs["acceleration"], supply_pressure=obs["supply_pressure"])
        setpoint = Setpoint(position=obs["desired_angle"][:1] * self.spur_radius,
                            velocity=obs["desired_velocity"], acceleration=obs["desired_acceleration"])
        duty = self.controller.update(self._t, measurement, setpoint)
        self._t += self.controller.period
        return duty
