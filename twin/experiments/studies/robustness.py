"""``twin study robustness``: the thesis's robustness protocol (Chapter 6, SPEC §9).

FF + PVA and sliding mode, T1 and T3, 0 / 6.5 / 13.5 g at the link tip, horizontal and
vertical, seeds 0..4: 120 runs through the sweep engine (``twin.batch.sweep.run_sweep``:
batched, on all cores, resumable from ``DIR/results.sqlite``). Tables in the thesis's form:
T1's SSE per run and its range; RMSE per run, mean and std for T1 and T3. A run with a MuJoCo
warning or an error is marked failed and left out of the statistics. No number here is tuned
toward the held-back measurements. Degrees and grams only in the rows, tables and answers.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import pathlib
import sys
from collections.abc import Callable, Sequence

import numpy as np
from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

from twin.batch.grid import GridPoint, expand
from twin.batch.sweep import counting, run_sweep
from twin.batch.tables import signed, summarise, write_csv
from twin.experiments import arguments
from twin.experiments.base import Experiment, Outcome
from twin.experiments.reference import THESIS_PAYLOADS_G
from twin.plants import ENSEMBLE_PREFIX, PLANTS, plant
from twin.sim.scenario import CONTROLLER_LABELS, MODEL_BASED_CONTROLLERS
from viz.figures import plt

ROBUSTNESS_CONTROLLERS = MODEL_BASED_CONTROLLERS
ROBUSTNESS_TRAJECTORIES = (1, 3)
ROBUSTNESS_PAYLOADS_G = THESIS_PAYLOADS_G  # g at the link tip
ROBUSTNESS_ORIENTATIONS = ("horizontal", "vertical")
ROBUSTNESS_SEEDS = 5  # "five runs each"
RUN_COLUMNS = ("plant", "controller", "trajectory", "payload_g", "orientation", "seed", "status",
               "rmse_deg", "sse_deg", "max_error_deg", "warnings")
SUMMARY_COLUMNS = ("plant", "controller", "trajectory", "payload_g", "orientation", "runs", "failed",
                   "rmse_mean_deg", "rmse_std_deg", "rmse_min_deg", "rmse_max_deg",
                   "sse_min_deg", "sse_max_deg", "sse_range_deg", "max_error_deg",
                   "ensemble_members", "band_p10_deg", "band_p50_deg", "band_p90_deg")
CELL = ("controller", "trajectory", "payload_g", "orientation")


def default_plant(fallback: str) -> str:
    """``as-built`` when that preset exists, else ``fallback``."""
    return "as-built" if PLANTS.get("as-built") is not None else fallback


@dataclasses.dataclass(frozen=True)
class RobustnessStudy:
    runs: list[dict]  # RUN_COLUMNS, one per scenario, in grid order (controller, trajectory, payload, orientation, seed)
    summary: list[dict]  # SUMMARY_COLUMNS, one per controller x trajectory x payload x orientation
    seeds: int

    @property
    def failed(self) -> list[dict]:
        return [r for r in self.runs if r["status"] != "ok"]


def ensemble_members(plant_name: str) -> list[str]:
    """The calibration ensemble's plant names (``as-built~K``) when ``plant_name`` is ``as-built``, else none."""
    if plant_name != "as-built":
        return []
    from twin.plants.as_built import ensemble_values

    return [f"{ENSEMBLE_PREFIX}{k}" for k in range(len(ensemble_values()))]


def robustness_grid(*, plant_name: str, seeds: int = ROBUSTNESS_SEEDS,
                    trajectories: Sequence[int] = ROBUSTNESS_TRAJECTORIES, ensemble: bool = False) -> list[GridPoint]:
    """The Chapter 6 protocol: controllers x trajectories x payloads x orientations x seeds 0..seeds-1
    (120 points with the defaults), each checked by building its scenario; with ``ensemble`` (as-built
    only) the same again on each calibration ensemble member."""
    plant(plant_name)  # an unknown name fails here, with the preset names
    plants = [plant_name] + (ensemble_members(plant_name) if ensemble else [])
    return expand({"controller": list(ROBUSTNESS_CONTROLLERS), "trajectory": list(trajectories),
                   "payload": list(ROBUSTNESS_PAYLOADS_G), "orientation": list(ROBUSTNESS_ORIENTATIONS),
                   "plant": plants, "seed": list(range(seeds))})


