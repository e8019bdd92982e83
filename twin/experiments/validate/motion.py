"""How the as-built controllers move the joint: sliding mode's switching term, the closed-form lag at which a
law opens its valve on a ramp, the pulse cycle of the slow trajectories, and where in T1 a payload costs."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from twin.experiments import calibrate
from twin.experiments.validate.common import SEEDS
from twin.sim.metrics import spread


class _SwitchingWatch:
    """Sliding mode as the thesis runs it, keeping the switching term it adds each 1 ms (% of duty)."""

    def __init__(self, inner) -> None:
        self.inner, self.period, self.added = inner, inner.period, []

    def reset(self, n: int) -> None:
        self.inner.reset(n)
        self.added = []

    def update(self, t, measurement, setpoint) -> np.ndarray:
        self.added.append(self.inner.switching(measurement, setpoint))
        return self.inner.update(t, measurement, setpoint)


def sliding_mode_parts(committed: dict[str, float]) -> dict:
    """Where the as-built sliding mode's tracking comes from, on Chapter 5's trajectories (seeds 0-4, horizontal,
    no payload): its mean RMSE as run and without its switching term (deg), the switching term's RMS over the
    run (% of duty), per trajectory; and the valve's emergent dead zone (%)."""
    import controllers
    from twin.envs.runner import nominal_model
    from twin.experiments.studies.valve import emergent_dead_zone
    from twin.plants.as_built import as_built_plant
    from twin.sim.scenario import Scenario
    from twin.sim.simulation import simulate

    plant = as_built_plant(committed)
    thesis = controllers.make_controller("smc", nominal=nominal_model(plant), gain_set=plant.gain_set,
                                         tick=plant.timestep)
    watch = _SwitchingWatch(thesis)  # simulate resets both for each batch
    bare = dataclasses.replace(thesis, gains=dataclasses.replace(thesis.gains, switching_amplitude=0.0))
    out: dict = {"dead_zone_pct": emergent_dead_zone(), "trajectories": {}}
    for t in sorted(key[1] for key in calibrate.EXPERIMENT_CELLS if key[0] == "smc"):
        scenarios = [Scenario("smc", t, plant=plant, seed=s) for s in SEEDS] * 2
        results = simulate(scenarios, controllers=[watch] * len(SEEDS) + [bare] * len(SEEDS))
        rmse = [math.degrees(r.metrics.rmse) for r in results]
        out["trajectories"][t] = {"as_run_deg": spread(rmse[:len(SEEDS)]).mean,
                                  "without_switching_deg": spread(rmse[len(SEEDS):]).mean,
                                  "switching_rms_pct": float(np.sqrt(np.mean(np.square(watch.added))))}
    return out


SLOW_TRAJECTORIES = (2, 3)  # the ramp (10 mm/s) and the sine (up to 16 mm/s): slow, continuous motion


def opening_ticks(params, period_ticks: int, tick: float) -> int:
    """The fewest whole ticks of coil, from a valve shut and at rest, after which the solenoid valve (its
    ``SolenoidParams``) lifts at all within the period: the shortest pulse that passes water."""
    from twin.physics import solenoid

    per_tick = int(round(tick / params.step))
    for n in range(1, period_ticks + 1):
        coil = np.zeros(period_ticks * per_tick)
        coil[:n * per_tick] = 1.0
        states, _ = solenoid.simulate(params, coil, h=params.step)
        if states[:, 1].max() > 0.0:
            return n
    raise ValueError("the valve does not open even on a full period")


def opening_command(ticks_to_open: int, period_ticks: int) -> float:
    """The held duty (%) above which a pulse reaches ``ticks_to_open`` of the period's ``period_ticks`` ticks
    (the coil switches on whole ticks: a duty d is rint(d S / 100) ticks; at the limit itself, half to even)."""
    return (ticks_to_open - 0.5) / period_ticks * 100.0


class NoClosedForm(ValueError):
    """:func:`opening_lag` has no closed form for this law: its switching term saturates before the valve opens."""


