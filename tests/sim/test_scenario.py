"""A scenario is what to simulate; it needs no controller name where the caller brings its own."""

from __future__ import annotations

import math

import numpy as np
import pytest

from controllers.open_loop import OpenLoop
from twin.envs.runner import run
from twin.exceptions import InvalidScenario
from twin.sim.metrics import spread
from twin.sim.scenario import Scenario
from twin.sim.simulation import simulate


def test_a_scenario_without_a_controller_runs_with_one_given():
    scenario = Scenario(None, 1, plant="thesis", noise=False)
    result = simulate([scenario], controllers=[OpenLoop(schedule=lambda t: 60.0, tick=1e-3)])[0]
    assert result.trace.angle[-1] > result.trace.angle[0] + math.radians(10)  # 60 % duty moves it


def test_running_a_scenario_without_a_controller_by_name_is_refused():
    with pytest.raises(InvalidScenario, match="without a controller"):
        run(Scenario(None, 1))


def test_an_unknown_controller_is_still_refused():
    with pytest.raises(InvalidScenario, match="unknown controller 'pid'"):
        Scenario("pid", 1)


def test_spread_is_the_thesis_mean_and_sample_std():
    s = spread([1.0, 2.0, 4.0])
    assert (s.n, s.mean, s.min, s.max) == (3, 7 / 3, 1.0, 4.0)
    assert s.std == pytest.approx(math.sqrt(((1 - 7 / 3) ** 2 + (2 - 7 / 3) ** 2 + (4 - 7 / 3) ** 2) / 2))
    assert spread([3.0]).std == 0.0
    assert math.isnan(spread([1.0, np.nan]).mean)