def _finite(value: float | None) -> float | None:
    return None if value is None or math.isnan(value) else value


def run_row(record: dict) -> dict:
    """A sweep record as a row of ``robustness_runs.csv``: failed when it raised a MuJoCo warning or an
    error, which ``warnings`` then names."""
    return {"plant": record["plant"], "controller": record["controller"], "trajectory": record["trajectory"],
            "payload_g": record["payload_g"], "orientation": record["orientation"], "seed": record["seed"],
            "status": record["status"], "rmse_deg": _finite(record["rmse_deg"]),
            "sse_deg": _finite(record["sse_deg"]), "max_error_deg": _finite(record["max_error_deg"]),
            "warnings": record["reason"] or ""}


def summary_rows(records: Sequence[dict]) -> list[dict]:
    """Per controller x trajectory x payload x orientation, over the runs that did not fail: RMSE
    mean, std (none from fewer than two runs), min, max; SSE min, max and range (the thesis's "±",
    max |SSE|; none for T3, which ends moving)."""
    rows = []
    for s in summarise(records):
        sse_min, sse_max = _finite(s["sse_min_deg"]), _finite(s["sse_max_deg"])
        rows.append({
            **{c: s[c] for c in SUMMARY_COLUMNS if c in s},
            **{c: _finite(s[c]) for c in ("rmse_mean_deg", "rmse_std_deg", "rmse_min_deg", "rmse_max_deg",
                                          "max_error_deg")},
            "sse_min_deg": sse_min, "sse_max_deg": sse_max,
            "sse_range_deg": None if sse_min is None else max(abs(sse_min), abs(sse_max)),
        })
        if s["runs"] - s["failed"] < 2:
            rows[-1]["rmse_std_deg"] = None  # no spread from one run
    return rows


def with_band(summary: list[dict], member_records: Sequence[dict]) -> list[dict]:
    """``summary`` with, per cell, the ensemble members' five-run mean RMSE: how many members, and the
    10 / 50 / 90 % percentiles of their means (empty without members)."""
    means: dict[tuple, list[float]] = {}
    for s in summary_rows(member_records):
        if s["rmse_mean_deg"] is not None:
            means.setdefault(tuple(s[c] for c in CELL), []).append(s["rmse_mean_deg"])
    out = []
    for s in summary:
        found = means.get(tuple(s[c] for c in CELL), [])
        band = [float(np.percentile(found, q)) for q in (10, 50, 90)] if found else [None] * 3
        out.append({**s, "ensemble_members": len(found), "band_p10_deg": band[0], "band_p50_deg": band[1],
                    "band_p90_deg": band[2]})
    return out


def robustness_study(*, out: pathlib.Path, plant_name: str, seeds: int = ROBUSTNESS_SEEDS,
                     trajectories: Sequence[int] = ROBUSTNESS_TRAJECTORIES, workers: int | None = None,
                     progress: Callable[[int], None] | None = None, ensemble: bool = False) -> RobustnessStudy:
    """Run the protocol (what ``out/results.sqlite`` holds already is not run again) and tabulate it;
    with ``ensemble`` (as-built only) also on each calibration ensemble member, for the band."""
    records = run_sweep(robustness_grid(plant_name=plant_name, seeds=seeds, trajectories=trajectories,
                                        ensemble=ensemble), out=out, workers=workers, progress=progress).records
    own = [r for r in records if r["plant"] == plant_name]
    members = [r for r in records if r["plant"] != plant_name]
    return RobustnessStudy(runs=[run_row(r) for r in own], summary=with_band(summary_rows(own), members),
                           seeds=seeds)


def write_robustness(study: RobustnessStudy, out: pathlib.Path) -> list[pathlib.Path]:
    """``robustness_runs.csv`` and ``robustness_summary.csv``."""
    paths = [out / "robustness_runs.csv", out / "robustness_summary.csv"]
    write_csv(study.runs, RUN_COLUMNS, paths[0])
    write_csv(study.summary, SUMMARY_COLUMNS, paths[1])
    return paths


