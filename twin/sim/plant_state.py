"""The plant side of n scenarios between MuJoCo steps: one implementation for
every loop that drives the joint, called in the step order of :class:`twin.sim.tick.Ticker`.

Per tick k, given the true rack state from MuJoCo:

``sense(k, y)``
    the Hall sample with its seeded noise, the observer's v_hat and a_hat,
    and the measured supply pressure -> a :class:`Measurement`;
``actuate(k, duty, y, v, external)``
    the valves (delays, dead zone, PWM), the hydraulic circuit and the implicit
    rack step with friction -> the two piston forces to write into ``ctrl``.

Arrays have a leading scenario axis (n,). Scenarios keep their own noise
generator (seeded by ``Scenario.seed``), so batching does not change any
scenario's numbers.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from twin.physics import hydraulics
from twin.physics.chambers import CompressibleCircuit
from twin.physics.hall import HallReading
from twin.physics.model import JointModel, referred_mass
from twin.physics.params import NOMINAL_PARAMS
from twin.physics.scenario_axis import selector
from twin.physics.sensing import FirstOrderObserver, KalmanObserver, uniform_noise
from twin.physics.stiction_map import StictionMaps
from twin.physics.valves import ValveBank
from twin.plants import Plant
from twin.sim.control import Measurement
from twin.sim.scenario import Scenario


def groups(keys: Sequence) -> dict:
    """Indices of equal keys, in first-seen order: {key: array of indices}."""
    found: dict = {}
    for i, key in enumerate(keys):
        found.setdefault(key, []).append(i)
    return {key: np.array(idx) for key, idx in found.items()}


def true_start(scenarios: Sequence[Scenario], reported: np.ndarray) -> np.ndarray:
    """Where each rack truly starts (m) so that its Hall sensor reads ``reported`` (m): the
    experiments started from where the reading said (as-built Hall calibration error)."""
    start = np.array(reported, dtype=float)
    for i, s in enumerate(scenarios):
        params = s.preset.params
        if params.hall.calibration_error:
            start[i] = HallReading(params.hall, params.gears.spur_radius).true_position(start[i])
    return start


def compile_kernels() -> None:
    """Compile, or load from numba's cache, the per-tick kernels (valves, rack step, compressible
    chambers): about 0.3 s the first time in a process (mostly numba starting up). A sweep calls it
    before forking its workers, so that each inherits them instead of paying again."""
    from twin.physics.params import ChamberParams
    from twin.physics.valves import ValveModel

    nothing, shut, free = np.zeros(0), np.zeros((0, 4)), np.zeros(0, dtype=bool)
    for model in ValveModel:
        ValveBank(params=NOMINAL_PARAMS.valves, model=model, n=0, tick=1e-3).update(0, nothing)
    hydraulics.rack_step(circuit_now=hydraulics.circuit(shut, nothing, 1.0), friction_params=NOMINAL_PARAMS.friction,
                         bore_area=1.0, y=nothing, v0=nothing, external_force=nothing, stuck=free, mass=nothing,
                         h=1e-3)
    CompressibleCircuit(chambers=ChamberParams(compressible=True), line=NOMINAL_PARAMS.supply_line,
                        friction_params=NOMINAL_PARAMS.friction, bore_area=1.0, stroke=(0.0, 1.0), supply=nothing,
                        initial_pressure=nothing).tick(conductance=shut, y=nothing, v0=nothing,
                                                       external_force=nothing, stuck=free, mass=nothing, h=1e-3,
                                                       breakaway=np.zeros_like)


def place_on_manifold(qpos: np.ndarray, joint: JointModel, y: np.ndarray) -> None:
    """Write rack position(s) ``y`` (m) into ``qpos`` rows (n, nq) with the gears coupled."""
    dofs = [joint.rack_a_dof, joint.rack_b_dof, joint.pinion_dof, joint.spur_dof]
    qpos[:, dofs] = np.asarray(y)[:, None] * joint.manifold[dofs][None, :]


class PlantState:
    """Noise, sensors, observer, valves and hydraulics for ``scenarios``.

    ``lengths[i]`` is scenario i's number of ticks; its noise at tick k depends
    only on its seed and k, not on its batch or its length;
    ``initial_position`` (n,) is where each rack starts at rest (m). With ``idle_after_end`` a
    scenario's solenoid valves and chambers are no longer advanced from tick ``lengths[i]`` on (a batch
    whose runs end at their lengths: nobody reads them after that, and every scenario's numbers are its
    own, so the others' are unchanged); without it they run for as long as the loop ticks.
    """

    def __init__(self, *, scenarios: Sequence[Scenario], joints: Sequence[JointModel], lengths: Sequence[int],
                 initial_position: np.ndarray, tick: float, idle_after_end: bool = False):
        n = len(scenarios)
        self.n, self.tick = n, tick
        self._ends = np.asarray(lengths, dtype=np.int64) if idle_after_end else None
        self.plants: list[Plant] = [s.preset for s in scenarios]
        self.supply = np.array([s.supply for s in scenarios])  # Pa
        self.mass = np.array([j.effective_mass for j in joints])  # kg
        self.manifold = np.stack([j.manifold for j in joints])  # (n, nv)
        ticks = int(max(lengths))
        self.position_noise = np.zeros((n, ticks))
        self.pressure_noise = np.zeros((n, ticks, 3))  # chamber A, chamber B, supply
        for i, (s, p, length) in enumerate(zip(scenarios, self.plants, lengths, strict=True)):
            if s.noise:
                rng = np.random.default_rng(s.seed)
                # Pressure noise has its own stream (spawned, not drawn after the positions), so a loop that
                # runs longer (the environment's episodes) sees the same noise at every tick as ``twin run``.
                (pressure_rng,) = rng.spawn(1)
                self.position_noise[i, :length] = uniform_noise(rng, p.params.sensors.position_noise, (length,))
                self.pressure_noise[i, :length] = uniform_noise(pressure_rng, p.params.sensors.pressure_noise,
                                                                (length, 3))
        model = joints[0].model
        stroke = tuple(float(x) for x in model.jnt_range[model.dof_jntid[joints[0].rack_a_dof]])
        start = np.asarray(initial_position, dtype=float)
        self._plant_groups = [_PlantGroup(preset, idx, tick=tick, stroke=stroke, supply=self.supply[idx],
                                          scenarios=[scenarios[i] for i in idx])
                              for preset, idx in groups(self.plants).items()]
        self.conductance = np.zeros((n, 4))  # m^3/(Pa s), V1..V4
        self.stuck = np.ones(n, dtype=bool)
        self.pressure_a = np.zeros(n)  # Pa
        self.pressure_b = np.zeros(n)  # Pa
        self.supply_now = self.supply.copy()  # Pa, at the valve block (varies with an as-built supply line)
        for group in self._plant_groups:
            if group.chambers is not None:
                self.pressure_a[group.idx] = group.chambers.state.pressure_a
                self.pressure_b[group.idx] = group.chambers.state.pressure_b
        self._halls = [(g.idx, g.hall) for g in self._plant_groups if g.hall is not None]
        first_reading = self._hall(start) + self.position_noise[:, 0]
        self.observer = FirstOrderObserver(gain=np.array([p.params.observer.gain for p in self.plants]),
                                           sample_period=tick, initial=first_reading)
        self._kalman = _kalman_observers(self.plants, tick=tick, initial=first_reading)

    def _hall(self, y: np.ndarray) -> np.ndarray:
        """The rack position the Hall sensor reports for the true ``y``, before noise."""
        if not self._halls:
            return y
        read = y.copy()
        for idx, hall in self._halls:
            read[idx] = hall(y[idx])
        return read

    def sense(self, k: int, y: np.ndarray) -> Measurement:
        """Sample the sensors at tick k from the true rack position ``y`` (n,)."""
        measured = self._hall(y) + self.position_noise[:, k]
        velocity, acceleration = self.observer.update(measured)
        if self._kalman:
            pressure_a, pressure_b = self.measured_pressures(k)
            velocity, acceleration = velocity.copy(), acceleration.copy()  # the first-order observer keeps its own
            for idx, observer in self._kalman:
                velocity[idx], acceleration[idx] = observer.update(measured[idx], pressure_a[idx], pressure_b[idx])
        return Measurement(position=measured, velocity=velocity, acceleration=acceleration,
                           supply_pressure=self.supply_now + self.pressure_noise[:, k, 2])

    def measured_pressures(self, k: int) -> tuple[np.ndarray, np.ndarray]:
        """Chamber pressures A and B as the pressure sensors read them (Pa)."""
        return self.pressure_a + self.pressure_noise[:, k, 0], self.pressure_b + self.pressure_noise[:, k, 1]

    def external_force(self, qfrc_passive: np.ndarray, qfrc_bias: np.ndarray) -> np.ndarray:
        """Everything MuJoCo applies along +y besides the pistons (gravity), (n,) in N."""
        return np.einsum("ij,ij->i", qfrc_passive - qfrc_bias, self.manifold)

    def actuate(self, k: int, duty: np.ndarray, y: np.ndarray, v: np.ndarray,
                external: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Piston forces (cylinder A, cylinder B) in N for the duty command (n,) in %."""
        force_a, force_b = np.zeros(self.n), np.zeros(self.n)
        live = None if self._ends is None else k < self._ends
        for group in self._plant_groups:
            idx, params = group.selector, group.preset.params
            group_live = None if live is None else live[idx]
            self.conductance[idx] = group.valves.update(k, duty[idx], group_live)
            area = params.cylinder.bore_area
            if group.chambers is None:
                forces = hydraulics.rack_step(
                    circuit_now=hydraulics.circuit(self.conductance[idx], self.supply[idx], area),
                    friction_params=params.friction, bore_area=area, y=y[idx], v0=v[idx],
                    external_force=external[idx], stuck=self.stuck[idx], mass=self.mass[idx], h=self.tick,
                    breakaway=group.breakaway(y[idx]))
                self.pressure_a[idx], self.pressure_b[idx] = forces.pressure_a, forces.pressure_b
            else:
                forces = group.chambers.tick(
                    conductance=self.conductance[idx], y=y[idx], v0=v[idx], external_force=external[idx],
                    stuck=self.stuck[idx], mass=self.mass[idx], h=self.tick, breakaway=group.breakaway,
                    live=group_live)
                state = group.chambers.state
                self.pressure_a[idx], self.pressure_b[idx] = state.pressure_a, state.pressure_b
                self.supply_now[idx] = state.supply_pressure
            force_a[idx], force_b[idx] = forces.cylinder_a, forces.cylinder_b
            self.stuck[idx] = forces.stuck
        return force_a, force_b


