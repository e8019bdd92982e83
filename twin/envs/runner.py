"""Run scenarios by name: builds the controllers each scenario names, then simulates.

This is the application layer over :mod:`twin.sim.simulation` (which knows only the
controller protocol); the CLI and the studies call it.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence

from controllers import make_controller
from controllers.feedforward import NominalModel
from twin.exceptions import InvalidScenario
from twin.physics.params import NOMINAL_PARAMS
from twin.sim.scenario import Scenario
from twin.sim.simulation import Result, simulate


def nominal_model(preset) -> NominalModel:
    """The controllers' model: always the thesis's numbers (SPEC), whatever the plant, so that a
    plant's model errors stay model errors; only the PWM period follows the plant's valves."""
    valves = dataclasses.replace(NOMINAL_PARAMS.valves, pwm_period=preset.params.valves.pwm_period)
    return NominalModel.thesis(dataclasses.replace(NOMINAL_PARAMS, valves=valves))


def thesis_controllers(scenarios: Sequence[Scenario]) -> list:
    """One controller per scenario; scenarios with the same controller, gain set and
    nominal model share one vectorised instance."""
    shared: dict = {}
    chosen = []
    for s in scenarios:
        if s.controller is None:
            raise InvalidScenario("a scenario without a controller cannot be run by name: pass its controller to "
                                  "twin.sim.simulation.simulate")
        preset = s.preset
        key = (s.controller, preset.gain_set, nominal_model(preset), preset.timestep)
        if key not in shared:
            shared[key] = make_controller(s.controller, nominal=key[2], gain_set=key[1], tick=key[3])
        chosen.append(shared[key])
    return chosen


def run_many(scenarios: Sequence[Scenario], *, progress: Callable[[int, int], None] | None = None,
             nthread: int = 0) -> list[Result]:
    """Every scenario in one batch, with the controllers they name."""
    return simulate(scenarios, controllers=thesis_controllers(scenarios), progress=progress, nthread=nthread)


def run(scenario: Scenario, **kwargs) -> Result:
    """One scenario: the case n = 1."""
    return run_many([scenario], **kwargs)[0]
