"""The joint as a dm_control environment (``dm_env`` interface).

    env = twin.envs.environment.load(task="track", trajectory=1, seed=0)
    timestep = env.reset()
    while not timestep.last():
        timestep = env.step([duty_percent])

The physics is the twin's own compiled model, and every physics step is one
tick of :class:`twin.sim.tick.Ticker`, the step order ``twin run`` uses, with
the same sensors, observer, valves, hydraulics and friction (no second
implementation); the agent's held action is the command. The observation
reads the tick's measurement, which the tick then acts on.

Tasks
    ``track``: follow T1-T4 (``trajectory=1..4``) or, with ``trajectory=None``,
    a random smooth sequence of cycloidal moves between 30 and 160 deg.
    ``hold``: reach and hold a random angle from a random start, with a random
    payload (0 - 13.5 g) and orientation (unless given), for 2 s.
Reward per step: exp(-e^2 / 2) with e the true tracking error in degrees at
the end of the step (1 on target, 0.61 at 1 deg, 0.01 at 3 deg).
Action: duty in [-100, 100] %, held for one action period: by default the
scenario's PWM period (16 ms unless ``pwm_period`` is given), or e.g. 1 ms with
``action_period=1e-3``.
Observations: measured rack position and angle, observer velocity and
acceleration, measured supply and chamber pressures, the desired angle now and
at the next ``PREVIEW`` PWM periods (the scenario's period), the desired rack
velocity and acceleration now, the time within the PWM period and the time
since the episode began.
Randomness: the task's random state (seeded by ``seed``) draws each episode's
targets, payloads and sensor-noise seeds; the first episode uses ``seed``
itself for the sensor noise (position and pressures), so at every tick it
shares with ``twin run --seed`` it sees the same noise.
Before the first ``reset()`` the physics holds a default episode (no random
draws), so the specs exist at once, as in dm_control's suite.
"""

from __future__ import annotations

import collections
import dataclasses
import decimal
import math
import numbers
import os
import warnings

os.environ.setdefault("MUJOCO_GL", "egl")  # dm_control picks a GL backend on import; the twin never renders here

import numpy as np  # noqa: E402
from dm_control import mujoco as dm_mujoco  # noqa: E402
from dm_control.rl import control  # noqa: E402
from dm_control.suite import base  # noqa: E402
from dm_env import specs  # noqa: E402

from twin.exceptions import InvalidAction, InvalidScenario
from twin.physics.model import THESIS_PAYLOADS, Orientation, build_mjcf, compile_joint
from twin.physics.ticks import whole_ticks
from twin.physics.trajectories import Reference, Segment, Trajectory, trajectory
from twin.sim.metrics import tracking_metrics
from twin.sim.plant_state import PlantState, place_on_manifold, true_start
from twin.sim.scenario import Scenario
from twin.sim.simulation import scored
from twin.sim.tick import Ticker

TASKS = ("track", "hold")
PREVIEW = 5  # future desired-angle samples, one PWM period apart
HOLD_DURATION = 2.0  # s
RANDOM_TRACK_DURATION = 4.0  # s
RANDOM_RANGE = (math.radians(30.0), math.radians(160.0))  # rad, inside the friction fit
MAX_RANDOM_PAYLOAD = max(THESIS_PAYLOADS)  # kg


@dataclasses.dataclass(frozen=True)
class Episode:
    """What one episode runs: the scenario, the reference and where the rack starts."""

    scenario: Scenario
    trajectory: Trajectory
    initial_angle: float  # rad