def _kalman_observers(plants: Sequence[Plant], *, tick: float, initial: np.ndarray) -> list:
    """(indices, KalmanObserver) for the scenarios whose plant observes with the Kalman filter, one per
    observer setting. It runs on the thesis's numbers (bore, viscous friction), not on the plant's own,
    so that its model errors are real; its mass is the train referred to the rack without payload
    (:func:`twin.physics.model.referred_mass`, 43.5 g), not the thesis's lumped 32.9 g, which a new
    observer design need not inherit (with it, the acceleration error was 1.3-1.5x worse)."""
    chosen = [(i, p.params) for i, p in enumerate(plants) if p.params.observer.kind == "kalman"]
    found = groups([(params.observer, params.sensors) for _, params in chosen])
    observers = []
    for (observer, sensors), members in found.items():
        idx = np.array([chosen[m][0] for m in members])
        observers.append((idx, KalmanObserver(
            mass=referred_mass(NOMINAL_PARAMS), area=NOMINAL_PARAMS.cylinder.bore_area,
            viscous=NOMINAL_PARAMS.friction.viscous, disturbance_density=observer.disturbance_density,
            position_noise=sensors.position_noise, pressure_noise=sensors.pressure_noise,
            sample_period=tick, initial=initial[idx])))
    return observers


