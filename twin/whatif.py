"""``twin whatif``: gravity, payload, supply and PWM questions, each answered with
a table (CSV), a plot and a one-paragraph answer.

payload    RMSE, SSE and max error against tip payload, both orientations, both
           model-based controllers, up to where the joint can no longer follow
           (max |error| above FOLLOW_LIMIT_DEG in any seed).
lift       the heaviest tip payload the joint lifts vertically through 80-100 deg,
           against supply pressure: torque balance with the friction model, then
           confirmed by bisection in simulation (valves fully open).
pwm        tracking against PWM period (thesis future work 4).
gear-load  peak gear tooth forces, from the couplings' constraint forces, against
           the Lewis safe loads at the pitch-line speed of the moment.
"""

from __future__ import annotations

import dataclasses
import pathlib
from collections.abc import Sequence

import numpy as np

from twin import friction
from twin.gears import lewis_safe_load
from twin.grid import expand
from twin.model import Orientation
from twin.params import JointParams
from twin.plants import plant
from twin.scenario import Scenario
from twin.sweep import run_sweep
from twin.tables import summarise

FOLLOW_LIMIT_DEG = 10.0  # max |error| beyond which the joint "no longer follows"
LIFT_SPAN_DEG = (80.0, 100.0)  # the lift must pass the horizontal link position
IMPACT_WINDOW = 10  # ticks: averaging window separating sustained loads from one-step impacts


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
    from twin.simulation import simulate

    scenarios = [Scenario("ffpva", 3, payload=float(m), orientation=Orientation.VERTICAL, plant=plant_name,
                          noise=False, supply_pressure=float(p)) for m, p in zip(payloads, pressures, strict=True)]
    opener = OpenLoop(schedule=lambda t: 100.0, tick=plant(plant_name).timestep)
    results = simulate(scenarios, controllers=[opener] * len(scenarios))
    return np.array([np.degrees(r.trace.angle).max() >= LIFT_SPAN_DEG[1] for r in results])


def lift_study(*, pressures_kpa: Sequence[float], plant_name: str = "thesis", tolerance: float = 0.005) -> Study:
    params = plant(plant_name).params
    pressures = np.array(pressures_kpa, dtype=float) * 1e3
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
    at_300 = np.interp(300e3, pressures, lifted_g)
    needed = pressures[lifted_g >= 13.5]
    differences = [abs(r["difference_pct"]) for r in rows if np.isfinite(r["difference_pct"])]
    answer = (f"Vertical, valves fully open, through {LIFT_SPAN_DEG[0]:g}-{LIFT_SPAN_DEG[1]:g} deg: "
              f"{at_300:.1f} g can be lifted at the tip at 300 kPa; "
              + (f"13.5 g needs {needed.min() / 1e3:.0f} kPa or more of those tried. " if needed.size
                 else "13.5 g cannot be lifted at any pressure tried. ")
              + (f"Simulation and torque balance agree within {max(differences):.1f} %. " if differences else "")
              + "Holding needs no pressure in this plant: sealed chambers lock the joint.")
    return Study("lift", rows, answer)


# --- pwm ------------------------------------------------------------------------------------------------------

def pwm_study(*, out: pathlib.Path, periods_ms: Sequence[float], trajectories: Sequence[int] = (1, 3), seeds: int = 3,
              plant_name: str = "thesis", workers: int | None = None, progress=None) -> Study:
    points = expand({"controller": ["ffpva", "smc"], "trajectory": list(trajectories), "plant": [plant_name],
                     "seed": list(range(seeds)), "pwm_period_ms": list(periods_ms)})
    rows = summarise(run_sweep(points, out=out, workers=workers, progress=progress).records)
    lines = []
    for controller in ("ffpva", "smc"):
        for t in trajectories:
            group = [r for r in rows if r["controller"] == controller and r["trajectory"] == t]
            best = min(group, key=lambda r: r["rmse_mean_deg"])
            lines.append(f"{controller} T{t}: best {best['pwm_period_ms']:g} ms ({best['rmse_mean_deg']:.2f} deg); "
                         + ", ".join(f"{r['pwm_period_ms']:g} ms {r['rmse_mean_deg']:.2f}" for r in group))
    return Study("pwm", rows, "\n".join(lines))


# --- gear load ------------------------------------------------------------------------------------------------

def _moving_average(x: np.ndarray, window: int) -> np.ndarray:
    return np.convolve(x, np.ones(window) / window, mode="same")


def gear_load_study(*, pressures_kpa: Sequence[float] = (300.0, 700.0), payloads_g: Sequence[float] = (0.0, 13.5),
                    plant_name: str = "thesis") -> Study:
    from twin.runner import run_many

    scenarios = [Scenario(c, t, payload=m / 1e3, orientation=Orientation.VERTICAL, plant=plant_name,
                          supply_pressure=p * 1e3)
                 for c in ("pva", "ffpva", "smc") for t in (1, 2, 3, 4) for m in payloads_g for p in pressures_kpa]
    gears = plant(plant_name).params.gears
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
            sustained = _moving_average(force, IMPACT_WINDOW)
            k = int(np.argmax(force / allowed))
            row[f"{mesh}_peak_n"] = float(force.max())
            row[f"{mesh}_peak_{IMPACT_WINDOW}ms_n"] = float(sustained.max())
            row[f"{mesh}_lewis_at_peak_n"] = float(allowed[k])
            row[f"{mesh}_exceeds"] = bool(np.any(force > allowed))
            row[f"{mesh}_sustained_exceeds"] = bool(np.any(sustained > allowed))
        rows.append(row)
    raw = sum(r["spur_exceeds"] or r["pinion_exceeds"] for r in rows)
    sustained = sum(r["spur_sustained_exceeds"] or r["pinion_sustained_exceeds"] for r in rows)
    worst = max(rows, key=lambda r: r["spur_peak_n"])
    answer = (f"{raw} of {len(rows)} runs exceed a Lewis safe load at some tick, {sustained} over a "
              f"{IMPACT_WINDOW} ms average. The largest spur tooth force is {worst['spur_peak_n']:.1f} N "
              f"({worst['controller']} T{worst['trajectory']}, {worst['payload_g']:g} g, {worst['supply_kpa']:g} kPa; "
              f"{worst['spur_peak_10ms_n']:.1f} N over {IMPACT_WINDOW} ms). Caveat: in this rigid, incompressible "
              "plant a valve that shuts on a moving joint stops it within one 1 ms step, so single-tick peaks are "
              "impacts whose size scales with 1/timestep; the sustained (averaged) loads are the meaningful ones "
              "until the plant has compliance (issue: as-built plant).")
    return Study("gear-load", rows, answer)
