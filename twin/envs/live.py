"""One scenario stepped on demand, with its target changed while it runs
(``twin view``).

The step order is :class:`twin.sim.tick.Ticker`'s, as in ``twin run``: sensors,
controller (at its period), valves and hydraulics, physics. Only the reference
differs: instead of a fixed trajectory it is a
*plan* that the user replaces while the joint moves:

* a target angle: a cycloidal move (eq. 5.2.5) from the current desired angle,
  at most ``MOVE_RATE`` fast and no shorter than ``MIN_MOVE``, then a hold;
* a trajectory T1-T4: a cycloidal move to its start angle, a short rest, then
  the trajectory as §7 defines it, then a hold at its end.

Sensor noise is drawn in blocks of ``NOISE_BLOCK`` ticks from the scenario's
seed and the block number, so a live run can last as long as the user likes.
"""

from __future__ import annotations

import dataclasses
import math

import mujoco
import numpy as np

from twin.envs.runner import thesis_controllers
from twin.physics.model import compile_joint
from twin.physics.sensing import uniform_noise
from twin.physics.ticks import whole_ticks
from twin.physics.trajectories import Segment, Trajectory, trajectory
from twin.sim.control import Setpoint
from twin.sim.plant_state import PlantState, place_on_manifold, true_start
from twin.sim.scenario import Scenario
from twin.sim.tick import Ticker

MOVE_RATE = math.radians(120.0)  # rad/s, average speed of a target move: T1's 120 deg in 1 s
MIN_MOVE = 0.3  # s
REST_BEFORE_TRAJECTORY = 0.3  # s
NOISE_BLOCK = 60_000  # ticks; a multiple of every PWM and controller period in ticks


@dataclasses.dataclass(frozen=True)
class Readout:
    time: float  # s since the start of this model
    angle: float  # rad, true output angle
    desired_angle: float  # rad
    duty: float  # %, command in force
    pressure_a: float  # Pa, measured
    pressure_b: float  # Pa, measured
    supply_pressure: float  # Pa, measured
    valve_open: tuple[bool, bool, bool, bool]  # V1..V4

    @property
    def error(self) -> float:
        return self.desired_angle - self.angle  # rad