def _cell(row: dict, column: str) -> str:
    if row["status"] != "ok":
        return "failed"
    return "-" if row[column] is None else signed(row[column]) if column == "sse_deg" else f"{row[column]:.2f}"


def _per_run_table(study: RobustnessStudy, trajectory: int, column: str, title: str, tail: Sequence[str],
                   tail_of: Callable[[dict], Sequence[str]]) -> list[str]:
    groups = [s for s in study.summary if s["trajectory"] == trajectory]
    if not groups:
        return []
    lines = [title, f"{'controller':13} {'payload':>7} {'orientation':11} "
             + " ".join(f"{'run ' + str(i + 1):>7}" for i in range(study.seeds))
             + "".join(f" {h:>8}" for h in tail)]
    for s in groups:
        runs = [r for r in study.runs if all(r[k] == s[k] for k in ("controller", "trajectory", "payload_g",
                                                                     "orientation"))]
        lines.append(f"{CONTROLLER_LABELS[s['controller']]:13} {s['payload_g']:>5g} g {s['orientation']:11} "
                     + " ".join(f"{_cell(r, column):>7}" for r in runs)
                     + "".join(f" {t:>8}" for t in tail_of(s)))
    return lines + [""]


def _number(value: float | None, spec: str = ".2f") -> str:
    return "-" if value is None else format(value, spec)


def format_robustness(study: RobustnessStudy) -> str:
    """The thesis's tables: T1's SSE per run with its range; RMSE per run, mean and std for each trajectory."""
    plant_name = study.runs[0]["plant"] if study.runs else "?"
    lines = [f"Robustness study (SPEC §9) on the {plant_name} plant, degrees; 'failed' runs (MuJoCo warning "
             "or error) are left out of every statistic", ""]
    lines += _per_run_table(study, 1, "sse_deg", "T1: steady-state error per run and its range (± max |SSE|)",
                            ("range",), lambda s: (f"±{_number(s['sse_range_deg'])}",))
    banded = any(s.get("ensemble_members") for s in study.summary)
    for trajectory in sorted({s["trajectory"] for s in study.summary}):
        lines += _per_run_table(study, trajectory, "rmse_deg", f"T{trajectory}: RMSE per run, mean and std"
                                + (", the calibration ensemble's median and 10-90 % band" if banded else ""),
                                ("mean", "std", "p50", "p10-p90") if banded else ("mean", "std"),
                                lambda s: (_number(s["rmse_mean_deg"]), _number(s["rmse_std_deg"]))
                                + ((_number(s.get("band_p50_deg")),
                                    f"{_number(s.get('band_p10_deg'))}-{_number(s.get('band_p90_deg'))}")
                                   if banded else ()))
    failed = study.failed
    lines.append(f"{len(study.runs)} runs, {len(failed)} failed")
    lines += [f"failed: {CONTROLLER_LABELS[r['controller']]} T{r['trajectory']} {r['payload_g']:g} g {r['orientation']} "
              f"seed {r['seed']}: {r['warnings']}" for r in failed[:20]]
    return "\n".join(lines)


ORIENTATION_STYLES = {"horizontal": "-", "vertical": "--"}