def opening_lag(controller, nominal, position, speed: float, *, ticks_to_open: int, period_ticks: int,
                tick: float):
    """Closed form: the error (m, >= 0) at a period's start at which ``controller`` (built by
    ``controllers.make_controller``) first commands a pulse that opens the valve, with the reference at
    ``position`` (m, a float or an array) moving at ``speed`` > 0 (a_d = 0) and the joint at rest behind it
    (v_hat = a_hat = 0). The coil is on at the period's tick k while rint(u_k S / 100) > k (S =
    ``period_ticks``), so a pulse reaches the ``ticks_to_open`` = n ticks that open the valve
    (:func:`opening_ticks`) once u_{n-1} passes :func:`opening_command` (the lag is that limit). With u_FF the
    feed-forward at ``position`` and v = ``speed``:

    - PVA + DZC (held for the period): past its threshold its compensation adds 30 %, which opens the valve if
      K_p e + K_v v + 30 % does; before it, K_p e + K_v v must open it on its own: the smaller error;
    - FF + PVA (held): its compensation lifts its band (20-30 %) to the band's top, which opens the valve if that
      is a pulse of n ticks: e = (20 % - u_FF - K_v v) / K_p;
    - sliding mode: u_FF+PVA held from the period's start, the switching term every tick, while the error grows
      by v per second: u_{n-1} = u_FF + K_p e + K_v v + 100 % (v + lambda (e + (n - 1) tick v)) / phi, unsaturated.

    Returns a float for a float ``position``, else an array of its shape.
    """
    from controllers import PVA, FeedForwardPVA, SlidingMode
    from controllers.feedforward import feedforward_duty

    if not speed > 0:
        raise ValueError(f"the reference must move forwards, got {speed} m/s")
    opening = opening_command(ticks_to_open, period_ticks)

    def opens(duty: float) -> bool:
        return np.rint(duty / 100.0 * period_ticks) >= ticks_to_open

    where = np.asarray(position, dtype=float)
    u_ff = feedforward_duty(nominal, where, np.full(where.shape, speed), np.zeros(where.shape))
    if isinstance(controller, PVA):
        g = controller.gains
        alone = max(opening - g.velocity * speed, 0.0) / g.position
        threshold = controller.compensation_threshold
        lifted = g.position * threshold + g.velocity * speed + controller.compensation
        lag = np.full(where.shape, min(threshold, alone) if opens(lifted) else alone)
    elif isinstance(controller, FeedForwardPVA):
        g = controller.gains.pva
        low, high = controller.gains.compensation_band
        edge = min(low, opening) if opens(high) else opening
        lag = np.maximum(edge - u_ff - g.velocity * speed, 0.0) / g.position
    elif isinstance(controller, SlidingMode):
        g = controller.gains
        per_speed = g.switching_amplitude / g.boundary_layer  # %/(m/s)
        grown = (ticks_to_open - 1) * tick * speed  # m the error grows before the binding tick
        lag = (np.maximum(opening - u_ff - g.pva.velocity * speed - per_speed * (speed + g.surface_slope * grown), 0.0)
               / (g.pva.position + per_speed * g.surface_slope))
        if np.any(speed + g.surface_slope * (lag + grown) >= g.boundary_layer):
            raise NoClosedForm("the switching term saturates before the valve opens: no closed form here")
    else:
        raise TypeError(f"no closed form for {type(controller).__name__}")
    return lag if lag.ndim else float(lag)


