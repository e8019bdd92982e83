"""``twin bench``: what a simulated second costs, as ratios measured in one run.

Reports, for the joint model at the default timestep: a bare ``mj_step`` loop,
one twin run (n = 1), a batch of many runs (n = 100 by default), and the same
single run through the dm_control environment, as wall seconds per simulated
second, with their ratios. Timings on a shared machine are noisy (other tenants
slow a run by up to a quarter here): every timing is the fastest of a few
repeats, the bare loop's and the twin's alike, and only ratios are compared.
"""

from __future__ import annotations

import dataclasses
import functools
import os
import pathlib
import time
from collections.abc import Callable

import mujoco

from twin.envs.runner import run_many
from twin.physics.model import compile_joint
from twin.sim.scenario import Scenario

REPEATS = 4  # of every twin timing; the bare loop is timed 5 times before and after each (here, a run
# slows by up to a quarter at random: the fastest of a few is the cost)


@dataclasses.dataclass(frozen=True)
class Bench:
    bare_step: float  # wall s per simulated s, plain mj_step loop of the joint at rest, one MjData, fastest seen
    twin_single: float  # wall s per simulated s, one twin run
    twin_batch: float  # wall s per simulated scenario-second, batch of `batch_size` on one thread
    batch_size: int
    env_single: float  # wall s per simulated s, the dm_control environment, same scenario and policy
    sweep_walls: dict  # workers -> wall s of the same sweep
    sweep_scenario_seconds: float  # simulated scenario-seconds in that sweep

    def lines(self) -> list[str]:
        return [
            f"bare mj_step:          {self.bare_step * 1e3:8.2f} ms per simulated s",
            f"twin, 1 run:           {self.twin_single * 1e3:8.2f} ms per simulated s "
            f"({self.twin_single / self.bare_step:.1f}x bare)",
            f"twin, {self.batch_size} runs batched on one thread: {self.twin_batch * 1e3:8.2f} ms per simulated scenario-s "
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


BARE_REPEATS = 5  # of every bare loop
BARE_LENGTH = 10  # a bare loop simulates this many times the run's duration


def _fastest(work: Callable[[], object], repeats: int, done: Callable[[], None] | None = None) -> float:
    """Wall seconds of the fastest of ``repeats`` calls of ``work``: on a shared machine the minimum is
    the cost, the rest is other tenants. ``done()`` after each call, outside its timing."""
    walls = []
    for _ in range(repeats):
        start = time.perf_counter()
        work()
        walls.append(time.perf_counter() - start)
        if done is not None:
            done()
    return min(walls)


def _bare_step_cost(seconds: float, done: Callable[[], None] | None = None) -> float:
    """A bare ``mj_step`` loop of the joint at rest, per simulated second."""
    joint = compile_joint()
    steps = int(round(seconds / joint.timestep))
    data = mujoco.MjData(joint.model)  # the joint stays at rest: every repeat steps the same state
    return _fastest(lambda: mujoco.mj_step(joint.model, data, nstep=steps), BARE_REPEATS, done) / seconds


def _sweep_grid() -> tuple[list, float]:
    """The 360-scenario thesis grid (3 controllers x 4 trajectories x 3 payloads x 2 orientations x 5 seeds)
    and the scenario-seconds it simulates."""
    from twin.batch.grid import expand
    from twin.physics.trajectories import trajectory

    points = expand({"controller": ["pva", "ffpva", "smc"], "trajectory": [1, 2, 3, 4], "payload": [0.0, 6.5, 13.5],
                     "orientation": ["horizontal", "vertical"], "seed": list(range(5))})
    return points, sum(trajectory(p.trajectory, spur_radius=1.0).duration for p in points)


def _sweep_walls(workers: int, progress: Callable[[int], None] | None = None) -> tuple[dict, float]:
    """The grid of :func:`_sweep_grid` timed end to end (workers start, run, store) with 1 worker and with
    ``workers``; ``progress(n)`` as ``run_sweep`` reports finished scenarios (its own sweeps do the same)."""
    import tempfile

    from twin.batch.sweep import run_sweep

    points, scenario_seconds = _sweep_grid()

    def sweep(count: int) -> None:
        with tempfile.TemporaryDirectory() as out:
            run_sweep(points, out=pathlib.Path(out), workers=count, progress=progress)

    return {count: _fastest(functools.partial(sweep, count), REPEATS) for count in sorted({1, workers})}, scenario_seconds


def planned_seconds(*, batch_size: int = 100, trajectory: int = 1, workers: int | None = None) -> float:
    """The scenario-seconds :func:`measure` simulates, counted before it runs: one warm-up run, five bare
    loops, and every repeat of the single run, the batch, the environment and the sweeps."""
    from twin.physics.trajectories import trajectory as reference

    duration = reference(trajectory, spur_radius=1.0).duration
    sweeps = len({1, workers or os.cpu_count() or 1})
    return (duration + 5 * BARE_REPEATS * BARE_LENGTH * duration  # five bare loops, one per stage and one last
            + REPEATS * duration * (1 + batch_size + 1) + REPEATS * sweeps * _sweep_grid()[1])


def measure(*, batch_size: int = 100, trajectory: int = 1, workers: int | None = None, bar=None) -> Bench:
    """Each measurement is preceded and the whole followed by a bare loop; the bare cost is the fastest
    of them all, so a quiet spell during one bare loop cannot flatter the twin. ``bar`` (a tqdm bar,
    optional) is given :func:`planned_seconds` before anything runs, counts the scenario-seconds simulated
    as each timed call ends (outside its timing; a sweep's as its scenarios finish) and is labelled with
    each of the four stages as it starts."""
    from twin.physics.trajectories import trajectory as reference

    run_seconds = reference(trajectory, spur_radius=1.0).duration  # the bar's units; timings use the run's own
    sweep_points, sweep_seconds = _sweep_grid()

    def stage(label: str) -> None:
        if bar is not None:
            bar.set_description(f"bench {label}")

    def done(scenario_seconds: float) -> Callable[[], None]:
        """What each timed call of ``scenario_seconds`` reports when it ends."""
        return lambda: None if bar is None else bar.update(scenario_seconds)

    if bar is not None:
        bar.reset(total=planned_seconds(batch_size=batch_size, trajectory=trajectory, workers=workers))
    stage("[1/4] one run and bare mj_step")
    scenario = Scenario("ffpva", trajectory)
    single = run_many([scenario])[0]  # also warms caches (model compile, imports, kernels)
    done(run_seconds)()
    duration = float(len(single.trace.time)) * 1e-3
    bare_done = done(BARE_LENGTH * run_seconds)
    bare = [_bare_step_cost(duration * BARE_LENGTH, bare_done)]
    twin_single = _fastest(lambda: run_many([scenario]), REPEATS, done(run_seconds)) / duration
    bare.append(_bare_step_cost(duration * BARE_LENGTH, bare_done))
    stage(f"[2/4] a batch of {batch_size} runs")
    batch = [Scenario("ffpva", trajectory, seed=s) for s in range(batch_size)]
    twin_batch = _fastest(lambda: run_many(batch, nthread=1), REPEATS,  # one core, as the bare loop
                          done(batch_size * run_seconds)) / (duration * batch_size)
    bare.append(_bare_step_cost(duration * BARE_LENGTH, bare_done))
    stage("[3/4] the dm_control environment")
    env_single = _env_cost(trajectory, duration, done(run_seconds))
    bare.append(_bare_step_cost(duration * BARE_LENGTH, bare_done))
    stage("[4/4] the sweep on 1 and all workers")
    walls, scenario_seconds = _sweep_walls(workers or os.cpu_count() or 1, None if bar is None else (
        lambda n: bar.update(n * sweep_seconds / len(sweep_points))))
    bare.append(_bare_step_cost(duration * BARE_LENGTH, bare_done))
    return Bench(bare_step=min(bare), twin_single=twin_single, twin_batch=twin_batch, batch_size=batch_size,
                 env_single=env_single, sweep_walls=walls, sweep_scenario_seconds=scenario_seconds)


def _env_cost(trajectory: int, duration: float, done: Callable[[], None] | None = None) -> float:
    """One FF + PVA episode through twin.envs.environment, the same scenario as the single twin run."""
    from controllers import make_controller
    from controllers.feedforward import NominalModel
    from controllers.policy import ControllerPolicy
    from twin.envs import environment as joint_env

    controller = make_controller("ffpva", nominal=NominalModel.thesis(), gain_set="simulation", tick=1e-3)
    environment = joint_env.load("track", trajectory=trajectory, seed=0)

    def episode() -> None:
        timestep = environment.reset()
        policy = ControllerPolicy(controller, spur_radius=environment.physics.spur_radius)
        while not timestep.last():
            timestep = environment.step(policy(timestep))

    return _fastest(episode, REPEATS, done) / duration
