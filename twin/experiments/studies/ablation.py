"""``twin study ablation``: which as-built effect does what to SPEC §8's experimental table.

The committed as-built preset is run on every experimental cell (PVA T1-T3,
FF + PVA T1-T4, sliding mode T1-T4, horizontal, no payload) as it is, then
with each effect switched off in turn, everything else as fitted and nothing
refitted. The supply line is integrated with the compressible chambers, so
switching compressibility off switches the line off with it.
"""

from __future__ import annotations

import argparse
import dataclasses
import pathlib
import sys
from collections.abc import Callable, Sequence

import numpy as np

from twin.batch.tables import counted, write_csv
from twin.experiments import arguments
from twin.experiments.base import Experiment, Outcome
from twin.experiments.calibrate import CHECK_SEEDS, EXPERIMENT_CELLS, Evaluator, cell_rows
from twin.experiments.reference import THESIS_EXPERIMENT_RMSE_DEG
from twin.plants.as_built import EFFECTS, calibrated_values
from twin.sim.scenario import CONTROLLER_LABELS
from viz.figures import plt

TOLERANCE = 0.2  # the bar: the twin's mean RMSE within 20 % of the experiment's


def variants() -> list[tuple[str, tuple[str, ...]]]:
    """(label, effects switched off): the preset itself, then one effect off at a time."""
    return [("as-built", ())] + [
        (f"- {effect}", (effect, "supply_line") if effect == "compressibility" else (effect,))
        for effect in EFFECTS]


@dataclasses.dataclass(frozen=True)
class Ablation:
    rows: list[dict]  # one per variant x cell
    seeds: tuple[int, ...]

    def within(self, variant: str) -> int:
        return sum(r["within_tolerance"] for r in self.rows if r["variant"] == variant)


def ablation_study(*, seeds: Sequence[int] = CHECK_SEEDS, workers: int = 2,
                   progress: Callable[[int, int, str], None] | None = None) -> Ablation:
    """``progress(done, total, variant)`` after each variant."""
    values = calibrated_values()
    rows = []
    with Evaluator(seeds=seeds, workers=workers, cells=EXPERIMENT_CELLS) as evaluator:
        for done, (label, off) in enumerate(variants(), start=1):
            cells = evaluator.cells(values, without=off)
            for cell, row in zip(cells, cell_rows(cells), strict=True):
                within = abs(cell.mean_rmse / row["experiment_rmse_deg"] - 1.0) <= TOLERANCE
                rows.append({"variant": label, **row, "within_tolerance": within})
            if progress is not None:
                progress(done, len(variants()), label)
    return Ablation(rows=rows, seeds=tuple(seeds))


def format_ablation(study: Ablation) -> str:
    """Mean RMSE (deg) per variant x cell, the experiment first, and how many cells are within 20 %."""
    cells = [(r["controller"], r["trajectory"]) for r in study.rows if r["variant"] == "as-built"]
    width = max(len(label) for label, _ in variants()) + 2
    head = "".join(f"{c[:5]} T{t}".rjust(10) for c, t in cells)
    lines = [f"As-built ablation (SPEC §8 cells, mean RMSE in deg over seeds {list(study.seeds)}; "
             f"'within': cells within {TOLERANCE:.0%} of the experiment)",
             "variant".ljust(width) + head + "   within",
             "experiment".ljust(width) + "".join(f"{THESIS_EXPERIMENT_RMSE_DEG[c][t][0]:10.2f}" for c, t in cells)]
    for label, _ in variants():
        rmse = [r["twin_rmse_deg"] for r in study.rows if r["variant"] == label]
        lines.append(label.ljust(width) + "".join(f"{x:10.2f}" for x in rmse)
                     + f"   {study.within(label)}/{len(cells)}")
    return "\n".join(lines)


def plot_ablation(rows: Sequence[dict], path: pathlib.Path) -> None:
    """Twin / experiment RMSE per variant (rows) x experimental cell (columns), on a log colour scale
    centred on 1; cells within the 20 % bar are boxed."""
    variants = list(dict.fromkeys(r["variant"] for r in rows))
    cells = list(dict.fromkeys((r["controller"], r["trajectory"]) for r in rows))
    ratio = np.array([[r["ratio"] for r in rows if r["variant"] == v] for v in variants])
    within = np.array([[r["within_tolerance"] for r in rows if r["variant"] == v] for v in variants])
    fig, ax = plt.subplots(figsize=(1.0 * len(cells) + 3, 0.45 * len(variants) + 1.5), constrained_layout=True)
    image = ax.imshow(np.log2(ratio), cmap="RdBu_r", vmin=-2, vmax=2, aspect="auto")
    for i in range(len(variants)):
        for j in range(len(cells)):
            ax.text(j, i, f"{ratio[i, j]:.2f}", ha="center", va="center", fontsize=8,
                    fontweight="bold" if within[i, j] else "normal")
            if within[i, j]:
                ax.add_patch(plt.Rectangle((j - 0.5, i - 0.5), 1, 1, fill=False, lw=1.5, ec="k"))
    ax.set_xticks(range(len(cells)), [f"{CONTROLLER_LABELS.get(c, c)}\nT{t}" for c, t in cells], fontsize=7)
    ax.set_yticks(range(len(variants)), variants, fontsize=8)
    colorbar = fig.colorbar(image, ax=ax, ticks=[-2, -1, 0, 1, 2])
    colorbar.ax.set_yticklabels(["1/4", "1/2", "1", "2", "4"])
    colorbar.set_label("twin / experiment RMSE")
    ax.set_title("as-built with one effect off (boxed: within 20 % of the experiment)")
    fig.savefig(path, dpi=110)
    plt.close(fig)


class AblationExperiment(Experiment):
    name = "ablation"
    help = "the as-built preset on SPEC §8's cells with each effect switched off in turn"

    def add_arguments(self, parser: argparse.ArgumentParser) -> None:
        parser.add_argument("--seeds", type=arguments.seed_count, default=5, help="noise seeds per cell (default 5)")
        parser.add_argument("--workers", type=arguments.workers, default=2, help="processes (default 2)")

    def check(self, args: argparse.Namespace) -> None:
        from twin.experiments.whatifs.common import refuse_oversized

        calibrated_values()  # no committed preset: a one-line error before anything is written
        refuse_oversized(len(variants()) * len(EXPERIMENT_CELLS) * args.seeds, "--seeds")

    def run(self, args: argparse.Namespace, out: pathlib.Path) -> Outcome:
        print(f"{len(variants())} variants x {len(EXPERIMENT_CELLS)} cells x {counted(args.seeds, 'seed')} on the as-built plant -> "
              f"{out.resolve()}", file=sys.stderr)
        study = ablation_study(seeds=range(args.seeds), workers=args.workers,
                               progress=lambda done, total, label: print(f"[{done}/{total}] {label}", file=sys.stderr))
        return Outcome(rows=study.rows, answer=format_ablation(study),
                       failed=sum(bool(r["failed_runs"]) for r in study.rows), detail=study)

    def file_names(self) -> tuple[str, ...]:
        return ("ablation.csv", "ablation.png")

    def write(self, outcome: Outcome, out: pathlib.Path) -> list[pathlib.Path]:
        path = out / "ablation.csv"
        write_csv(outcome.rows, list(outcome.rows[0]), path)
        return [path]

    def plot(self, outcome: Outcome, path: pathlib.Path) -> None:
        plot_ablation(outcome.rows, path)


EXPERIMENT = AblationExperiment()
