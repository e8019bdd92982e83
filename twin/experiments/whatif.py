"""``twin whatif``: gravity, payload, supply and PWM questions, each answered with
a table (CSV), a plot and a one-paragraph answer.

payload    RMSE, SSE and max error against tip payload, both orientations, both
           model-based controllers, up to where the joint can no longer follow
           (max |error| above FOLLOW_LIMIT_DEG in any seed).
lift       the heaviest tip payload the joint lifts vertically through 80-100 deg,
           against supply pressure: torque balance with the friction model, then
           confirmed by bisection in simulation (valves fully open).
pwm        tracking against the valves' PWM period alone (SPEC §10), on the
           time-resolved valve (``thesis-pwm``); the controllers keep the
           thesis's update rates, so only the valves change.
gear-load  gear tooth forces, from the couplings' constraint forces, against
           the Lewis safe loads at the pitch-line speed of the moment, over
           several averaging windows (single 1 ms ticks are impacts).
supply     tracking on the as-built plant with its air-over-water supply line,
           with a gas accumulator at the valve block instead (SPEC §10, future
           work 1), and with an ideal constant supply: how much the sagging,
           ringing supply costs, and how much an accumulator buys back.
"""

from __future__ import annotations

import dataclasses
import pathlib
from collections.abc import Sequence

import numpy as np

from twin.batch.grid import expand
from twin.batch.sweep import run_sweep
from twin.batch.tables import summarise
from twin.exceptions import InvalidScenario
from twin.physics import friction
from twin.physics.gears import lewis_safe_load
from twin.physics.model import Orientation
from twin.physics.params import JointParams
from twin.physics.ticks import whole_ticks
from twin.physics.valves import ValveModel
from twin.plants import Plant, plant
from twin.sim import report
from twin.sim.scenario import Scenario

FOLLOW_LIMIT_DEG = 10.0  # max |error| beyond which the joint "no longer follows"
LIFT_SPAN_DEG = (80.0, 100.0)  # the lift must pass the horizontal link position
THESIS_SUPPLY = 300e3  # Pa, the supply the lift answer quotes
THESIS_PAYLOAD = 13.5e-3  # kg
PWM_CONTROLLERS = ("ffpva", "smc")
AVERAGING_WINDOWS = (1e-3, 2e-3, 5e-3, 10e-3, 20e-3)  # s, moving averages of the tooth forces
SUSTAINED_WINDOW = 10e-3  # s: averaging window separating sustained loads from one-step impacts
DEFAULT_PLANTS = {"payload": "thesis", "lift": "thesis", "pwm": "thesis-pwm", "gear-load": "thesis",
                  "supply": "as-built"}
SUPPLY_MODELS = ("line", "accumulator", "constant")  # SupplyLineParams.model, the plant's own first


@dataclasses.dataclass(frozen=True)
class Study:
    name: str
    rows: list[dict]
    answer: str


# --- payload --------------------------------------------------------------------------------------------------

