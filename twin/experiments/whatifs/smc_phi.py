"""``twin whatif smc-phi``: sliding mode against its boundary layer phi, on every measured sliding-mode cell.

Sliding mode adds 100 % sat(sigma / phi) to FF + PVA every 1 ms (§6); the thesis ran it at phi = 0.3 m/s.
On the as-built plant its switching term at that phi lifts the command past the valve's dead zone no
sooner than FF + PVA's compensation does (``twin validate``'s pulse cycle), and the twin's sliding mode
misses T2 and T3. This what-if asks how strong the term would have to be: sliding mode at each phi on the
cells the thesis measured it on (§8's T1-T4, §9's T1 payload cells; seeds 0..N-1), beside FF + PVA on the
same cells and seeds, the measured means and the closed-form lag at which each law opens the valve on T2.
It answers a question; it changes nothing: phi stays the thesis's in every other command.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import pathlib
from collections.abc import Sequence

from twin.exceptions import InvalidScenario
from twin.experiments.arguments import seed_count
from twin.experiments.base import Experiment, Outcome
from twin.experiments.validate import RMSE_TOLERANCE
from twin.experiments.whatifs.common import (
    add_common_arguments,
    number_list,
    progress_bar,
    refuse_oversized,
    simulate_in_parts,
)
from twin.sim.metrics import spread
from viz.figures import finish_panels, plt

COLUMNS = ("controller", "phi_m_s", "source", "trajectory", "payload_g", "orientation", "rmse_mean_deg",
           "rmse_std_deg", "measured_deg", "ratio", "opening_lag_t2_deg")
DEFAULT_PHIS = (0.1, 0.15, 0.2, 0.3)
TOLERANCE = RMSE_TOLERANCE  # a measured cell's bar, as `twin validate` judges it


def measured_cells() -> list:
    """The calibration targets sliding mode was measured on (``twin.experiments.calibrate.Target``), §8 first."""
    from twin.experiments.calibrate import TARGETS

    return [t for t in TARGETS if t.controller == "smc"]


def parse_phis(text: str) -> tuple[float, ...]:
    """``--phis``: boundary layers in m/s, comma-separated, each in (0, 10]; the plant's own phi is always run."""
    values = number_list(text, "--phis", "numbers in m/s")
    if not values or not all(math.isfinite(v) and 0 < v <= 10 for v in values):
        raise InvalidScenario(f"--phis: each phi must be in (0, 10] m/s, got {text!r}")
    return tuple(values)  # number_list sorts them


def plant_phi(base) -> float:
    """The boundary layer of ``base``'s own sliding mode (its gain set's), m/s: always run beside the given ones."""
    import controllers
    from twin.envs.runner import nominal_model

    return controllers.make_controller("smc", nominal=nominal_model(base), gain_set=base.gain_set,
                                       tick=base.timestep).gains.boundary_layer


def _label(row: dict) -> str:
    orientation = "" if row["orientation"] == "horizontal" and not row["payload_g"] else (
        f" {row['payload_g']:g} g {row['orientation'][0].upper()}")
    return f"T{row['trajectory']}{orientation}"