class JointPhysics(dm_mujoco.Physics):
    """dm_control physics whose every step is one tick of the twin."""

    def begin(self, episode: Episode, *, ticks: int) -> None:
        """Rebuild the model for the episode's payload and orientation and start it at rest."""
        s = episode.scenario
        preset = s.preset
        root = build_mjcf(params=preset.params, payload_mass=s.payload, orientation=s.orientation,
                          timestep=preset.timestep)
        self.reload_from_xml_string(root.to_xml_string(), root.get_assets())
        self.joint = compile_joint(params=preset.params, payload_mass=s.payload, orientation=s.orientation,
                                   timestep=preset.timestep)
        self.episode, self.ticks = episode, ticks
        r_s = preset.params.gears.spur_radius
        self.spur_radius = r_s
        self.pwm_ticks = whole_ticks(preset.params.valves.pwm_period, preset.timestep, what="PWM period")
        times = np.arange(ticks + PREVIEW * self.pwm_ticks + 1) * preset.timestep
        self.reference: Reference = episode.trajectory.sample(times, r_s)
        y0 = true_start([s], np.array([episode.initial_angle * r_s]))  # the sensor reads the start angle
        place_on_manifold(self.data.qpos[None, :], self.joint, y0)
        self.data.qvel[:] = 0.0
        self.plant = PlantState(scenarios=[s], joints=[self.joint], lengths=[ticks + 1],
                                initial_position=y0, tick=preset.timestep)
        d = self.data
        # dm_control's step: mj_step2 then mj_step1, so derived fields (gravity) are at the new state.
        self.ticker = Ticker(self.plant, qpos=d.qpos[None, :], qvel=d.qvel[None, :], ctrl=d.ctrl[None, :],
                             qfrc_passive=d.qfrc_passive[None, :], qfrc_bias=d.qfrc_bias[None, :],
                             rack_dof=self.joint.rack_a_dof, step=lambda k: super(JointPhysics, self).step(1))
        self.duty = np.zeros(1)
        self.ticker.sense()
        self.true_angle = np.zeros(ticks + 1)
        self.true_angle[0] = self.data.qpos[self.joint.spur_dof]
        self.measured_position = np.zeros(ticks)  # m, the Hall reading each tick acted on

    @property
    def k(self) -> int:
        """Ticks since the episode began."""
        return self.ticker.k

    @property
    def measurement(self):
        """The sensors and observer now (sampled once per tick; the next tick acts on it)."""
        return self.ticker.sense()

    def step(self, nstep: int = 1) -> None:
        for _ in range(nstep):
            if self.k >= self.ticks:
                raise InvalidScenario("the episode is over: reset the environment")
            self.measured_position[self.k] = self.ticker.sense().position[0]  # act() uses this same sample
            self.ticker.act(self.duty)
            self.true_angle[self.k] = self.data.qpos[self.joint.spur_dof]

    def ticks_for(self, duration: float) -> int:
        """Ticks in an episode of ``duration`` (s): whole action periods, rounded up."""
        return episode_steps(duration, self.action_period) * whole_ticks(self.action_period, self.timestep())

    def desired_angle(self, k: int | None = None) -> float:
        return float(self.reference.position[self.k if k is None else k] / self.spur_radius)

    def angle_error(self) -> float:
        """True tracking error now (rad)."""
        return self.desired_angle() - float(self.true_angle[self.k])

    def episode_rmse(self) -> float:
        """RMSE (rad) over the episode's reference duration, as ``twin run`` reports it: of the angle its
        plant scores (the Hall reading on ``as-built``, the true angle on ``thesis``). Only once the
        episode has run that long (InvalidScenario before: the ticks not yet run have no angle)."""
        n = int(round(self.episode.trajectory.duration / self.timestep()))
        if self.k < n:
            raise InvalidScenario(f"the episode's RMSE needs its whole {n * self.timestep():g} s; "
                                  f"{self.k * self.timestep():g} s have run")
        desired = self.reference.position[:n] / self.spur_radius
        angle = scored(self.true_angle[:n], self.measured_position[:n], self.episode.scenario.preset)
        return tracking_metrics(desired, angle).rmse


