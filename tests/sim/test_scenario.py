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


@pytest.mark.parametrize("given, message", [
    ({"trajectory": 5}, "unknown trajectory 5"),
    ({"trajectory": True}, "unknown trajectory True"),  # True == 1
    ({"payload": -1e-3}, "payload must be 0 or between 0.001 and 200 g, got -1 g"),
    ({"payload": 1e-323}, "payload must be 0 or between 0.001 and 200 g, got 9.881312917e-321 g"),
    ({"payload": math.nan}, "got nan g"),
    ({"payload": "6.5"}, "got '6.5'"),
    ({"payload": 10**400}, r"got 10000000000000000000\.\.\.$"),  # OverflowError until stop 60
    ({"payload": np.bool_(True)}, r"got np\.True_$"),
    ({"payload": 0.2000000001}, "got 200.0000001 g"),  # "got 200 g", inside the range, until stop 60
    ({"seed": -1}, "seed must be an integer"),
    ({"noise": "off"}, "noise must be True or False, got 'off'"),  # ran with the noise on until stop 60
    ({"noise": None}, "noise must be True or False, got None"),  # ran with the noise off
    ({"supply_pressure": "700"}, r"supply pressure must be in \(0, 700\] kPa .*, got '700'"),  # TypeError till stop 60
    ({"supply_pressure": 2e6}, r"supply pressure must be in \(0, 700\] kPa .*, got 2000 kPa"),
    ({"supply_pressure": math.inf}, "got inf kPa"),
    ({"pwm_period": "0.016"}, "PWM period must be a whole number .*, got '0.016'"),  # TypeError until stop 60
    ({"pwm_period": math.nan}, "got nan ms"),
    ({"pwm_period": 0.0165}, "PWM period must be a whole number"),
])
def test_a_bad_scenario_is_refused_in_one_line_naming_the_value(given, message):
    with pytest.raises(InvalidScenario, match=message) as caught:
        Scenario("ffpva", **{"trajectory": 1, **given})
    assert "\n" not in str(caught.value)


def test_numpy_numbers_make_a_scenario_as_python_numbers_do():
    given = Scenario("ffpva", 1, payload=np.float64(6.5e-3), supply_pressure=np.int64(250_000), noise=np.bool_(False),
                     pwm_period=np.float64(8e-3))
    assert given == Scenario("ffpva", 1, payload=6.5e-3, supply_pressure=250_000, noise=False, pwm_period=8e-3)
    assert type(given.noise) is bool  # kept as Python's, which JSON takes


def test_spread_is_the_thesis_mean_and_sample_std():
    s = spread([1.0, 2.0, 4.0])
    assert (s.n, s.mean, s.min, s.max) == (3, 7 / 3, 1.0, 4.0)
    assert s.std == pytest.approx(math.sqrt(((1 - 7 / 3) ** 2 + (2 - 7 / 3) ** 2 + (4 - 7 / 3) ** 2) / 2))
    assert spread([3.0]).std == 0.0
    assert math.isnan(spread([1.0, np.nan]).mean)