def phi_study(*, phis: Sequence[float], seeds: int = 10, plant_name: str = "as-built", bar=None) -> Outcome:
    """Sliding mode at each phi and FF + PVA on :func:`measured_cells` on ``plant_name``, seeds
    0..``seeds``-1, one batch."""
    import controllers
    from twin.envs.runner import nominal_model
    from twin.experiments import validate
    from twin.experiments.calibrate import TARGET_OF
    from twin.experiments.whatifs.ensemble import cell_scenario
    from twin.physics.valves import ValveModel
    from twin.plants import plant

    base = plant(plant_name)
    nominal = nominal_model(base)
    thesis = controllers.make_controller("smc", nominal=nominal, gain_set=base.gain_set, tick=base.timestep)
    phis = tuple(sorted(set(phis) | {thesis.gains.boundary_layer}))
    laws = {("smc", phi): dataclasses.replace(thesis, gains=dataclasses.replace(thesis.gains, boundary_layer=phi))
            for phi in phis}
    laws[("ffpva", None)] = controllers.make_controller("ffpva", nominal=nominal, gain_set=base.gain_set,
                                                        tick=base.timestep)
    cells = [t.key[1:] for t in measured_cells()]  # (trajectory, payload g, orientation)
    jobs = [(key, cell, s) for key in laws for cell in cells for s in range(seeds)]
    if bar is not None:
        bar.reset(total=len(jobs))
    results = simulate_in_parts([cell_scenario((key[0], *cell), base, s) for key, cell, s in jobs],
                                [laws[key] for key, _, _ in jobs],
                                lambda r: (r.metrics.rmse, bool(r.warnings)), bar)
    lags = (validate.ramp_opening_lags(base, nominal, laws)["lag_deg"]
            if base.valve_model is ValveModel.SOLENOID else {})  # no valve threshold to reach: no closed form
    rmse: dict[tuple, list[float]] = {}  # (law key, cell) -> the runs' RMSE, deg
    for (key, cell, _), (run_rmse, _) in zip(jobs, results, strict=True):
        rmse.setdefault((key, cell), []).append(math.degrees(run_rmse))
    rows = []
    for key in laws:
        for cell in cells:
            s = spread(rmse[(key, cell)])
            target = TARGET_OF[(key[0], *cell)]
            rows.append(dict(zip(COLUMNS, (key[0], key[1], target.source, *cell, s.mean, s.std, target.rmse_deg,
                                           s.mean / target.rmse_deg, lags.get(key, math.nan)), strict=True)))
    failed = sum(warned for _, warned in results)
    return Outcome(rows, answer(rows, phi=thesis.gains.boundary_layer, seeds=seeds, plant_name=plant_name),
                   failed=failed, detail=thesis.gains.boundary_layer)


def answer(rows: Sequence[dict], *, phi: float, seeds: int, plant_name: str) -> str:
    def cell(r: dict) -> tuple:
        return r["trajectory"], r["payload_g"], r["orientation"]

    def lag(value: float) -> str:
        return "" if math.isnan(value) else f"; lag on T2 {value:.2f} deg"

    ffpva = {cell(r): r for r in rows if r["controller"] == "ffpva"}
    smc = [r for r in rows if r["controller"] == "smc"]
    runs = "seed 0" if seeds == 1 else f"seeds 0-{seeds - 1}"
    ffpva_rows = list(ffpva.values())
    lines = [f"Sliding mode on {plant_name} against its boundary layer phi (the thesis's: {phi:g} m/s), on the "
             f"{len(ffpva_rows)} cells it was measured on, {runs}; mean RMSE in deg (x measured). FF + PVA on the "
             "same cells and seeds: " + ", ".join(f"{_label(r)} {r['rmse_mean_deg']:.2f}" for r in ffpva_rows)
             + lag(ffpva_rows[0]["opening_lag_t2_deg"]) + ". On the rig sliding mode was ahead of FF + PVA on "
             f"{sum(r['measured_deg'] < ffpva[cell(r)]['measured_deg'] for r in smc if r['phi_m_s'] == phi)} of "
             f"{len(ffpva_rows)}."]
    fitting = {}
    for value in sorted({r["phi_m_s"] for r in smc}, reverse=True):
        group = [r for r in smc if r["phi_m_s"] == value]
        inside = [abs(r["ratio"] - 1) <= TOLERANCE for r in group]
        ahead = sum(r["rmse_mean_deg"] < ffpva[cell(r)]["rmse_mean_deg"] for r in group)
        by_source = {source: (sum(i for r, i in zip(group, inside, strict=True) if r["source"] == source),
                              sum(r["source"] == source for r in group)) for source in dict.fromkeys(
                                  r["source"] for r in group)}
        fitting[value] = by_source
        lines.append(f"phi {value:g} m/s: " + ", ".join(f"{_label(r)} {r['rmse_mean_deg']:.2f} (x{r['ratio']:.2f})"
                                                          for r in group)
                     + "; within " + f"{TOLERANCE:.0%} on " + ", ".join(f"{n} of {total} ({source})" for source, (
                         n, total) in by_source.items())
                     + f"; ahead of FF + PVA on {ahead} of {len(group)}" + lag(group[0]["opening_lag_t2_deg"])
                     + (" (the thesis's)" if value == phi else ""))
    every = [v for v, by in fitting.items() if all(n == total for n, total in by.values())]
    first = smc[0]["source"]  # the thesis's own table (§8) comes first
    chapter5 = [v for v, by in fitting.items() if by[first][0] == by[first][1]]
    lines.append(("Of the phis run, every measured sliding-mode cell is within tolerance at "
                  + ", ".join(f"{v:g}" for v in every) + " m/s." if every else
                  "No phi run puts every measured sliding-mode cell within tolerance"
                  + (f"; every {first} cell is at " + ", ".join(f"{v:g}" for v in chapter5) + " m/s." if chapter5
                     else ".")) + " A what-if, not a fit: every other command runs the thesis's phi.")
    return "\n".join(lines)


