"""``twin study ablation``: which as-built effect does what to SPEC §8's experimental table.

The committed as-built preset is run on every experimental cell (PVA T1-T3,
FF + PVA T1-T4, sliding mode T1-T4, horizontal, no payload) as it is, then
with each effect switched off in turn, everything else as fitted and nothing
refitted. The supply line is integrated with the compressible chambers, so
switching compressibility off switches the line off with it.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence

from twin.experiments.calibrate import CHECK_SEEDS, Evaluator, cell_rows
from twin.experiments.reference import THESIS_EXPERIMENT_RMSE_DEG
from twin.plants.as_built import EFFECTS, calibrated_values

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
    evaluator = Evaluator(seeds=seeds, workers=workers)
    rows = []
    try:
        for done, (label, off) in enumerate(variants(), start=1):
            cells = evaluator.cells(values, without=off)
            for cell, row in zip(cells, cell_rows(cells), strict=True):
                within = abs(cell.mean_rmse / row["experiment_rmse_deg"] - 1.0) <= TOLERANCE
                rows.append({"variant": label, **row, "within_tolerance": within})
            if progress is not None:
                progress(done, len(variants()), label)
    finally:
        evaluator.close()
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
