"""The simulation loop: many scenarios stepped together, in the one step order of
:class:`twin.sim.tick.Ticker` (sensors, observer, controllers if due, valves,
hydraulics, MuJoCo step), on ``mujoco.batch.Batch``.

The physics step equals the sensor tick. Scenarios with different payloads or
orientations run on their own compiled models in the same batch; a scenario
that ends early stops being stepped.
"""

from __future__ import annotations

import dataclasses
import functools
import time
from collections.abc import Callable, Sequence

import mujoco
import mujoco.batch
import numpy as np

from twin.exceptions import InvalidScenario, SimulationFailed
from twin.physics.model import JointModel, Orientation, compile_joint
from twin.physics.params import JointParams
from twin.physics.scenario_axis import selector
from twin.physics.ticks import whole_ticks
from twin.physics.trajectories import trajectory
from twin.plants import Plant
from twin.sim.control import Controller, Setpoint
from twin.sim.metrics import Metrics, tracking_metrics
from twin.sim.plant_state import PlantState, groups, place_on_manifold, true_start
from twin.sim.scenario import Scenario
from twin.sim.tick import Ticker

PROGRESS_EVERY = 250  # ticks between progress callbacks


@dataclasses.dataclass(frozen=True)
class Trace:
    """Time series of one run, SI units; arrays are (T,) unless noted."""

    time: np.ndarray  # s
    desired_angle: np.ndarray  # rad
    angle: np.ndarray  # rad, the output shaft (spur joint)
    rack_position: np.ndarray  # m, true y
    measured_position: np.ndarray  # m, Hall sensor
    duty: np.ndarray  # %, command in force
    valve_open: np.ndarray  # (T, 4) bool, V1..V4
    pressure_a: np.ndarray  # Pa
    pressure_b: np.ndarray  # Pa
    supply_pressure: np.ndarray  # Pa
    coupling_error: np.ndarray  # rad, spur angle - y / r_s
    tooth_force_spur: np.ndarray  # N, pinion-spur mesh: spur coupling torque / r_s
    tooth_force_rack_a: np.ndarray  # N, rack A - pinion mesh: what rack A pushes into the teeth
    tooth_force_rack_b: np.ndarray  # N, rack B - pinion mesh
    velocity: np.ndarray  # m/s, true rack velocity (read when the tick was sensed)
    estimated_velocity: np.ndarray  # m/s, the observer's v_hat at that tick
    estimated_acceleration: np.ndarray  # m/s^2, the observer's a_hat


def scored_angle(trace: Trace, preset: Plant) -> np.ndarray:
    """rad, (T,): the angle the metrics score: on a plant that scores its sensor (``metrics_on_sensor``, as
    the thesis's experiments did) the Hall reading over the spur's pitch radius, else the true output angle."""
    return scored(trace.angle, trace.measured_position, preset)


def scored(angle: np.ndarray, measured_position: np.ndarray, preset: Plant) -> np.ndarray:
    """:func:`scored_angle` from the true output angles (rad) and the Hall readings (m) of the same ticks,
    for loops that keep no :class:`Trace` (the dm_control environment)."""
    return measured_position / preset.params.gears.spur_radius if preset.metrics_on_sensor else angle


@dataclasses.dataclass(frozen=True)
class Result:
    scenario: Scenario
    trace: Trace
    metrics: Metrics
    warnings: tuple[str, ...]
    wall_time: float  # s, for the whole batch this run was part of

    @property
    def scored_angle(self) -> np.ndarray:
        """rad, (T,): the angle this run's metrics score (:func:`scored_angle`)."""
        return scored_angle(self.trace, self.scenario.preset)


@functools.lru_cache(maxsize=64)
def _joint(params: JointParams, payload: float, orientation: Orientation, timestep: float) -> JointModel:
    return compile_joint(params=params, payload_mass=payload, orientation=orientation, timestep=timestep)


def _warnings(counts: np.ndarray) -> tuple[str, ...]:
    """Names and counts of the warnings raised, from one simulation's counters (mjNWARNING,)."""
    return tuple(f"{mujoco.mjtWarning(index).name} x{count}" for index, count in enumerate(counts) if count)


RUN_PART = 200  # runs simulated at once where a command's runs can be many: a run keeps its whole trace (about
# 1.2 MB on T1-T3) until its batch ends, and one batch of 99,000 ran out of 20 GB (2026-11-27)


