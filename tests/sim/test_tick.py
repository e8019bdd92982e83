"""The step order is written once (twin.sim.tick.Ticker) and every loop goes through it."""

from __future__ import annotations

import numpy as np
import pytest

from twin.envs import environment
from twin.envs.live import LiveJoint
from twin.envs.runner import run
from twin.sim.scenario import Scenario
from twin.sim.tick import Ticker


class FakePlant:
    """Records the calls a tick makes, in order."""

    def __init__(self, calls: list):
        self.calls = calls

    def sense(self, k, y):
        self.calls.append(("sense", k, float(y[0])))
        return f"measurement {k}"

    def external_force(self, passive, bias):
        self.calls.append(("external",))
        return np.zeros(1)

    def actuate(self, k, duty, y, v, external):
        self.calls.append(("actuate", k, float(duty[0]), float(y[0]), float(v[0])))
        return np.array([1.5]), np.array([-0.5])


def _ticker(calls: list) -> tuple[Ticker, dict]:
    arrays = {"qpos": np.array([[0.25, 9.0]]), "qvel": np.array([[0.5, 9.0]]), "ctrl": np.zeros((1, 2)),
              "qfrc_passive": np.zeros((1, 2)), "qfrc_bias": np.zeros((1, 2))}

    def step(k):
        calls.append(("step", k))
        arrays["qpos"][0, 0] += 1.0  # the physics moves the rack

    return Ticker(FakePlant(calls), rack_dof=0, step=step, **arrays), arrays


def test_a_tick_senses_commands_actuates_then_steps():
    calls: list = []
    ticker, arrays = _ticker(calls)

    def command(k, measurement):
        calls.append(("command", k, measurement))
        return np.array([40.0])

    ticker.tick(command)
    ticker.tick(command)
    assert calls == [("sense", 0, 0.25), ("command", 0, "measurement 0"), ("external",),
                     ("actuate", 0, 40.0, 0.25, 0.5), ("step", 0),
                     ("sense", 1, 1.25), ("command", 1, "measurement 1"), ("external",),
                     ("actuate", 1, 40.0, 1.25, 0.5), ("step", 1)]
    assert arrays["ctrl"].tolist() == [[1.5, -0.5]] and ticker.k == 2


def test_sensing_is_once_per_tick_and_act_senses_first_when_nobody_did():
    calls: list = []
    ticker, _ = _ticker(calls)
    first = ticker.sense()
    assert ticker.sense() is first and [c[0] for c in calls] == ["sense"]
    ticker.act(np.array([10.0]))  # uses the kept measurement: no second sample at tick 0
    ticker.act(np.array([10.0]))  # nobody sensed tick 1: act does
    assert [c[0] for c in calls] == ["sense", "external", "actuate", "step", "sense", "external", "actuate", "step"]


def test_restart_forgets_the_kept_measurement():
    calls: list = []
    ticker, _ = _ticker(calls)
    ticker.sense()
    ticker.restart(0)
    ticker.sense()
    assert [c[0] for c in calls] == ["sense", "sense"]


@pytest.fixture
def acts(monkeypatch):
    """Counts Ticker.act calls."""
    count = [0]
    real = Ticker.act

    def counting(self, duty):
        count[0] += 1
        return real(self, duty)

    monkeypatch.setattr(Ticker, "act", counting)
    return count


def test_twin_run_goes_through_the_ticker_once_per_tick(acts):
    result = run(Scenario("ffpva", 1, plant="thesis"))
    assert acts[0] == len(result.trace.time) == 3000


def test_the_environment_goes_through_the_ticker_once_per_tick(acts):
    env = environment.load("track", trajectory=1, seed=0)
    env.reset()
    before = acts[0]
    env.step([30.0])  # one action: one 16 ms PWM period
    assert acts[0] - before == 16


def test_the_live_joint_goes_through_the_ticker_once_per_tick(acts):
    joint = LiveJoint(Scenario("smc", 1, plant="thesis"))
    joint.advance(0.05)
    assert acts[0] == 50 and joint.steps == 50
