"""``twin bench``: what a simulated second costs, as ratios measured in one run.

Reports, for the joint model at the default timestep: a bare ``mj_step`` loop,
one twin run (n = 1), a batch of many runs (n = 100 by default), and the same
single run through the dm_control environment, as wall seconds per simulated
second, with their ratios. Timings on a shared machine are noisy: compare the ratios.
"""

from __future__ import annotations

import dataclasses
import os
import pathlib
import time

import mujoco

from twin.model import compile_joint
from twin.runner import run_many
from twin.scenario import Scenario


@dataclasses.dataclass(frozen=True)
class Bench:
    bare_step: float  # wall s per simulated s, plain mj_step loop, one MjData
    twin_single: float  # wall s per simulated s, one twin run
    twin_batch: float  # wall s per simulated scenario-second, batch of `batch_size`
    batch_size: int
    env_single: float  # wall s per simulated s, the dm_control environment, same scenario and policy
    sweep_walls: dict  # workers -> wall s of the same sweep
    sweep_scenario_seconds: float  # simulated scenario-seconds in that sweep

    def lines(self) -> list[str]:
        return [
            f"bare mj_step:          {self.bare_step * 1e3:8.2f} ms per simulated s",
            f"twin, 1 run:           {self.twin_single * 1e3:8.2f} ms per simulated s "
            f"({self.twin_single / self.bare_step:.1f}x bare)",
            f"twin, {self.batch_size} runs batched: {self.twin_batch * 1e3:8.2f} ms per simulated scenario-s "
            f"({self.twin_batch / self.bare_step:.2f}x bare; {self.twin_batch * self.batch_size * 1e3:.0f} ms "
            f"per simulated s of the whole batch)",
            f"dm_control env, 1 run: {self.env_single * 1e3:8.2f} ms per simulated s "
            f"({self.env_single / self.twin_single:.2f}x the twin's own loop)",
        ] + [
            f"sweep of {self.sweep_scenario_seconds:.0f} scenario-s, {w} worker{'s' if w > 1 else ''}: {wall:6.2f} s wall "
            f"= {wall / self.sweep_scenario_seconds * 1e3:.2f} ms per scenario-s "
            f"({wall / self.sweep_scenario_seconds / self.bare_step:.2f}x bare mj_step on one core; "
            f"{wall * w / self.sweep_scenario_seconds / self.bare_step:.2f}x per core used; "
            f"speed-up {self.sweep_walls[1] / wall:.2f}x over 1 worker)"
            for w, wall in self.sweep_walls.items()
        ]


def _bare_step_cost(seconds: float, repeats: int = 5) -> float:
    """The fastest of ``repeats`` bare loops: on a shared machine the minimum is the cost, the rest is
    other tenants; taking it makes every ratio to it conservative (the twin is timed once)."""
    joint = compile_joint()
    steps = int(round(seconds / joint.timestep))
    costs = []
    for _ in range(repeats):
        data = mujoco.MjData(joint.model)
        start = time.perf_counter()
        mujoco.mj_step(joint.model, data, nstep=steps)
        costs.append((time.perf_counter() - start) / seconds)
    return min(costs)


def _sweep_walls(workers: int) -> tuple[dict, float]:
    """The 360-scenario thesis grid (3 controllers x 4 trajectories x 3 payloads x 2 orientations x 5 seeds),
    timed end to end (workers start, run, store) with 1 worker and with ``workers``."""
    import tempfile

    from twin.grid import expand
    from twin.sweep import run_sweep
    from twin.trajectories import trajectory

    points = expand({"controller": ["pva", "ffpva", "smc"], "trajectory": [1, 2, 3, 4], "payload": [0.0, 6.5, 13.5],
                     "orientation": ["horizontal", "vertical"], "seed": list(range(5))})
    scenario_seconds = sum(trajectory(p.trajectory, spur_radius=1.0).duration for p in points)
    walls = {}
    for count in sorted({1, workers}):
        with tempfile.TemporaryDirectory() as out:
            start = time.perf_counter()
            run_sweep(points, out=pathlib.Path(out), workers=count)
            walls[count] = time.perf_counter() - start
    return walls, scenario_seconds


def measure(*, batch_size: int = 100, trajectory: int = 1, workers: int | None = None) -> Bench:
    scenario = Scenario("ffpva", trajectory)
    run_many([scenario])  # warm caches (model compile, imports)
    start = time.perf_counter()
    single = run_many([scenario])[0]
    duration = float(len(single.trace.time)) * 1e-3
    twin_single = (time.perf_counter() - start) / duration
    batch = [Scenario("ffpva", trajectory, seed=s) for s in range(batch_size)]
    start = time.perf_counter()
    run_many(batch)
    twin_batch = (time.perf_counter() - start) / (duration * batch_size)
    walls, scenario_seconds = _sweep_walls(workers or os.cpu_count() or 1)
    return Bench(bare_step=_bare_step_cost(duration * 10), twin_single=twin_single,
                 twin_batch=twin_batch, batch_size=batch_size, env_single=_env_cost(trajectory, duration),
                 sweep_walls=walls, sweep_scenario_seconds=scenario_seconds)


def _env_cost(trajectory: int, duration: float) -> float:
    """One FF + PVA episode through twin.env, the same scenario as the single twin run."""
    from controllers import make_controller
    from controllers.feedforward import NominalModel
    from controllers.policy import ControllerPolicy
    from twin import env as joint_env

    controller = make_controller("ffpva", nominal=NominalModel.thesis(), gain_set="simulation", tick=1e-3)
    environment = joint_env.load("track", trajectory=trajectory, seed=0)
    start = time.perf_counter()
    timestep = environment.reset()
    policy = ControllerPolicy(controller, spur_radius=environment.physics.spur_radius)
    while not timestep.last():
        timestep = environment.step(policy(timestep))
    return (time.perf_counter() - start) / duration