class JointTask(base.Task):
    """``track`` or ``hold``; see the module docstring."""

    def __init__(self, *, name: str, trajectory_number: int | None, scenario: Scenario,
                 randomise_load: bool, seed: int):
        super().__init__(random=seed)
        self.name = name
        self.trajectory_number = trajectory_number
        self.base_scenario = scenario
        self.randomise_load = randomise_load
        self._first_seed = scenario.seed
        self._episodes = 0

    def _random_moves(self, start: float) -> Trajectory:
        """Cycloidal moves to random angles with random rests, exactly RANDOM_TRACK_DURATION long."""
        segments, level, elapsed = [], start, 0.0
        while True:
            move = float(self.random.choice([0.5, 0.75, 1.0]))
            if elapsed + move > RANDOM_TRACK_DURATION:
                break
            target = self.random.uniform(*RANDOM_RANGE)
            rest = min(float(self.random.choice([0.25, 0.5])), RANDOM_TRACK_DURATION - elapsed - move)
            segments.append(Segment("cycloid", move, target - level))
            if rest > 0:
                segments.append(Segment("rest", rest))
            level, elapsed = target, elapsed + move + rest
        if RANDOM_TRACK_DURATION - elapsed > 1e-12:
            segments.append(Segment("rest", RANDOM_TRACK_DURATION - elapsed))
        return Trajectory(0, start, tuple(segments))

    def default_episode(self) -> Episode:
        """What the physics holds before the first reset: drawn from nothing random, so building
        it does not change the episodes that ``reset()`` gives."""
        if self.name == "track" and self.trajectory_number is not None:
            r_s = self.base_scenario.preset.params.gears.spur_radius
            reference = trajectory(self.trajectory_number, spur_radius=r_s)
        else:
            reference = Trajectory(0, sum(RANDOM_RANGE) / 2, (Segment("rest", self.duration),))
        return Episode(self.base_scenario, reference, reference.start)

    def next_episode(self) -> Episode:
        seed = self._first_seed if self._episodes == 0 else int(self.random.randint(2**31 - 1))
        self._episodes += 1
        scenario = dataclasses.replace(self.base_scenario, seed=seed)
        r_s = scenario.preset.params.gears.spur_radius
        if self.name == "track":
            if self.trajectory_number is not None:
                reference = trajectory(self.trajectory_number, spur_radius=r_s)
            else:
                reference = self._random_moves(self.random.uniform(*RANDOM_RANGE))
            return Episode(scenario, reference, reference.start)
        if self.randomise_load:
            scenario = dataclasses.replace(
                scenario, payload=float(self.random.uniform(0.0, MAX_RANDOM_PAYLOAD)),
                orientation=Orientation(self.random.choice([o.value for o in Orientation])))
        target, start = self.random.uniform(*RANDOM_RANGE), self.random.uniform(*RANDOM_RANGE)
        return Episode(scenario, Trajectory(0, target, (Segment("rest", HOLD_DURATION),)), start)

    @property
    def duration(self) -> float:
        """Every episode of this task lasts this long (s)."""
        if self.name == "hold":
            return HOLD_DURATION
        if self.trajectory_number is None:
            return RANDOM_TRACK_DURATION
        r_s = self.base_scenario.preset.params.gears.spur_radius
        return trajectory(self.trajectory_number, spur_radius=r_s).duration

    def initialize_episode(self, physics: JointPhysics) -> None:
        physics.begin(self.next_episode(), ticks=physics.ticks_for(self.duration))
        self._clipped_said = False

    def action_spec(self, physics):
        return specs.BoundedArray(shape=(1,), dtype=np.float64, minimum=-100.0, maximum=100.0, name="duty")

    def before_step(self, action, physics: JointPhysics) -> None:
        """The action is the duty in %: a non-finite one is refused (InvalidAction); one outside
        [-100, 100] is clipped, and the first clip of an episode is reported (a warning)."""
        try:  # a number, not text or a truth value (NumPy reads "50" as 50 and True as 1)
            given = np.asarray(action)  # an object array: a Decimal, a Fraction, an int past int64
            if given.dtype.kind not in "iuf" and not (given.dtype.kind == "O" and all(map(_a_number, given.flat))):
                raise TypeError(given.dtype)
            duty = given.astype(float).reshape(1)
        except (TypeError, ValueError):
            raise InvalidAction(f"the action must be one number (duty in %), got {action!r}") from None
        if not np.all(np.isfinite(duty)):
            raise InvalidAction(f"the action must be a finite duty in %, got {float(duty[0])}")
        clipped = np.clip(duty, -100.0, 100.0)
        if clipped[0] != duty[0] and not getattr(self, "_clipped_said", False):
            warnings.warn(f"action {duty[0]:g} % clipped to {clipped[0]:g} % (the duty is within ±100 %); "
                          "further clips this episode are not reported", stacklevel=2)
            self._clipped_said = True
        physics.duty = clipped

    def get_observation(self, physics: JointPhysics) -> collections.OrderedDict:
        m = physics.measurement
        pa, pb = physics.plant.measured_pressures(min(physics.k, physics.ticks))
        every = physics.pwm_ticks
        k = physics.k
        preview = [physics.desired_angle(k + i * every) for i in range(PREVIEW + 1)]
        obs = collections.OrderedDict()
        obs["rack_position"] = m.position.copy()
        obs["angle"] = m.position / physics.spur_radius
        obs["velocity"] = m.velocity.copy()
        obs["acceleration"] = m.acceleration.copy()
        obs["supply_pressure"] = m.supply_pressure.copy()
        obs["chamber_pressures"] = np.array([pa[0], pb[0]])
        obs["desired_angle"] = np.array(preview)
        obs["desired_velocity"] = physics.reference.velocity[k:k + 1].copy()
        obs["desired_acceleration"] = physics.reference.acceleration[k:k + 1].copy()
        obs["time_in_period"] = np.array([(k % every) * physics.timestep()])
        obs["time"] = np.array([k * physics.timestep()])
        return obs

    def get_reward(self, physics: JointPhysics) -> float:
        error_deg = math.degrees(physics.angle_error())
        return float(math.exp(-0.5 * error_deg**2))