def simulate_in_parts(scenarios: Sequence[Scenario], *, controllers: Sequence[Controller], keep: Callable,
                      progress_of: Callable[[int], Callable | None] | None = None, nthread: int = 0) -> list:
    """``keep(result)`` of each scenario's run, in order, simulated :data:`RUN_PART` at a time so that memory
    holds one part's traces, not all; ``progress_of(count)`` gives each part's ``progress`` (as for
    :func:`simulate`). Each run is its own (its seed, its state), so the numbers are one batch's (tested)."""
    kept: list = []
    for start in range(0, len(scenarios), RUN_PART):
        part = slice(start, start + RUN_PART)
        results = simulate(scenarios[part], controllers=controllers[part], nthread=nthread,
                           progress=None if progress_of is None else progress_of(len(scenarios[part])))
        kept += [keep(r) for r in results]
    return kept


def simulate(scenarios: Sequence[Scenario], *, controllers: Sequence[Controller],
             progress: Callable[[int, int], None] | None = None, nthread: int = 0,
             start_positions: np.ndarray | None = None) -> list[Result]:
    """Run every scenario to the end of its trajectory; one :class:`Result` each, in order.

    ``controllers[i]`` drives scenario i; scenarios that share one controller
    instance are driven by it together, vectorised (its arrays are in the order
    of those scenarios). ``twin.envs.runner`` builds them from the scenarios' names.
    ``progress(done_ticks, total_ticks)`` is called as the batch advances. ``start_positions`` (n,),
    m: where each rack starts at rest as its sensor reads it, instead of its trajectory's start (an
    open-loop experiment from chosen rest positions; the reference is still the trajectory's).
    """
    if not scenarios:
        raise InvalidScenario("no scenarios to simulate")
    started = time.perf_counter()
    n = len(scenarios)
    plants: list[Plant] = [s.preset for s in scenarios]
    h = plants[0].timestep
    if any(p.timestep != h for p in plants):
        raise InvalidScenario("scenarios in one batch must share the physics timestep")
    joints = [_joint(p.params, s.payload, s.orientation, p.timestep) for s, p in zip(scenarios, plants, strict=True)]
    dof = joints[0]
    if any((j.rack_a_dof, j.spur_dof) != (dof.rack_a_dof, dof.spur_dof) for j in joints):
        raise SimulationFailed("joint models disagree on their degrees of freedom")

    batch = mujoco.batch.Batch(joints[0].model, nsim=n, nthread=nthread, persistent=True)
    if any(j.model is not joints[0].model for j in joints):
        batch.set_models([j.model for j in joints])
    qpos, qvel, ctrl = batch.bind("qpos"), batch.bind("qvel"), batch.bind("ctrl")
    qfrc_bias, qfrc_passive = batch.bind("qfrc_bias"), batch.bind("qfrc_passive")
    qfrc_constraint = batch.bind("qfrc_constraint")

    spur_radius = np.array([p.params.gears.spur_radius for p in plants])
    trajectories = [trajectory(s.trajectory, spur_radius=r) for s, r in zip(scenarios, spur_radius, strict=True)]
    lengths = np.array([whole_ticks(tr.duration, h, what="trajectory") for tr in trajectories])
    ticks = int(lengths.max())
    t = np.arange(ticks) * h
    sampled: dict = {}  # scenarios of one trajectory and gearing share their reference
    for tr, r in zip(trajectories, spur_radius, strict=True):
        if (tr, r) not in sampled:
            sampled[tr, r] = tr.sample(t, r)
    references = [sampled[tr, r] for tr, r in zip(trajectories, spur_radius, strict=True)]
    y_d = np.stack([ref.position for ref in references])
    v_d = np.stack([ref.velocity for ref in references])
    a_d = np.stack([ref.acceleration for ref in references])

    reported = y_d[:, 0] if start_positions is None else np.asarray(start_positions, dtype=float)
    start = true_start(scenarios, reported)  # the Hall sensor reads the reference's start there
    for i, joint in enumerate(joints):
        place_on_manifold(qpos[i:i + 1], joint, start[i:i + 1])
    qvel[:] = 0.0
    batch.forward()
    plant = PlantState(scenarios=scenarios, joints=joints, lengths=lengths, initial_position=start, tick=h,
                       idle_after_end=True)  # traces end at their lengths

    if len(controllers) != n:
        raise InvalidScenario(f"{len(controllers)} controllers for {n} scenarios")
    controller_groups = []
    for _, idx in groups([id(c) for c in controllers]).items():
        controller = controllers[idx[0]]
        controller.reset(len(idx))
        controller_groups.append((controller, selector(idx), whole_ticks(controller.period, h, what="controller period")))

    duty = np.zeros(n)
    failures: dict[int, str] = {}
    active = np.flatnonzero(lengths > 1)  # scenario i is stepped at ticks 0 .. lengths[i] - 2
    ends = {int(length) for length in lengths}
    # Recorded tick-major, (ticks, n): each tick writes contiguous rows.
    rec = {name: np.zeros((ticks, n)) for name in ("y", "ym", "theta", "duty", "pa", "pb", "ps", "fs", "fa", "fb", "v", "vh", "ah")}
    valve_open = np.zeros((ticks, n, 4), dtype=bool)
    stage_vel = int(mujoco.mjtStage.mjSTAGE_VEL)
    def step(k: int) -> None:
        nonlocal active
        if k + 1 in ends:
            active = active[lengths[active] > k + 1]
        try:  # derived fields (gravity) at the new state; a finished scenario stops here
            batch.step(ids=None if len(active) == n else active, stage=stage_vel)
        except mujoco.batch.SimulationError as error:
            for i in error.ids:
                failures[int(i)] = f"MuJoCo error at t = {k * h:.3f} s: {batch.error(int(i))}"
            active = np.array([i for i in active if int(i) not in failures], dtype=int)

    def command(k: int, measurement) -> np.ndarray:
        for controller, idx, every in controller_groups:
            if k % every == 0:
                setpoint = Setpoint(position=y_d[idx, k], velocity=v_d[idx, k], acceleration=a_d[idx, k])
                duty[idx] = controller.update(k * h, measurement.subset(idx), setpoint)
        return duty

    ticker = Ticker(plant, qpos=qpos, qvel=qvel, ctrl=ctrl, qfrc_passive=qfrc_passive, qfrc_bias=qfrc_bias,
                    rack_dof=dof.rack_a_dof, step=step)
    for k in range(ticks):
        rec["theta"][k] = qpos[:, dof.spur_dof]  # before the step, like y
        ticker.tick(command)
        rec["y"][k] = ticker.position
        rec["ym"][k] = ticker.measurement.position  # what tick k sensed
        rec["v"][k] = ticker.velocity
        rec["vh"][k] = ticker.measurement.velocity
        rec["ah"][k] = ticker.measurement.acceleration
        rec["duty"][k] = duty
        rec["pa"][k] = plant.pressure_a
        rec["pb"][k] = plant.pressure_b
        rec["ps"][k] = plant.supply_now
        valve_open[k] = plant.conductance > 0
        # Constraint forces of this step (computed at tick k's state; not refreshed by the stage above).
        rec["fs"][k] = np.abs(qfrc_constraint[:, dof.spur_dof]) / spur_radius
        rec["fa"][k] = np.abs(qfrc_constraint[:, dof.rack_a_dof])
        rec["fb"][k] = np.abs(qfrc_constraint[:, dof.rack_b_dof])
        if progress is not None and (k % PROGRESS_EVERY == 0 or k == ticks - 1):
            progress(k + 1, ticks)

    wall = time.perf_counter() - started
    warning_counts = batch.warning[:, :, 1]  # (n, mjNWARNING): mjWarningStat.number of every simulation
    results = []
    for i, s in enumerate(scenarios):
        T = lengths[i]
        series = {name: rec[name][:T, i].copy() for name in rec}  # contiguous per run
        theta = series["theta"]
        desired = y_d[i, :T] / spur_radius[i]
        warnings = _warnings(warning_counts[i])
        if i in failures:
            warnings += (failures[i],)
        if not np.all(np.isfinite(theta)):
            warnings += ("state is not finite",)
        trace = Trace(
            time=t[:T], desired_angle=desired, angle=theta, rack_position=series["y"],
            measured_position=series["ym"], duty=series["duty"], valve_open=valve_open[:T, i].copy(),
            pressure_a=series["pa"], pressure_b=series["pb"], supply_pressure=series["ps"],
            coupling_error=theta - series["y"] / spur_radius[i],
            tooth_force_spur=series["fs"], tooth_force_rack_a=series["fa"], tooth_force_rack_b=series["fb"],
            velocity=series["v"], estimated_velocity=series["vh"], estimated_acceleration=series["ah"],
        )
        tr_i = trajectories[i]
        scored = scored_angle(trace, plants[i])
        metrics = tracking_metrics(desired, scored, ends_at_rest=tr_i.ends_at_rest,
                                   rest_end_ticks=[int(round(e / h)) - 1 for e in tr_i.rest_ends()])
        results.append(Result(scenario=s, trace=trace, metrics=metrics, warnings=warnings, wall_time=wall))
    return results
