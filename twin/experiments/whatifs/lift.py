"""``twin whatif lift``: the heaviest tip payload the joint lifts vertically through 80-100 deg,
against supply pressure: torque balance with the friction model, then confirmed by bisection in
simulation (valves fully open).
"""

from __future__ import annotations

import argparse
import pathlib
from collections.abc import Sequence

import numpy as np

from twin.experiments.base import Experiment, Outcome
from twin.experiments.reference import THESIS_PAYLOADS_G
from twin.experiments.whatifs.common import (
    add_common_arguments,
    list_flag,
    progress_bar,
    refuse_oversized,
    simulate_in_parts,
)
from twin.physics import friction
from twin.physics.model import Orientation
from twin.physics.params import NOMINAL_PARAMS, JointParams
from twin.plants import plant
from twin.sim.scenario import Scenario
from viz.figures import finish, plt

LIFT_SPAN_DEG = (80.0, 100.0)  # the lift must pass the horizontal link position
THESIS_PAYLOAD = THESIS_PAYLOADS_G[-1] * 1e-3  # kg, the heaviest payload of the robustness study
PAYLOAD_COLUMN = f"lifts_{THESIS_PAYLOAD * 1e3:g}g"  # true where a run with that payload passed the span
LIFT_TOLERANCE = 0.005  # the bisection stops within this fraction of each pressure's closed-form lift


def lift_limit_closed_form(params: JointParams, supply_pressure: float) -> float:
    """Heaviest tip payload (kg) whose gravity torque the full supply force, less friction, still
    beats everywhere in LIFT_SPAN_DEG (valves fully open, at vanishing speed); negative if not even
    the bare link rises:

        (P A - F_f(y)) r_s = (1 + mu_L) (m L + m_link L / 2) g sin(theta),  y = theta r_s,
        F_f = max(F_c(y), stiction)   (the rack starts each lift from rest)

    with mu_L the load friction (:func:`twin.physics.friction.load_friction`: the gravity load the
    gears carry costs mu_L of itself again in friction; 0 on the thesis plant)."""
    r_s, length = params.gears.spur_radius, params.masses.link_length
    theta = np.radians(np.linspace(*LIFT_SPAN_DEG, 401))
    y = theta * r_s
    resisting = np.maximum(friction.coulomb_force(params.friction, y, np.ones_like(y)), params.friction.stiction)
    torque = (supply_pressure * params.cylinder.bore_area - resisting) * r_s
    carried = 1.0 + params.friction.load_friction  # the gravity load plus its load friction
    mass = torque / (carried * params.gravity * length * np.sin(theta)) - params.masses.link_mass / 2
    return float(np.min(mass))


def _lifts(payloads: np.ndarray, pressures: np.ndarray, plant_name: str, bar=None) -> np.ndarray:
    """Simulate each (payload, pressure) from 80 deg (T3's start) with the valves fully open (``bar`` counts
    the runs); True where the link passes the end of LIFT_SPAN_DEG within the run."""
    from controllers.open_loop import OpenLoop

    scenarios = [Scenario(None, 3, payload=float(m), orientation=Orientation.VERTICAL, plant=plant_name,
                          noise=False, supply_pressure=float(p)) for m, p in zip(payloads, pressures, strict=True)]
    opener = OpenLoop(schedule=lambda t: 100.0, tick=plant(plant_name).timestep)
    return np.array(simulate_in_parts(scenarios, [opener] * len(scenarios),
                                      lambda r: bool(np.degrees(r.trace.angle).max() >= LIFT_SPAN_DEG[1]), bar),
                    dtype=bool)


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


def _bisection_steps(closed: np.ndarray, can: np.ndarray, tolerance: float) -> int:
    """Halvings until every bracket in ``can`` (0 to 1.5 x its closed form + 1 mg) is within ``tolerance``
    of its closed form: all pressures are bisected together, so the most demanding one sets the count."""
    steps = 0
    for c in closed[can]:
        width, k = 1.5 * c + 1e-3, 0
        while width > tolerance * abs(c):
            width, k = width / 2, k + 1
        steps = max(steps, k)
    return steps


def closed_forms(pressures_kpa: Sequence[float], plant_name: str) -> tuple[np.ndarray, np.ndarray]:
    """The distinct pressures (Pa, sorted, so rows and answer run upwards) and each one's closed-form lift (kg)."""
    params = plant(plant_name).params
    pressures = np.unique(np.array(pressures_kpa, dtype=float)) * 1e3
    return pressures, np.array([lift_limit_closed_form(params, p) for p in pressures])


def planned_runs(closed: np.ndarray, tolerance: float = LIFT_TOLERANCE) -> int:
    """The most runs :func:`lift_study` makes for these closed forms: the bare link and the thesis payload at
    every pressure, then every bisection step at each pressure whose closed form lifts anything."""
    return 2 * closed.size + int(np.sum(closed > 0)) * _bisection_steps(closed, closed > 0, tolerance)