def ramp_opening_lags(plant, nominal, laws: dict) -> dict:
    """Per law in ``laws`` (name -> controller), the closed-form :func:`opening_lag` on T2 (deg, the median over
    the ramp's reference) on ``plant``'s solenoid valve, NaN for a law it has no closed form for (a sliding mode
    whose switching term saturates before the valve opens: a small phi); also ``"opening_pct"``, the held command
    whose pulse opens that valve, and ``"feedforward_pct"``, the ramp's feed-forward duty (lowest, highest)."""
    from controllers.feedforward import feedforward_duty
    from twin.physics.ticks import whole_ticks
    from twin.physics.trajectories import RAMP_SPEED, trajectory

    radius = plant.params.gears.spur_radius
    period_ticks = whole_ticks(plant.params.valves.pwm_period, plant.timestep, what="PWM period")
    n_open = opening_ticks(plant.params.valves.solenoid, period_ticks, plant.timestep)
    ramp = trajectory(2, spur_radius=radius)
    positions = ramp.sample(np.arange(0.0, ramp.duration, plant.timestep), radius).position
    u_ff = feedforward_duty(nominal, positions, np.full(positions.shape, RAMP_SPEED), np.zeros(positions.shape))
    def lag(law) -> float:
        try:
            return math.degrees(float(np.median(opening_lag(law, nominal, positions, RAMP_SPEED, ticks_to_open=n_open,
                                                            period_ticks=period_ticks, tick=plant.timestep))) / radius)
        except NoClosedForm:
            return math.nan

    lags = {name: lag(law) for name, law in laws.items()}
    return {"lag_deg": lags, "opening_pct": opening_command(n_open, period_ticks),
            "feedforward_pct": (float(u_ff.min()), float(u_ff.max()))}


def discharge_open(valve_open: np.ndarray) -> np.ndarray:
    """(T,) bool: either discharge valve open (V2 or V4), from a trace's ``valve_open`` (T, 4), V1..V4."""
    return valve_open[:, 1] | valve_open[:, 3]


def opening_starts(opened: np.ndarray) -> np.ndarray:
    """Indices at which ``opened`` (T,) bool turns true: where a discharge valve opens (:func:`discharge_open`)."""
    return np.flatnonzero(np.diff(np.concatenate(([False], opened)).astype(int)) == 1)


def pulse_statistics(time: np.ndarray, desired: np.ndarray, scored: np.ndarray, opened: np.ndarray) -> dict:
    """One run's pulses: ``opened`` (T,) bool, either discharge valve open (:func:`discharge_open`); angles in rad.
    Returns the openings per second, and per opening the advance of the scored angle until the next opening (or
    the run's end) and the error |desired - scored| when the valve opened, each as a list in deg."""
    starts = opening_starts(opened)
    ends = np.append(starts[1:], len(time) - 1)
    return {"openings_per_s": len(starts) / (time[-1] - time[0] + (time[1] - time[0])),
            "advance_deg": [math.degrees(abs(scored[b] - scored[a])) for a, b in zip(starts, ends, strict=True)],
            "error_at_opening_deg": [math.degrees(abs(desired[a] - scored[a])) for a in starts]}