def _a_number(x: object) -> bool:
    """A real number of any type (a Python or NumPy one, a Decimal, a Fraction), not a truth value."""
    return isinstance(x, numbers.Real | decimal.Decimal) and not isinstance(x, bool | np.bool_)


def episode_steps(duration: float, action_period: float) -> int:
    return math.ceil(round(duration / action_period, 9))


MAX_TASK_SEED = 2**32 - 1  # dm_control's task seeds a NumPy RandomState, which takes no more


def load(task: str = "track", *, trajectory: int | None = 1, action_period: float | None = None,
         seed: int = 0, controller: str = "ffpva", **scenario) -> control.Environment:
    """A dm_control Environment of the joint.

    ``scenario`` takes the keyword arguments of :class:`twin.sim.scenario.Scenario`
    (``payload`` in kg, ``orientation``, ``plant``, ``noise``, ``supply_pressure``,
    ``pwm_period`` in s). ``action_period`` (s) defaults to the scenario's PWM period.
    ``hold`` randomises payload and orientation unless either is given.
    """
    if task not in TASKS:
        raise InvalidScenario(f"unknown task {task!r}: choose one of {', '.join(TASKS)}")
    if trajectory is not None and trajectory not in (1, 2, 3, 4):  # True or 1.0: refused by the Scenario below
        raise InvalidScenario(f"unknown trajectory {trajectory!r}: choose 1-4 or None (random)")
    randomise_load = task == "hold" and "payload" not in scenario and "orientation" not in scenario
    base_scenario = Scenario(controller, trajectory or 1, seed=seed, **scenario)
    if seed > MAX_TASK_SEED:  # twin run takes up to 2^63 - 1; dm_control's random state raised a NumPy error
        raise InvalidScenario(f"the environment's seed must be from 0 to 2^32 - 1 (its task's random state), "
                              f"got {seed}")
    if action_period is None:
        action_period = base_scenario.preset.params.valves.pwm_period
    root = build_mjcf(params=base_scenario.preset.params, payload_mass=base_scenario.payload,
                      orientation=base_scenario.orientation, timestep=base_scenario.preset.timestep)
    physics = JointPhysics.from_xml_string(root.to_xml_string(), root.get_assets())
    physics.action_period = action_period
    whole_ticks(action_period, physics.timestep(), what="action period")
    joint_task = JointTask(name=task, trajectory_number=trajectory if task == "track" else None,
                           scenario=base_scenario, randomise_load=randomise_load, seed=seed)
    if action_period > joint_task.duration:  # one step would run the whole episode and past it
        raise InvalidScenario(f"action period of {action_period} s is longer than the episode "
                              f"({joint_task.duration:g} s)")
    physics.begin(joint_task.default_episode(), ticks=physics.ticks_for(joint_task.duration))
    steps = episode_steps(joint_task.duration, action_period)
    # dm_control ends an episode once step_count >= time_limit / control_timestep.
    return control.Environment(physics, joint_task, time_limit=(steps - 0.5) * action_period,
                               control_timestep=action_period)