class _PlantGroup:
    """The scenarios ``idx`` that share one plant: its valves and, as-built, its chambers,
    static-friction map and Hall reading (None where the plant does not have the effect)."""

    def __init__(self, preset: Plant, idx: np.ndarray, *, tick: float, stroke: tuple[float, float],
                 supply: np.ndarray, scenarios: Sequence[Scenario]):
        params = preset.params
        self.preset, self.idx = preset, idx
        self.selector = selector(idx)  # idx, for indexing every tick
        self.valves = ValveBank(params=params.valves, model=preset.valve_model, n=len(idx), tick=tick)
        map_seeds = [params.stiction_map.seed if params.stiction_map.seed is not None else (s.seed, 1)
                     for s in scenarios]  # (seed, 1): the map's stream, apart from the noise's
        self.stiction = (StictionMaps(params.stiction_map, params.friction.stiction, stroke, map_seeds)
                         if params.stiction_map.scatter > 0 else None)
        self.hall = (HallReading(params.hall, params.gears.spur_radius)
                     if params.hall.calibration_error else None)
        self.chambers = None
        if params.chambers.compressible:
            self.chambers = CompressibleCircuit(
                chambers=params.chambers, line=params.supply_line, friction_params=params.friction,
                bore_area=params.cylinder.bore_area, stroke=stroke, supply=supply,
                initial_pressure=params.chambers.initial_pressure_fraction * supply)

    def breakaway(self, y: np.ndarray) -> np.ndarray:
        """Static friction (N) at rack positions ``y``."""
        return self.stiction(y) if self.stiction is not None else np.full_like(y, self.preset.params.friction.stiction)
