"""The :class:`Plant` record and the four ``thesis*`` presets (see :mod:`twin.plants` for what each is)."""

from __future__ import annotations

import dataclasses

from twin.physics.params import FrictionParams, JointParams, ValveParams
from twin.physics.valves import ValveModel


@dataclasses.dataclass(frozen=True)
class Plant:
    name: str
    params: JointParams
    valve_model: ValveModel
    gain_set: str  # "simulation" or "experiment"
    timestep: float = 1e-3  # s, physics step = sensor tick
    metrics_on_sensor: bool = False  # score the Hall reading (as the thesis's experiments did), not the true angle


THESIS_PARAMS = JointParams(
    valves=ValveParams(dead_zone_duty=0.0),
    friction=FrictionParams(stiction=0.0),
)

THESIS_PLANTS = {
    "thesis": Plant("thesis", THESIS_PARAMS, ValveModel.AVERAGED, "simulation"),
    "thesis-deadzone": Plant("thesis-deadzone", dataclasses.replace(THESIS_PARAMS, valves=ValveParams()),
                             ValveModel.AVERAGED, "simulation"),
    "thesis-continuous": Plant("thesis-continuous", dataclasses.replace(
        THESIS_PARAMS, valves=ValveParams(dead_zone_duty=0.0, switching_period=0.0)), ValveModel.AVERAGED, "simulation"),
    "thesis-pwm": Plant("thesis-pwm", dataclasses.replace(THESIS_PARAMS, valves=ValveParams()),
                        ValveModel.PWM, "simulation"),
    "thesis-solenoid": Plant("thesis-solenoid", dataclasses.replace(THESIS_PARAMS, valves=ValveParams(dead_zone_duty=0.0)),
                             ValveModel.SOLENOID, "simulation"),
}