def plot_phi(rows: Sequence[dict], path: pathlib.Path, *, thesis_phi: float) -> None:
    """One panel a measured cell: sliding mode against phi, FF + PVA on the same seeds, the measured band."""
    cells = list(dict.fromkeys((r["trajectory"], r["payload_g"], r["orientation"]) for r in rows
                               if r["controller"] == "smc"))
    columns = 3
    fig, axes = plt.subplots(-(-len(cells) // columns), columns, figsize=(11, 2.6 * -(-len(cells) // columns)),
                             sharex=True, constrained_layout=True, squeeze=False)
    for ax, cell in zip(axes.flat, cells, strict=False):
        group = sorted((r for r in rows if r["controller"] == "smc"
                        and (r["trajectory"], r["payload_g"], r["orientation"]) == cell), key=lambda r: r["phi_m_s"])
        ax.errorbar([r["phi_m_s"] for r in group], [r["rmse_mean_deg"] for r in group],
                    yerr=[r["rmse_std_deg"] for r in group], marker="o", capsize=3, label="sliding mode")
        measured = group[0]["measured_deg"]
        ax.axhspan(measured * (1 - TOLERANCE), measured * (1 + TOLERANCE), color="tab:green", alpha=0.15, lw=0,
                   label=f"measured +-{TOLERANCE:.0%}")
        ax.axhline(measured, color="tab:green", lw=1.0)
        ffpva = next(r["rmse_mean_deg"] for r in rows if r["controller"] == "ffpva"
                     and (r["trajectory"], r["payload_g"], r["orientation"]) == cell)
        ax.axhline(ffpva, color="tab:orange", ls="--", lw=1.0, label="twin FF + PVA")
        ax.axvline(thesis_phi, color="0.5", ls=":", lw=1.0, label="the thesis's phi")
        ax.set_title(f"{_label(group[0])} ({group[0]['source']})", fontsize=9)
        ax.set_ylabel("RMSE (deg)")
    for ax in axes.flat[len(cells):]:
        ax.set_visible(False)
    for ax in axes[-1]:
        ax.set_xlabel("boundary layer phi (m/s)")
    finish_panels(fig, [ax for ax in axes.flat[:len(cells)]], path, legend_size=6)


class SmcPhiWhatIf(Experiment):
    name = "smc-phi"
    help = "sliding mode against its boundary layer phi, on every measured sliding-mode cell (nothing else changes)"
    default_plant = "as-built"

    def add_arguments(self, parser: argparse.ArgumentParser) -> None:
        add_common_arguments(parser, self.default_plant, seeds=False)
        parser.add_argument("--seeds", type=seed_count, default=10, help="noise seeds per case (default 10)")
        parser.add_argument("--phis", default=",".join(f"{p:g}" for p in DEFAULT_PHIS), metavar="LIST",
                            help="boundary layers in m/s (default 0.1,0.15,0.2,0.3; the thesis's 0.3 always runs)")

    def check(self, args: argparse.Namespace) -> None:
        from twin.plants import plant

        args.phi_values = parse_phis(args.phis)
        base = plant(args.plant)
        if base.gain_set != "experiment":
            raise InvalidScenario(f"--plant {args.plant} runs the thesis's simulation gains; smc-phi compares with the "
                                  "rig's measurements, so it needs a plant with the experiment gains (as-built)")
        laws = len(set(args.phi_values) | {plant_phi(base)}) + 1  # the plant's own phi (phi_study's), and FF + PVA
        refuse_oversized(laws * len(measured_cells()) * args.seeds, "--phis x --seeds")

    def run(self, args: argparse.Namespace, out: pathlib.Path) -> Outcome:
        with progress_bar(self.name) as bar:
            return phi_study(phis=args.phi_values, seeds=args.seeds, plant_name=args.plant, bar=bar)

    def plot(self, outcome: Outcome, path: pathlib.Path) -> None:
        plot_phi(outcome.rows, path, thesis_phi=outcome.detail)


EXPERIMENT = SmcPhiWhatIf()