def payload_study(*, out: pathlib.Path, payloads_g: Sequence[float], trajectory: int = 1, seeds: int = 3,
                  plant_name: str = "thesis", workers: int | None = None, progress=None) -> Study:
    points = expand({"controller": ["ffpva", "smc"], "trajectory": [trajectory], "payload": list(payloads_g),
                     "orientation": ["horizontal", "vertical"], "plant": [plant_name], "seed": list(range(seeds))})
    records = run_sweep(points, out=out, workers=workers, progress=progress).records
    rows = summarise(records)
    lines = []
    for controller in ("ffpva", "smc"):
        for orientation in ("horizontal", "vertical"):
            group = sorted((r for r in rows if r["controller"] == controller and r["orientation"] == orientation),
                           key=lambda r: r["payload_g"])
            following = [r for r in group if r["failed"] == 0 and r["max_error_deg"] <= FOLLOW_LIMIT_DEG]
            last_ok = max((r["payload_g"] for r in following), default=None)
            first_bad = next((r["payload_g"] for r in group
                              if r["failed"] or r["max_error_deg"] > FOLLOW_LIMIT_DEG), None)
            reach = (f"follows T{trajectory} up to {last_ok:g} g" if last_ok is not None else "never follows")
            reach += f", not at {first_bad:g} g" if first_bad is not None else " (the whole range)"
            rmse = ", ".join(f"{r['payload_g']:g} g: {r['rmse_mean_deg']:.2f}" for r in group[:: max(1, len(group) // 4)])
            lines.append(f"{controller} {orientation}: {reach}; RMSE (deg) {rmse}")
    return Study("payload", rows, "\n".join(lines))


# --- lift -----------------------------------------------------------------------------------------------------

def lift_limit_closed_form(params: JointParams, supply_pressure: float) -> float:
    """Heaviest tip payload (kg) whose gravity torque the full supply force, less friction, still
    beats everywhere in LIFT_SPAN_DEG (valves fully open, at vanishing speed); negative if not even
    the bare link rises:

        (P A - F_f(y)) r_s = (m L + m_link L / 2) g sin(theta),  y = theta r_s,
        F_f = max(F_c(y), stiction)   (the rack starts each lift from rest)
    """
    r_s, length = params.gears.spur_radius, params.masses.link_length
    theta = np.radians(np.linspace(*LIFT_SPAN_DEG, 401))
    y = theta * r_s
    resisting = np.maximum(friction.coulomb_force(params.friction, y, np.ones_like(y)), params.friction.stiction)
    torque = (supply_pressure * params.cylinder.bore_area - resisting) * r_s
    mass = torque / (params.gravity * length * np.sin(theta)) - params.masses.link_mass / 2
    return float(np.min(mass))


def _lifts(payloads: np.ndarray, pressures: np.ndarray, plant_name: str) -> np.ndarray:
    """Simulate each (payload, pressure) from 80 deg (T3's start) with the valves fully open;
    True where the link passes the end of LIFT_SPAN_DEG within the run."""
    from controllers.open_loop import OpenLoop
    from twin.sim.simulation import simulate

    scenarios = [Scenario("ffpva", 3, payload=float(m), orientation=Orientation.VERTICAL, plant=plant_name,
                          noise=False, supply_pressure=float(p)) for m, p in zip(payloads, pressures, strict=True)]
    opener = OpenLoop(schedule=lambda t: 100.0, tick=plant(plant_name).timestep)
    results = simulate(scenarios, controllers=[opener] * len(scenarios))
    return np.array([np.degrees(r.trace.angle).max() >= LIFT_SPAN_DEG[1] for r in results])


def _lift_at(pressure: float, pressures: np.ndarray, lifted_g: np.ndarray) -> str:
    """What the answer can say about the lift at ``pressure`` (Pa), given the sorted studied
    ``pressures`` (Pa) and their lifts (g): the studied value, a linear interpolation inside the
    studied range, or plainly that it was not studied."""
    at = f"{pressure / 1e3:g} kPa"
    exact = np.isclose(pressures, pressure, rtol=1e-9, atol=0.0)
    if np.any(exact):
        return f"{float(lifted_g[exact][0]):.1f} g can be lifted at the tip at {at}"
    if pressures[0] < pressure < pressures[-1]:
        above = int(np.searchsorted(pressures, pressure))
        return (f"about {float(np.interp(pressure, pressures, lifted_g)):.1f} g can be lifted at the tip at {at} "
                f"(interpolated between {pressures[above - 1] / 1e3:g} and {pressures[above] / 1e3:g} kPa)")
    studied = "-".join(f"{p / 1e3:g}" for p in dict.fromkeys((pressures[0], pressures[-1])))
    return f"{at} was not studied (pressures {studied} kPa)"


def lift_study(*, pressures_kpa: Sequence[float], plant_name: str = "thesis", tolerance: float = 0.005) -> Study:
    params = plant(plant_name).params
    pressures = np.unique(np.array(pressures_kpa, dtype=float)) * 1e3  # sorted, so rows and answer run upwards
    closed = np.array([lift_limit_closed_form(params, p) for p in pressures])
    bare_link_lifts = _lifts(np.zeros_like(pressures), pressures, plant_name)
    can = bare_link_lifts & (closed > 0)
    low, high = np.zeros_like(closed), np.where(can, 1.5 * closed + 1e-3, 0.0)
    while np.any(can & (high - low > tolerance * np.abs(closed))):  # bisection, all pressures in one batch
        middle = (low + high) / 2
        lifted = _lifts(middle[can], pressures[can], plant_name)
        low[can], high[can] = np.where(lifted, middle[can], low[can]), np.where(lifted, high[can], middle[can])
    simulated = np.where(bare_link_lifts, (low + high) / 2, np.nan)
    rows = [{"supply_kpa": p / 1e3, "lift_closed_form_g": max(c, 0.0) * 1e3,
             "lift_simulated_g": s * 1e3 if np.isfinite(s) else 0.0,
             "difference_pct": 100 * (s - c) / c if c > 0 and np.isfinite(s) else float("nan")}
            for p, c, s in zip(pressures, closed, simulated, strict=True)]
    lifted_g = np.array([r["lift_simulated_g"] for r in rows])
    needed = pressures[lifted_g >= THESIS_PAYLOAD * 1e3]
    differences = [abs(r["difference_pct"]) for r in rows if np.isfinite(r["difference_pct"])]
    answer = (f"Vertical, valves fully open, through {LIFT_SPAN_DEG[0]:g}-{LIFT_SPAN_DEG[1]:g} deg: "
              f"{_lift_at(THESIS_SUPPLY, pressures, lifted_g)}; "
              + (f"13.5 g needs {needed.min() / 1e3:g} kPa or more of those tried. " if needed.size
                 else "13.5 g cannot be lifted at any pressure tried. ")
              + (f"Simulation and torque balance agree within {max(differences):.1f} %. " if differences else "")
              + "Holding needs no pressure in this plant: sealed chambers lock the joint.")
    return Study("lift", rows, answer)


# --- pwm ------------------------------------------------------------------------------------------------------

def _pwm_setup(base: Plant) -> str:
    """The answer's statement of what the PWM study varies and what it holds, for the plant ``base``."""
    valves = base.params.valves
    held = f"{valves.pwm_period * 1e3:g} ms"  # the controllers' rate: the base plant's period
    if base.valve_model is ValveModel.PWM:
        effect = (f"each discharge valve is open for the first |u| x period of every period, behind its "
                  f"{valves.opening_delay * 1e3:g}/{valves.closing_delay * 1e3:g} ms opening/closing delays")
    else:
        effect = ("the averaged valve ignores the period except for the duty resolution "
                  "(100 % / period in ticks); use --plant thesis-pwm for switching valves")
    dead_zone = (f" The {valves.dead_zone_duty:g} % dead zone stays a fraction of the period, as SPEC §3 gives "
                 "it at 16 ms." if valves.dead_zone_duty > 0 else "")
    return (f"Only the valves' PWM period varies ({base.name} plant: {effect}). The controllers keep the "
            f"thesis's update rates whatever the period: FF + PVA every {held}; sliding mode's switching term "
            f"every 1 ms, its FF + PVA part every {held}. The controller's rate is a separate question (SPEC §10: "
            f"PVA inside the PWM period) and is not mixed in here.{dead_zone}")


def pwm_study(*, periods_ms: Sequence[float], trajectories: Sequence[int] = (1, 3), seeds: int = 3,
              plant_name: str = DEFAULT_PLANTS["pwm"], progress=None) -> Study:
    """RMSE against the valves' PWM period, with the controllers' periods fixed at the base plant's
    (16 ms): one batch, controllers shared across scenarios, built from the base plant rather than from
    each scenario (``twin.envs.runner`` would make the controllers follow the valves' period)."""
    from controllers import make_controller
    from twin.envs.runner import nominal_model
    from twin.sim.simulation import simulate

    base = plant(plant_name)
    cases = [(Scenario(c, t, plant=plant_name, seed=s, pwm_period=ms / 1e3), ms)
             for c in PWM_CONTROLLERS for t in trajectories for s in range(seeds) for ms in periods_ms]
    controllers = {c: make_controller(c, nominal=nominal_model(base), gain_set=base.gain_set, tick=base.timestep)
                   for c in PWM_CONTROLLERS}
    results = simulate([s for s, _ in cases], controllers=[controllers[s.controller] for s, _ in cases],
                       progress=progress)
    records = [{**report.summary(r), "pwm_period_ms": ms, "status": "failed" if r.warnings else "ok"}
               for r, (_, ms) in zip(results, cases, strict=True)]
    rows = summarise(records)
    lines = [_pwm_setup(base)]
    for controller in PWM_CONTROLLERS:
        for t in trajectories:
            group = sorted((r for r in rows if r["controller"] == controller and r["trajectory"] == t),
                           key=lambda r: r["pwm_period_ms"])
            best = min(group, key=lambda r: r["rmse_mean_deg"])
            lines.append(f"{controller} T{t}: best {best['pwm_period_ms']:g} ms ({best['rmse_mean_deg']:.2f} deg); "
                         + ", ".join(f"{r['pwm_period_ms']:g} ms {r['rmse_mean_deg']:.2f}" for r in group))
    return Study("pwm", rows, "\n".join(lines))


# --- gear load ------------------------------------------------------------------------------------------------

def _moving_average(x: np.ndarray, window: int) -> np.ndarray:
    return np.convolve(x, np.ones(window) / window, mode="same")


def window_label(window: float) -> str:
    """Column label of an averaging window (s): ``"10ms"``."""
    return f"{window * 1e3:g}ms"


def mesh_loads(mesh: str, force: np.ndarray, allowed: np.ndarray, tick: float) -> dict:
    """For one mesh and each averaging window: the peak averaged force, and the tick where averaged
    force / Lewis safe load is largest, with that ratio and both loads at that same tick (N)."""
    row = {}
    for window in AVERAGING_WINDOWS:
        averaged = _moving_average(force, whole_ticks(window, tick, what="averaging window"))
        ratio = averaged / allowed
        k = int(np.argmax(ratio))
        label = window_label(window)
        row[f"{mesh}_peak_{label}_n"] = float(averaged.max())
        row[f"{mesh}_worst_ratio_{label}"] = float(ratio[k])
        row[f"{mesh}_at_worst_{label}_n"] = float(averaged[k])
        row[f"{mesh}_lewis_at_worst_{label}_n"] = float(allowed[k])
    return row


def _exceeding(rows: Sequence[dict], window: float) -> int:
    """Runs in which either mesh exceeds its Lewis safe load over ``window`` (s)."""
    label = window_label(window)
    return sum(max(r[f"spur_worst_ratio_{label}"], r[f"pinion_worst_ratio_{label}"]) > 1.0 for r in rows)


def gear_load_study(*, pressures_kpa: Sequence[float] = (300.0, 700.0), payloads_g: Sequence[float] = (0.0, 13.5),
                    plant_name: str = "thesis") -> Study:
    from twin.envs.runner import run_many

    scenarios = [Scenario(c, t, payload=m / 1e3, orientation=Orientation.VERTICAL, plant=plant_name,
                          supply_pressure=p * 1e3)
                 for c in ("pva", "ffpva", "smc") for t in (1, 2, 3, 4) for m in payloads_g for p in pressures_kpa]
    preset = plant(plant_name)
    gears = preset.params.gears
    rows = []
    for r in run_many(scenarios):
        tr = r.trace
        speed = np.abs(np.gradient(tr.rack_position, tr.time))
        row = {"controller": r.scenario.controller, "trajectory": r.scenario.trajectory,
               "payload_g": r.scenario.payload * 1e3, "supply_kpa": r.scenario.supply / 1e3}
        for mesh, force, spur in (("spur", tr.tooth_force_spur, True),
                                  ("pinion", np.maximum.reduce([tr.tooth_force_spur, tr.tooth_force_rack_a,
                                                                tr.tooth_force_rack_b]), False)):
            allowed = lewis_safe_load(gears, spur=spur, pitch_line_speed=speed)
            row.update(mesh_loads(mesh, force, allowed, preset.timestep))
        rows.append(row)
    single, sustained = window_label(AVERAGING_WINDOWS[0]), window_label(SUSTAINED_WINDOW)
    worst = max(rows, key=lambda r: r[f"spur_worst_ratio_{single}"])
    by_window = ", ".join(f"{w * 1e3:g} ms {max(r[f'spur_peak_{window_label(w)}_n'] for r in rows):.1f} N "
                          f"({_exceeding(rows, w)})" for w in AVERAGING_WINDOWS)
    answer = (f"{_exceeding(rows, AVERAGING_WINDOWS[0])} of {len(rows)} runs exceed a Lewis safe load at some "
              f"single {AVERAGING_WINDOWS[0] * 1e3:g} ms tick, {_exceeding(rows, SUSTAINED_WINDOW)} over a "
              f"{SUSTAINED_WINDOW * 1e3:g} ms average. Largest spur tooth force over all runs (and runs over a "
              f"Lewis safe load) by averaging window: {by_window}. Worst single tick against the Lewis load at "
              f"that tick ({worst['controller']} T{worst['trajectory']}, {worst['payload_g']:g} g, "
              f"{worst['supply_kpa']:g} kPa): {worst[f'spur_at_worst_{single}_n']:.1f} N against "
              f"{worst[f'spur_lewis_at_worst_{single}_n']:.1f} N; the same run's worst {SUSTAINED_WINDOW * 1e3:g} ms "
              f"average is {worst[f'spur_at_worst_{sustained}_n']:.1f} N against "
              f"{worst[f'spur_lewis_at_worst_{sustained}_n']:.1f} N at its tick. "
              "Caveat: in this rigid, incompressible plant a valve that shuts on a moving joint stops it within one "
              "1 ms step, so single-tick peaks are impacts whose size scales with 1/timestep; the sustained "
              "(averaged) loads are the meaningful ones until the plant has compliance (issue: as-built plant).")
    return Study("gear-load", rows, answer)


# --- supply ---------------------------------------------------------------------------------------------------

def supply_variants(base: Plant) -> dict[str, Plant]:
    """``base`` with each supply model of :data:`SUPPLY_MODELS`, named after it."""
    if not base.params.chambers.compressible:
        raise InvalidScenario(f"the supply study needs a plant whose supply can sag (compressible chambers, as "
                              f"as-built): {base.name!r} holds its supply constant")
    return {model: dataclasses.replace(base, name=f"{base.name}, {model} supply", params=dataclasses.replace(
        base.params, supply_line=dataclasses.replace(base.params.supply_line, model=model)))
        for model in SUPPLY_MODELS}


def supply_study(*, trajectories: Sequence[int] = (1, 3), seeds: int = 3, plant_name: str = DEFAULT_PLANTS["supply"],
                 progress=None) -> Study:
    """FF + PVA and sliding mode on ``trajectories`` with each supply model, ``seeds`` runs each, one batch."""
    from twin.envs.runner import run_many

    variants = supply_variants(plant(plant_name))
    cases = [(Scenario(c, t, plant=variants[m], seed=s), m)
             for m in SUPPLY_MODELS for c in PWM_CONTROLLERS for t in trajectories for s in range(seeds)]
    results = run_many([s for s, _ in cases], progress=progress)
    records = [{**report.summary(r), "pwm_period_ms": None, "status": "failed" if r.warnings else "ok"}
               for r in results]
    model_of = {variant.name: model for model, variant in variants.items()}
    rows = [{"supply_model": model_of[row["plant"]], **row} for row in summarise(records)]
    line = variants["line"].params.supply_line
    lines = [f"{plant_name} plant, supply through a hose ringing at {line.natural_frequency:g} Hz (line), the same with "
             f"a {line.accumulator_compliance:.0e} m^3/Pa gas accumulator at the valve block (accumulator), and a "
             f"constant {THESIS_SUPPLY / 1e3:g} kPa (constant); mean RMSE over {seeds} seeds:"]
    for controller in PWM_CONTROLLERS:
        for t in trajectories:
            by_model = {r["supply_model"]: r for r in rows if r["controller"] == controller and r["trajectory"] == t}
            line_rmse = by_model["line"]["rmse_mean_deg"]
            lines.append(f"{controller} T{t}: " + ", ".join(
                f"{m} {by_model[m]['rmse_mean_deg']:.2f} deg ({by_model[m]['rmse_mean_deg'] / line_rmse - 1:+.0%}"
                + ("" if np.isnan(by_model[m]["sse_mean_deg"]) else f", SSE {by_model[m]['sse_mean_deg']:+.2f}")
                + ")" for m in SUPPLY_MODELS))
    return Study("supply", rows, "\n".join(lines))
