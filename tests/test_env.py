"""The dm_control environment: conformance, equivalence with `twin run`, seeding, random-policy smoke."""

from __future__ import annotations

import unittest

import dm_env
import numpy as np
import pytest
from dm_env import test_utils

from controllers import make_controller
from controllers.feedforward import NominalModel
from controllers.policy import ControllerPolicy
from twin import env as joint_env
from twin.exceptions import InvalidScenario
from twin.model import Orientation
from twin.runner import run
from twin.scenario import Scenario


class TrackConformance(test_utils.EnvironmentTestMixin, unittest.TestCase):
    def make_object_under_test(self):
        return joint_env.load("track", trajectory=2, seed=0)


class RandomTrackConformance(test_utils.EnvironmentTestMixin, unittest.TestCase):
    def make_object_under_test(self):
        return joint_env.load("track", trajectory=None, seed=1)


class HoldConformance(test_utils.EnvironmentTestMixin, unittest.TestCase):
    def make_object_under_test(self):
        return joint_env.load("hold", action_period=1e-3, seed=2)

    def make_action_sequence(self):  # long enough to end an episode (2 s of 1 ms steps)
        for _ in range(2100):
            yield self.make_action()


def _episode(environment, policy) -> float:
    timestep = environment.reset()
    while not timestep.last():
        timestep = environment.step(policy(timestep))
    return environment.physics.episode_rmse()


@pytest.mark.parametrize("name, trajectory, load", [
    ("ffpva", 1, {}),
    ("pva", 4, {}),
    ("smc", 3, {"payload": 13.5e-3, "orientation": Orientation.VERTICAL}),
])
def test_thesis_controllers_as_policies_match_twin_run(name, trajectory, load):
    controller = make_controller(name, nominal=NominalModel.thesis(), gain_set="simulation", tick=1e-3)
    environment = joint_env.load("track", trajectory=trajectory, action_period=controller.period, seed=3,
                                 controller=name, **load)
    policy = ControllerPolicy(controller, spur_radius=9.525e-3 / 2)  # SPEC §2
    rmse = _episode(environment, policy)
    reference = run(Scenario(name, trajectory, seed=3, **load))
    assert rmse == reference.metrics.rmse
    n = len(reference.trace.angle)
    np.testing.assert_array_equal(environment.physics.true_angle[:n], reference.trace.angle)


def test_same_seed_same_episodes_and_episodes_differ():
    def first_observations(seed):
        environment = joint_env.load("hold", seed=seed)
        out = []
        for _ in range(2):
            timestep = environment.reset()
            out.append((timestep.observation["desired_angle"][0], environment.physics.episode.scenario.payload))
        return out

    assert first_observations(5) == first_observations(5)
    a, b = first_observations(5)
    assert a != b


def test_random_policy_raises_no_mujoco_warning():
    environment = joint_env.load("hold", seed=11)
    rng = np.random.default_rng(11)
    for _ in range(4):  # payloads and orientations vary by episode
        timestep = environment.reset()
        while not timestep.last():
            timestep = environment.step(rng.uniform(-100, 100, size=1))
            assert 0.0 <= timestep.reward <= 1.0
        warnings = environment.physics.data.warning
        assert all(warnings[i].number == 0 for i in range(len(warnings)))
        assert np.all(np.isfinite(environment.physics.true_angle))


def test_observations_match_their_spec_and_episode_lengths():
    environment = joint_env.load("track", trajectory=1, seed=0)
    timestep = environment.reset()
    spec = environment.observation_spec()
    assert set(timestep.observation) == set(spec)
    assert timestep.observation["desired_angle"].shape == (joint_env.PREVIEW + 1,)
    steps = 0
    while not timestep.last():
        timestep = environment.step([0.0])
        steps += 1
    assert steps == 188  # ceil(3 s / 16 ms)
    assert timestep.step_type == dm_env.StepType.LAST


def test_bad_arguments_are_rejected():
    with pytest.raises(InvalidScenario):
        joint_env.load("dance")
    with pytest.raises(InvalidScenario):
        joint_env.load("track", trajectory=9)
    with pytest.raises(InvalidScenario):
        joint_env.load("track", action_period=1.5e-3)