def pulse_cycle(committed: dict[str, float]) -> dict:
    """How the as-built controllers move the joint on the slow trajectories (Chapter 5, horizontal, no payload,
    seeds 0-4): per controller and trajectory the runs' mean RMSE, their openings per second and the medians
    of :func:`pulse_statistics` (and T2's first run, for :func:`figure_pulses`); per controller the closed-form
    :func:`opening_lag` on T2 (deg, the median over T2's reference); T2's feed-forward duty (%, lowest and highest), the command that opens the valve
    (%), how far T2's reference moves in a PWM period (deg), the valve's opening delay (ms) and sliding mode's
    phi (m/s)."""
    import controllers
    from twin.envs.runner import nominal_model, run_many
    from twin.physics.trajectories import RAMP_SPEED
    from twin.plants.as_built import as_built_plant
    from twin.sim.scenario import Scenario

    plant = as_built_plant(committed)
    nominal = nominal_model(plant)
    radius = plant.params.gears.spur_radius
    valves = plant.params.valves
    names = [name for name in ("pva", "ffpva", "smc")
             if all((name, t, 0.0, "horizontal") in calibrate.EXPERIMENT_CELLS for t in SLOW_TRAJECTORIES)]
    laws = {name: controllers.make_controller(name, nominal=nominal, gain_set=plant.gain_set, tick=plant.timestep)
            for name in names}
    out: dict = {**ramp_opening_lags(plant, nominal, laws),
                 "period_advance_deg": math.degrees(RAMP_SPEED * valves.pwm_period / radius),
                 "opening_delay_ms": valves.opening_delay * 1e3, "runs": {}}
    if "smc" in laws:
        out["phi"] = laws["smc"].gains.boundary_layer
    keys = [(name, t) for name in names for t in SLOW_TRAJECTORIES]
    scenarios = [Scenario(name, t, plant=plant, seed=s) for name, t in keys for s in SEEDS]
    results = run_many(scenarios)
    out["example"] = {}  # controller -> T2's first run: time (s), error (deg), discharge open (bool), (T,) each
    for k, key in enumerate(keys):
        runs = results[k * len(SEEDS):(k + 1) * len(SEEDS)]
        scored = [r.scored_angle for r in runs]
        opened = [discharge_open(r.trace.valve_open) for r in runs]
        stats = [pulse_statistics(r.trace.time, r.trace.desired_angle, y, o)
                 for r, y, o in zip(runs, scored, opened, strict=True)]
        if key[1] == 2:
            out["example"][key[0]] = (runs[0].trace.time, np.degrees(runs[0].trace.desired_angle - scored[0]),
                                      opened[0])
        rmse = spread([math.degrees(r.metrics.rmse) for r in runs])
        out["runs"][key] = {
            "rmse_deg": rmse.mean,
            "rmse_std_deg": rmse.std,
            "openings_per_s": float(np.mean([s["openings_per_s"] for s in stats])),
            "advance_deg": float(np.median(np.concatenate([s["advance_deg"] for s in stats]))),
            "error_at_opening_deg": float(np.median(np.concatenate([s["error_at_opening_deg"] for s in stats])))}
    return out


def _rms(x: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.square(x)))) if x.size else math.nan


def payload_phases(committed: dict[str, float]) -> list[dict]:
    """Where in T1 a payload's cost falls on the committed preset: per Chapter 6 T1 cell (its 0 g horizontal
    cell included; seeds 0-4) the mean RMSE and the RMS error (deg, mean over the runs) over T1's move (its
    first segment, the 120 deg rise) and over its hold (the rest). Added 2026-11-26 after seeing that the
    twin's payload costs split by controller the other way round from the rig's (:func:`payload_effects`)."""
    from twin.envs.runner import run_many
    from twin.physics.model import Orientation
    from twin.physics.trajectories import trajectory
    from twin.plants.as_built import as_built_plant
    from twin.sim.scenario import Scenario

    plant = as_built_plant(committed)
    move_end = trajectory(1, spur_radius=plant.params.gears.spur_radius).segments[0].duration  # s
    controllers = {key[0] for key in calibrate.CELLS if key[1] == 1 and (key[2] > 0 or key[3] != "horizontal")}
    keys = sorted((key for key in calibrate.CELLS if key[1] == 1 and key[0] in controllers),  # each law's 0 g flat first
                  key=lambda key: (key[0], key[3] != "horizontal", key[2]))
    results = run_many([Scenario(c, t, payload=g * 1e-3, orientation=Orientation(o), plant=plant, seed=s)
                        for c, t, g, o in keys for s in SEEDS])
    rows = []
    for k, (controller, _, payload_g, orientation) in enumerate(keys):
        runs = results[k * len(SEEDS):(k + 1) * len(SEEDS)]
        errors = [(r.trace.time, np.degrees(r.scored_angle - r.trace.desired_angle)) for r in runs]
        rows.append({"controller": controller, "payload_g": payload_g, "orientation": orientation,
                     "rmse_deg": float(np.mean([math.degrees(r.metrics.rmse) for r in runs])),
                     "move_deg": float(np.mean([_rms(e[t < move_end]) for t, e in errors])),
                     "hold_deg": float(np.mean([_rms(e[t >= move_end]) for t, e in errors])),
                     "move_end_s": move_end, "failed_runs": sum(len(r.warnings) > 0 for r in runs)})
    return rows