def robustness_figure(runs: Sequence[dict]) -> plt.Figure:
    """RMSE against tip payload: every finished run a dot, the median of each cell a line; one panel per
    trajectory (its title counts the failed runs, which are not drawn), colour per controller, line style
    per orientation. Log scale, so that a stalled run (tens of degrees) shows as the outlier it is
    instead of flattening the others."""
    if not runs:
        raise ValueError("no robustness runs to plot")
    finished = [r for r in runs if r["status"] != "failed" and r["rmse_deg"] is not None]
    trajectories = sorted({r["trajectory"] for r in runs})
    fig, axes = plt.subplots(1, len(trajectories), figsize=(5.5 * len(trajectories), 4.5), squeeze=False,
                             sharey=True, constrained_layout=True)
    controllers = sorted({r["controller"] for r in runs})
    lines = [(c, o) for c in controllers for o in ORIENTATION_STYLES]
    for ax, trajectory in zip(axes[0], trajectories, strict=True):
        for line_index, (controller, orientation) in enumerate(lines):
            members = [r for r in finished if (r["trajectory"], r["controller"], r["orientation"])
                       == (trajectory, controller, orientation)]
            if not members:
                continue
            color = f"C{controllers.index(controller)}"
            payloads = sorted({r["payload_g"] for r in members})
            offset = 0.15 * (line_index - (len(lines) - 1) / 2)  # side by side, so the dots do not hide
            median = [float(np.median([r["rmse_deg"] for r in members if r["payload_g"] == g])) for g in payloads]
            ax.plot([g + offset for g in payloads], median, ls=ORIENTATION_STYLES[orientation], color=color,
                    label=f"{CONTROLLER_LABELS[controller]}, {orientation}")
            ax.plot([r["payload_g"] + offset for r in members], [r["rmse_deg"] for r in members], ls="none",
                    marker="o", ms=3.5, alpha=0.6, color=color)
        ax.set_yscale("log")
        ax.yaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
        ax.yaxis.set_major_formatter(FuncFormatter(lambda value, _: f"{value:g}"))
        ax.yaxis.set_minor_formatter(NullFormatter())
        failed = sum(r["trajectory"] == trajectory for r in runs) - sum(r["trajectory"] == trajectory
                                                                         for r in finished)
        ax.set_title(f"T{trajectory} ({runs[0]['plant']} plant)" + (f", {failed} failed runs not shown" if failed else ""))
        ax.set_xlabel("payload at the link tip (g)")
        ax.grid(alpha=0.3, which="both")
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=8, handlelength=3.5)  # long enough to show the dashes
    axes[0][0].set_ylabel("RMSE (deg): runs (dots), median (line)")
    return fig


def plot_robustness(runs: Sequence[dict], path: pathlib.Path) -> None:
    """:func:`robustness_figure`, written to ``path``."""
    fig = robustness_figure(runs)
    fig.savefig(path, dpi=90)
    plt.close(fig)


class RobustnessStudyExperiment(Experiment):
    name = "robustness"
    help = "FF + PVA and sliding mode, T1 and T3, 0/6.5/13.5 g, horizontal and vertical, 5 seeds (SPEC §9)"
    resumable = True

    def add_arguments(self, parser: argparse.ArgumentParser) -> None:
        parser.add_argument("--seeds", type=arguments.seed_count, default=ROBUSTNESS_SEEDS, help="noise seeds per case (default 5)")
        parser.add_argument("--workers", type=arguments.workers, default=None, help="processes (default: all cores)")
        parser.add_argument("--plant", default=None, metavar="NAME", help="default: as-built if present, else thesis")
        parser.add_argument("--no-ensemble", dest="ensemble", action="store_false",
                            help="as-built: skip the calibration ensemble's runs (no band in the summary)")

    def check(self, args: argparse.Namespace) -> None:
        args.plant = default_plant("thesis") if args.plant is None else args.plant
        plant(args.plant)  # an unknown name is a one-line error before anything is written
        args.ensemble = args.ensemble and args.plant == "as-built"
        args.points = robustness_grid(plant_name=args.plant, seeds=args.seeds, ensemble=args.ensemble)  # too big too

    def run(self, args: argparse.Namespace, out: pathlib.Path) -> Outcome:
        from tqdm import tqdm

        points = args.points
        print(f"{len(points)} runs on the {args.plant} plant -> {out.resolve()}", file=sys.stderr)
        with tqdm(total=len(points), unit="run", file=sys.stderr, dynamic_ncols=True, desc="robustness") as bar:
            study = robustness_study(out=out, plant_name=args.plant, seeds=args.seeds, workers=args.workers,
                                     progress=counting(bar), ensemble=args.ensemble)
        return Outcome(rows=study.summary, answer=format_robustness(study), failed=len(study.failed), detail=study)

    def file_names(self) -> tuple[str, ...]:
        return ("robustness_runs.csv", "robustness_summary.csv", "robustness.png")

    def write(self, outcome: Outcome, out: pathlib.Path) -> list[pathlib.Path]:
        return write_robustness(outcome.detail, out)

    def plot(self, outcome: Outcome, path: pathlib.Path) -> None:
        plot_robustness(outcome.detail.runs, path)


EXPERIMENT = RobustnessStudyExperiment()
