"""Run a thesis controller as a policy in the dm_control environment of the joint.

    .venv/bin/python examples/run_policy.py [--controller ffpva|smc|pva] [--task track|hold] [--trajectory 1-4]

Prints the episode return and the tracking RMSE. Swap ``policy`` for your own
function of a ``dm_env.TimeStep`` to try another controller.
"""

from __future__ import annotations

import argparse
import math

from controllers import make_controller
from controllers.feedforward import NominalModel
from controllers.policy import ControllerPolicy
from twin.envs import environment as joint_env


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--controller", choices=("pva", "ffpva", "smc"), default="ffpva")
    parser.add_argument("--task", choices=joint_env.TASKS, default="track")
    parser.add_argument("--trajectory", type=int, choices=(1, 2, 3, 4), default=1)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()

    controller = make_controller(args.controller, nominal=NominalModel.thesis(), gain_set="simulation", tick=1e-3)
    env = joint_env.load(args.task, trajectory=args.trajectory, action_period=controller.period,
                         seed=args.seed, controller=args.controller)
    timestep = env.reset()
    policy = ControllerPolicy(controller, spur_radius=env.physics.spur_radius)
    episode_return = 0.0
    while not timestep.last():
        timestep = env.step(policy(timestep))
        episode_return += timestep.reward
    episode = env.physics.episode
    print(f"{args.controller} on {args.task} (payload {episode.scenario.payload * 1e3:.1f} g, "
          f"{episode.scenario.orientation.value}): return {episode_return:.1f} over "
          f"{env.physics.k} ms, RMSE {math.degrees(env.physics.episode_rmse()):.3f} deg")


if __name__ == "__main__":
    main()
