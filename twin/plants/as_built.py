"""The ``as-built`` plant: the thesis plant plus, as physics, every effect the
thesis names as a cause of its experiments' 1.5-4x larger errors (§3, §4, §5, §8).

Effects (each switchable by name; all off gives the ``thesis`` plant exactly):

==================  =========================================================================
effect              what it adds
==================  =========================================================================
compressibility     chamber pressures as states, free air lowering beta at low pressure, a
                    small leak past the discharge valves (fitted) (:mod:`twin.physics.chambers`)
supply_line         the air-over-water supply reaching the valves through a hose: sags while
                    water flows, rings, recovers (``SupplyLineParams``, §3); needs
                    compressibility (they are integrated together)
stiction            breakaway force above Coulomb, varying along the stroke (a static friction
                    map, thesis future work 2): stick-slip
ccw_friction        Coulomb friction larger moving towards 0 deg (the thesis tracked worse CCW)
dead_zone           the valves' dead zone (§3: "about 30 %")
held_supply         the pair's supply valve stays on while the discharge valve's pulses are too
                    short to open it (§3: only the discharge valve is PWM'd, the supply valve
                    "stays fully on"); with compressible chambers that leak, the joint then creeps
hall_calibration    the DAQ's eq. 4.2.1 against the sensor's measured calibration points (§5)
experiment_gains    the controllers' experiment gains (§6), as on the real joint
sensor_metrics      errors scored on the Hall reading, as the thesis's experiments were
==================  =========================================================================

The valve stays the averaged eq. 4.4.2 with the 5 ms / 2 ms delays: eq. 4.4.2
was measured on the real PWM'd valves, so it already holds what pulse-width
modulation does on average (the time-resolved ``pwm`` valve, with incompressible
water, tracks 3-5x worse than the experiments: it stalls the rack for most of each
period, which the measured R(d) says the real joint does not).

The parameters the thesis does not give are :data:`FITTED`, with the bounds that
keep them physically plausible; ``twin calibrate`` fits them to §8's experimental
table and writes ``twin/plants/data/as_built.json``, which this module reads. Other
as-built values are assumptions, stated in :data:`ASSUMED`.
"""

from __future__ import annotations

import dataclasses
import importlib.resources
import json
import pathlib
from collections.abc import Iterable

from twin.exceptions import InvalidScenario
from twin.physics.params import ChamberParams, HallParams, JointParams, StictionMapParams, SupplyLineParams
from twin.physics.valves import ValveModel
from twin.plants.preset import THESIS_PARAMS, Plant

EFFECTS = ("compressibility", "supply_line", "stiction", "ccw_friction", "dead_zone", "held_supply",
           "hall_calibration", "experiment_gains", "sensor_metrics")
CALIBRATION_FILE = importlib.resources.files("twin.plants") / "data" / "as_built.json"  # package data


@dataclasses.dataclass(frozen=True)
class Fitted:
    """A parameter ``twin calibrate`` fits, its plausible range and why that range."""

    name: str
    low: float
    high: float
    unit: str
    why: str


FITTED = (
    Fitted("stiction", 1.0, 3.6, "N", "breakaway force. The thesis's 'average static friction 3.6 N' is the top: "
           "at 300 kPa P_ws A is 3.77 N, and at 245 kPa (where the thesis measured the rack moving) 3.6 N would "
           "not let it start; eq. 4.5.7's Coulomb peak (about 2 N) is near the bottom"),
    Fitted("dead_zone_duty", 20.0, 35.0, "%", "SPEC §3: 'below about 30 % duty the valve does not open'"),
    Fitted("air_fraction", 0.0, 0.03, "", "free air per chamber volume at 1 atm: none to 3 % (visibly bubbly "
           "water in 4 mm cylinders and hoses)"),
    Fitted("ccw_coulomb_scale", 1.0, 1.5, "", "Coulomb friction towards 0 deg relative to eq. 4.5.7, which "
           "fits CW and CCW tests together: up to 50 % more one way"),
    Fitted("leak_conductance", 0.0, 3e-14, "m^3/(Pa s)", "past each discharge valve to the tank: from a tight "
           "seat to 0.54 mL/min at 300 kPa (a 0.05 mL drop every 6 s: a visibly weeping seat, more than a "
           "valve sold as normally closed would be let go with)"),
)