class LiveJoint:
    """``scenario`` (its trajectory is the first plan), ready to :meth:`advance`."""

    def __init__(self, scenario: Scenario):
        preset = scenario.preset
        self.scenario = scenario
        self.joint = compile_joint(params=preset.params, payload_mass=scenario.payload,
                                   orientation=scenario.orientation, timestep=preset.timestep)
        self.model = self.joint.model
        self.data = mujoco.MjData(self.model)
        self.tick = preset.timestep
        self.spur_radius = preset.params.gears.spur_radius
        self.switch_controller(scenario.controller)

        first = trajectory(scenario.trajectory, spur_radius=self.spur_radius)
        self.plan, self.plan_start = first, 0.0
        y0 = true_start([scenario], np.array([first.start * self.spur_radius]))  # the sensor reads the start
        qpos = self.data.qpos[None, :].copy()
        place_on_manifold(qpos, self.joint, y0)
        self.data.qpos[:] = qpos[0]
        mujoco.mj_forward(self.model, self.data)
        self.plant = PlantState(scenarios=[scenario], joints=[self.joint], lengths=[NOISE_BLOCK],
                                initial_position=y0, tick=self.tick)
        d = self.data
        self.ticker = Ticker(self.plant, qpos=d.qpos[None, :], qvel=d.qvel[None, :], ctrl=d.ctrl[None, :],
                             qfrc_passive=d.qfrc_passive[None, :], qfrc_bias=d.qfrc_bias[None, :],
                             rack_dof=self.joint.rack_a_dof, step=self._physics_step)
        self.block, self.steps = 0, 0
        self.duty = np.zeros(1)

    def switch_controller(self, name: str) -> None:
        """Drive the joint with controller ``name`` from the next tick on (a fresh controller state)."""
        self.scenario = dataclasses.replace(self.scenario, controller=name)
        self.controller = thesis_controllers([self.scenario])[0]
        self.controller.reset(1)
        self.every = whole_ticks(self.controller.period, self.tick, what="controller period")
        pwm = whole_ticks(self.scenario.preset.params.valves.pwm_period, self.tick)
        if NOISE_BLOCK % self.every or NOISE_BLOCK % pwm:
            raise ValueError("NOISE_BLOCK must be a whole number of controller and PWM periods")

    @property
    def time(self) -> float:
        return self.steps * self.tick  # s

    def desired(self, at: float | None = None) -> tuple[float, float, float]:
        """The plan's desired rack position (m), velocity and acceleration at time ``at``."""
        t = self.time if at is None else at
        ref = self.plan.sample(np.array([t - self.plan_start]), self.spur_radius)
        return float(ref.position[0]), float(ref.velocity[0]), float(ref.acceleration[0])

    def set_target(self, angle: float) -> None:
        """Move to ``angle`` (rad) and hold there."""
        start = self.desired()[0] / self.spur_radius
        move = max(MIN_MOVE, abs(angle - start) / MOVE_RATE)
        self._replan(Trajectory(0, start, (Segment("cycloid", move, angle - start),)))

    def play(self, number: int) -> None:
        """Go to trajectory ``number``'s start, then run it."""
        chosen = trajectory(number, spur_radius=self.spur_radius)
        start = self.desired()[0] / self.spur_radius
        move = max(MIN_MOVE, abs(chosen.start - start) / MOVE_RATE)
        lead = (Segment("cycloid", move, chosen.start - start), Segment("rest", REST_BEFORE_TRAJECTORY))
        self._replan(Trajectory(number, start, lead + chosen.segments))

    def _replan(self, plan: Trajectory) -> None:
        self.plan, self.plan_start = plan, self.time

    @property
    def k(self) -> int:
        """Ticks into the current noise block."""
        return self.ticker.k

    def _next_noise_block(self) -> None:
        self.block += 1
        rng = np.random.default_rng([self.scenario.seed, self.block])
        sensors = self.scenario.preset.params.sensors
        if self.scenario.noise:
            self.plant.position_noise[0] = uniform_noise(rng, sensors.position_noise, (NOISE_BLOCK,))
            self.plant.pressure_noise[0] = uniform_noise(rng, sensors.pressure_noise, (NOISE_BLOCK, 3))
        self.ticker.restart(0)

    def _physics_step(self, k: int) -> None:
        mujoco.mj_step2(self.model, self.data)  # then mj_step1: derived fields (gravity) at the new state
        mujoco.mj_step1(self.model, self.data)

    def _command(self, k: int, measurement) -> np.ndarray:
        if k % self.every == 0:
            position, velocity, acceleration = self.desired()
            setpoint = Setpoint(position=np.array([position]), velocity=np.array([velocity]),
                                acceleration=np.array([acceleration]))
            self.duty = self.controller.update(self.time, measurement, setpoint)
        return self.duty

    def step(self) -> None:
        """One tick of :class:`twin.sim.tick.Ticker`."""
        if self.k == NOISE_BLOCK:
            self._next_noise_block()
        self.ticker.tick(self._command)
        self.steps += 1

    def advance(self, duration: float) -> None:
        """Step ``duration`` seconds (whole ticks, rounded down)."""
        for _ in range(int(duration / self.tick + 1e-9)):
            self.step()

    def readout(self) -> Readout:
        pa, pb = self.plant.measured_pressures(min(self.k, NOISE_BLOCK - 1))
        return Readout(
            time=self.time, angle=float(self.data.qpos[self.joint.spur_dof]),
            desired_angle=self.desired()[0] / self.spur_radius, duty=float(self.duty[0]),
            pressure_a=float(pa[0]), pressure_b=float(pb[0]),
            supply_pressure=float(self.plant.supply_now[0]),
            valve_open=tuple(bool(x) for x in self.plant.conductance[0] > 0))


@dataclasses.dataclass(frozen=True)
class Compare:
    """What the second joint of compare mode changes from the first: ``Scenario`` fields (SI) and
    the user's own ``KEY=VALUE`` text for display. Applied afresh to every first scenario, so a
    controller, payload or orientation the page changes is shared unless this pins it."""

    changes: dict  # Scenario field -> value, e.g. {"controller": "smc"}
    text: dict  # the user's keys -> the user's values (edge units), e.g. {"controller": "smc"}

    def applied(self, scenario: Scenario) -> Scenario:
        return dataclasses.replace(scenario, **self.changes)


class LiveJoints:
    """The first :class:`LiveJoint` and, in compare mode, a second one; every command and every
    tick goes to both, first then second, so they share targets, replays and time."""

    def __init__(self, scenario: Scenario, compare: Compare | None = None):
        self.compare = compare
        self.joints = [LiveJoint(scenario)]
        if compare is not None:
            self.joints.append(LiveJoint(compare.applied(scenario)))

    @property
    def first(self) -> LiveJoint:
        return self.joints[0]

    @property
    def second(self) -> LiveJoint | None:
        return self.joints[1] if len(self.joints) > 1 else None

    def set_target(self, angle: float) -> None:
        for joint in self.joints:
            joint.set_target(angle)

    def play(self, number: int) -> None:
        for joint in self.joints:
            joint.play(number)

    def switch_controller(self, name: str) -> None:
        """The first joint's controller; the second's too unless compare mode pins its own."""
        self.first.switch_controller(name)
        if self.second is not None and "controller" not in self.compare.changes:
            self.second.switch_controller(name)

    def step(self) -> None:
        for joint in self.joints:
            joint.step()

    def target(self) -> float:
        """Where the current plan ends and holds (rad)."""
        return self.first.plan.end
