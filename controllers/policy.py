"""A controller as a policy for :mod:`twin.envs.environment`: observation in, duty out.

The controller is called every time the policy is, so the environment's action
period must equal the controller's period (16 ms for PVA and FF + PVA, 1 ms for
sliding mode): ``twin.envs.environment.load(..., action_period=controller.period)``. The
policy checks this on every call against the observed episode time and raises
:class:`~twin.exceptions.InvalidScenario` at the first step that disagrees; the
controller's clock is the environment's.
"""

from __future__ import annotations

import dataclasses

import dm_env
import numpy as np

from twin.exceptions import InvalidScenario
from twin.sim.control import Controller, Measurement, Setpoint

TIME_TOLERANCE = 1e-9  # s, far below the 1 ms tick


@dataclasses.dataclass
class ControllerPolicy:
    controller: Controller
    spur_radius: float  # m, to turn the desired angle into a rack position
    _calls: int = dataclasses.field(default=0, init=False)  # updates since the episode began

    def reset(self) -> None:
        self.controller.reset(1)
        self._calls = 0

    def _check_cadence(self, time: float) -> None:
        """Raise unless the environment is at the time of this call at the controller's period."""
        expected = self._calls * self.controller.period
        if abs(time - expected) > TIME_TOLERANCE:
            raise InvalidScenario(
                f"the environment's action period is not the controller's period "
                f"({self.controller.period * 1e3:g} ms): call {self._calls} came at {time * 1e3:g} ms, "
                f"not {expected * 1e3:g} ms; load the environment with action_period=controller.period")

    def __call__(self, timestep: dm_env.TimeStep) -> np.ndarray:
        if timestep.first():
            self.reset()
        obs = timestep.observation
        time = float(obs["time"][0])
        self._check_cadence(time)
        measurement = Measurement(position=obs["rack_position"], velocity=obs["velocity"],
                                  acceleration=obs["acceleration"], supply_pressure=obs["supply_pressure"])
        setpoint = Setpoint(position=obs["desired_angle"][:1] * self.spur_radius,
                            velocity=obs["desired_velocity"], acceleration=obs["desired_acceleration"])
        duty = self.controller.update(time, measurement, setpoint)
        self._calls += 1
        return duty
