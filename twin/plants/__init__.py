"""Named plant presets: a parameter set, a valve model and the gain set the
controllers use on it.

``thesis``
    What the thesis simulated (§8, "friction model assumed perfect"): the
    plant is the controllers' model. Valve: ``averaged`` eq. 4.4.2 at every
    duty above 0 % (the feed-forward inverts eq. 4.4.2 down to small duties,
    so a plant equal to that model has no dead zone), with the 5 ms opening and
    2 ms closing delays. Force loss: eq. 4.5.5 with eq. 4.5.7 only (no separate
    stiction, which eq. 4.5.5 does not contain). Constant 300 kPa supply,
    incompressible water, sealed chambers lock the joint. Simulation gains.
``thesis-deadzone``
    The same with the real valve's 30 % dead zone (§3): commands below 30 %
    leave the valve shut. A sensitivity variant, not a reproduction target.
``thesis-continuous``
    The ``thesis`` plant with a continuous duty (no 1 ms switching tick): what
    an ideal averaged valve would do. A sensitivity variant.
``thesis-pwm``
    The same with the time-resolved PWM valve: each valve shut or fully open,
    16 ms period, delays and 30 % dead zone.
``as-built``
    The joint as built (:mod:`twin.plants.as_built`): the thesis plant plus every
    effect the thesis blames for its experiments' larger errors, as physics,
    with the few parameters the thesis does not give fitted by ``twin calibrate``.
"""

from __future__ import annotations

import dataclasses

from twin.exceptions import InvalidScenario
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

PLANTS = {
    "thesis": Plant("thesis", THESIS_PARAMS, ValveModel.AVERAGED, "simulation"),
    "thesis-deadzone": Plant("thesis-deadzone", dataclasses.replace(THESIS_PARAMS, valves=ValveParams()),
                             ValveModel.AVERAGED, "simulation"),
    "thesis-continuous": Plant("thesis-continuous", dataclasses.replace(
        THESIS_PARAMS, valves=ValveParams(dead_zone_duty=0.0, switching_period=0.0)), ValveModel.AVERAGED, "simulation"),
    "thesis-pwm": Plant("thesis-pwm", dataclasses.replace(THESIS_PARAMS, valves=ValveParams()),
                        ValveModel.PWM, "simulation"),
}


from twin.exceptions import TwinError  # noqa: E402
from twin.plants.as_built import as_built_plant  # noqa: E402  (it builds on Plant)

try:  # a missing or broken calibration file loses the preset, not the package (twin calibrate remakes it)
    PLANTS["as-built"] = as_built_plant()
except TwinError as error:
    import warnings

    warnings.warn(f"no as-built plant: {error}", stacklevel=1)


def plant(name: str) -> Plant:
    if name not in PLANTS:
        raise InvalidScenario(f"unknown plant {name!r}: choose one of {', '.join(PLANTS)}")
    return PLANTS[name]