ASSUMED = {
    "dead_volume": "0.3 mL per chamber at the end of stroke: ports, fittings and hose to the valve block",
    "initial_pressure_fraction": "both chambers start at half the supply (the thesis pre-charges the joint "
                                 "by moving it side to side; the shut valves then trap a middle pressure)",
    "stiction_map": "scatter 0.5 N about the fitted breakaway, knots 1 mm apart, seed 0",
    "supply_line": "60 Hz, damping ratio 0.3, 2e-13 m^3/Pa at the valve block: a hose ringing near the 62.5 Hz "
                   "PWM as §3 describes, sagging ~10 kPa at full flow",
}


def calibrated_values(path: pathlib.Path = CALIBRATION_FILE) -> dict[str, float]:
    """The fitted values from ``path`` (the committed calibration by default)."""
    try:
        record = json.loads(path.read_text())
        values = {f.name: float(record["fitted"][f.name]) for f in FITTED}
    except (OSError, ValueError, KeyError) as error:
        raise InvalidScenario(f"cannot read the as-built calibration {path}: {error}") from None
    for f in FITTED:
        if not f.low <= values[f.name] <= f.high:
            raise InvalidScenario(f"as-built {f.name} = {values[f.name]} is outside its plausible "
                                  f"[{f.low}, {f.high}] {f.unit}")
    return values


def as_built_params(values: dict[str, float], *, without: Iterable[str] = ()) -> tuple[JointParams, dict]:
    """Joint parameters with the fitted ``values``, minus the effects named in ``without``;
    also the plant options (gain set, scoring) those effects set."""
    off = set(without)
    unknown = off - set(EFFECTS)
    if unknown:
        raise InvalidScenario(f"unknown as-built effects {sorted(unknown)}: choose from {', '.join(EFFECTS)}")
    on = set(EFFECTS) - off
    if "supply_line" in on and "compressibility" not in on:
        raise InvalidScenario("the supply line is integrated with the compressible chambers: switch "
                              "compressibility on with it, or switch supply_line off too")
    base = THESIS_PARAMS
    friction = dataclasses.replace(
        base.friction,
        stiction=values["stiction"] if "stiction" in on else base.friction.stiction,
        ccw_coulomb_scale=values["ccw_coulomb_scale"] if "ccw_friction" in on else 1.0)
    params = dataclasses.replace(
        base,
        valves=dataclasses.replace(base.valves, dead_zone_duty=values["dead_zone_duty"] if "dead_zone" in on
                                   else base.valves.dead_zone_duty, supply_held_in_dead_zone="held_supply" in on),
        friction=friction,
        chambers=(ChamberParams(compressible=True, air_fraction=values["air_fraction"],
                                leak_conductance=values["leak_conductance"])
                  if "compressibility" in on else ChamberParams()),
        supply_line=SupplyLineParams(model="line") if "supply_line" in on else SupplyLineParams(),
        hall=HallParams(calibration_error="hall_calibration" in on),
        stiction_map=StictionMapParams(scatter=0.5) if "stiction" in on else StictionMapParams(),
    )
    options = {"gain_set": "experiment" if "experiment_gains" in on else "simulation",
               "metrics_on_sensor": "sensor_metrics" in on}
    return params, options


def as_built_plant(values: dict[str, float] | None = None, *, without: Iterable[str] = (),
                   name: str = "as-built"):
    """The as-built :class:`twin.plants.Plant` (the committed calibration unless ``values`` are given)."""
    params, options = as_built_params(calibrated_values() if values is None else values, without=without)
    return Plant(name, params, ValveModel.AVERAGED, options["gain_set"],
                 metrics_on_sensor=options["metrics_on_sensor"])


__all__ = ["ASSUMED", "CALIBRATION_FILE", "EFFECTS", "FITTED", "as_built_params",
           "as_built_plant", "calibrated_values"]