def lift_study(*, pressures_kpa: Sequence[float], plant_name: str = "thesis", tolerance: float = LIFT_TOLERANCE,
               bar=None) -> Outcome:
    """``bar`` (a tqdm bar, optional) is given the number of scenarios before any runs, then counts them."""
    pressures, closed = closed_forms(pressures_kpa, plant_name)
    n = len(pressures)
    if bar is not None:  # the bare link and the thesis payload at every pressure, then the bisection (at most)
        bar.reset(total=planned_runs(closed, tolerance))

    def lifts(payloads: np.ndarray, at: np.ndarray) -> np.ndarray:
        return _lifts(payloads, at, plant_name, bar)

    first = lifts(np.concatenate([np.zeros(n), np.full(n, THESIS_PAYLOAD)]), np.concatenate([pressures, pressures]))
    bare_link_lifts, payload_lifts = first[:n], first[n:]  # the payload itself, not read off the bisection
    can = bare_link_lifts & (closed > 0)
    steps = _bisection_steps(closed, can, tolerance)
    if bar is not None:  # exact now that the bare link's runs say which pressures lift it at all
        bar.total = 2 * n + int(np.sum(can)) * steps
        bar.refresh()
    low, high = np.zeros_like(closed), np.where(can, 1.5 * closed + 1e-3, 0.0)
    for _ in range(steps):  # bisection, all pressures in one batch
        middle = (low + high) / 2
        lifted = lifts(middle[can], pressures[can])
        low[can], high[can] = np.where(lifted, middle[can], low[can]), np.where(lifted, high[can], middle[can])
    simulated = np.where(bare_link_lifts, (low + high) / 2, np.nan)
    rows = [{"supply_kpa": p / 1e3, "lift_closed_form_g": max(c, 0.0) * 1e3,
             "lift_simulated_g": s * 1e3 if np.isfinite(s) else 0.0,
             "difference_pct": 100 * (s - c) / c if c > 0 and np.isfinite(s) else float("nan"),
             PAYLOAD_COLUMN: bool(lifted)}
            for p, c, s, lifted in zip(pressures, closed, simulated, payload_lifts, strict=True)]
    differences = [abs(r["difference_pct"]) for r in rows if np.isfinite(r["difference_pct"])]
    answer = (f"Vertical, valves fully open, through {LIFT_SPAN_DEG[0]:g}-{LIFT_SPAN_DEG[1]:g} deg: "
              f"{_lift_at(NOMINAL_PARAMS.supply.pressure, pressures, np.array([r['lift_simulated_g'] for r in rows]))}; "
              f"{_payload_needs(pressures, payload_lifts)} "
              + (f"Simulation and torque balance agree within {max(differences):.1f} %. " if differences else "")
              + "Holding needs no pressure in this plant: sealed chambers lock the joint.")
    return Outcome(rows, answer)


def _payload_needs(pressures: np.ndarray, lifted: np.ndarray) -> str:
    """The lowest of the sorted ``pressures`` (Pa) at which the thesis payload was lifted, from the runs
    of that payload itself (``lifted``), with the tried pressure below it and any higher one that failed."""
    grams = f"{THESIS_PAYLOAD * 1e3:g} g"
    if not np.any(lifted):
        return f"{grams} is not lifted at any pressure tried (up to {pressures[-1] / 1e3:g} kPa)."
    first = int(np.argmax(lifted))
    said = f"{grams} is lifted from {pressures[first] / 1e3:g} kPa, the lowest pressure tried that lifts it"
    said += f" ({pressures[first - 1] / 1e3:g} kPa does not)" if first > 0 else " (nothing lower was tried)"
    failed = pressures[first:][~lifted[first:]]
    if failed.size:
        said += f", yet not at {', '.join(f'{p / 1e3:g}' for p in failed)} kPa"
    return said + "."


def plot_lift(rows: Sequence[dict], path: pathlib.Path) -> None:
    fig, ax = plt.subplots(figsize=(7, 4.5), constrained_layout=True)
    p = [r["supply_kpa"] for r in rows]
    ax.plot(p, [r["lift_closed_form_g"] for r in rows], "k-", label="torque balance with friction")
    ax.plot(p, [r["lift_simulated_g"] for r in rows], "o", color="C3", label="simulation (bisection)")
    ax.axhline(THESIS_PAYLOAD * 1e3, color="0.6", ls=":", label=f"{THESIS_PAYLOAD * 1e3:g} g (thesis payload)")
    finish(fig, ax, path, xlabel="supply pressure (kPa)", ylabel="heaviest tip payload lifted vertically (g)")


class LiftWhatIf(Experiment):
    name = "lift"
    help = "heaviest payload lifted vertically against supply pressure"
    default_plant = "thesis"

    def add_arguments(self, parser: argparse.ArgumentParser) -> None:
        add_common_arguments(parser, self.default_plant, seeds=False)
        parser.add_argument("--pressures", default="100:700:50", metavar="LIST", help="kPa (default 100:700:50)")

    def check(self, args: argparse.Namespace) -> None:
        args.pressure_values = list_flag(args, "--pressures", "pressures", "supply_kpa")
        refuse_oversized(planned_runs(closed_forms(args.pressure_values, args.plant)[1]), "--pressures")

    def run(self, args: argparse.Namespace, out: pathlib.Path) -> Outcome:
        with progress_bar(self.name) as bar:
            return lift_study(pressures_kpa=args.pressure_values, plant_name=args.plant, bar=bar)

    def plot(self, outcome: Outcome, path: pathlib.Path) -> None:
        plot_lift(outcome.rows, path)


EXPERIMENT = LiftWhatIf()
