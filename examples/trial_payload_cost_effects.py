"""Trial (not installed): which as-built effect sets what a horizontal 13.5 g costs each law on T1.

`twin validate` reads the sliding-mode T1 13.5 g horizontal miss by the payload's cost: on seeds 40-79 the
payload costs the twin's sliding mode x1.20 over its 0 g flat cell, the rig's x1.03, while it costs the
twin's FF + PVA x1.00, the rig's x1.25 (2026-11-26). This script runs both laws on T1 at 0 g and 13.5 g,
horizontal, seeds 40-79, on the committed preset (the ninth refit's, ``twin/plants/data/ninth_refit.json``) as it is and with each effect switched off in turn
(compressibility only with the supply line, which needs it), nothing refitted, and prints each cell's mean
RMSE and the cost (13.5 g over 0 g) with its paired standard error. Its result (2026-11-26) is
in docs/investigations.md.

About 65 s on 2 cores.

    python examples/trial_payload_cost_effects.py
"""

from __future__ import annotations

import argparse
import math

import numpy as np

from twin.experiments.calibrate import Evaluator
from twin.experiments.studies.ablation import variants
from twin.plants.as_built import NINTH_REFIT_FILE, calibrated_values

SEEDS = range(40, 80)
KEYS = [(c, 1, g, "horizontal") for c in ("ffpva", "smc") for g in (0.0, 13.5)]  # each law's 0 g, then 13.5 g


def cost(flat: np.ndarray, loaded: np.ndarray) -> tuple[float, float]:
    """The loaded cell's mean RMSE over the flat one's, and its standard error. The two cells run on the same
    seeds (the same stiction maps and noise), so the error is the paired one (delta method: the spread of
    loaded - ratio * flat over the seeds), not that of two independent means."""
    ratio = loaded.mean() / flat.mean()
    return ratio, float(np.std(loaded - ratio * flat, ddof=1) / math.sqrt(flat.size) / flat.mean())


def main() -> None:
    print("without                          | FF + PVA 0 g, 13.5 g (deg), cost | sliding mode 0 g, 13.5 g (deg), cost "
          "(T1 horizontal, seeds 40-79)")
    values = calibrated_values(NINTH_REFIT_FILE)
    with Evaluator(seeds=SEEDS, workers=2, cells=KEYS) as evaluator:
        for _, off in variants():  # the ablation study's: the preset, then each effect off in turn
            if "load_friction" in off:  # it acts only on a vertical joint: this row would be the preset's
                continue
            rmse = [np.array(cell.rmse_deg) for cell in evaluator.cells(values, without=off)]
            cells = []
            for k in (0, 2):
                ratio, se = cost(rmse[k], rmse[k + 1])
                cells.append(f"{rmse[k].mean():.2f}, {rmse[k + 1].mean():.2f}, x{ratio:.2f} ± {se:.2f}")
            print(f"{','.join(off) or '(nothing: as committed)':32s} | {cells[0]} | {cells[1]}", flush=True)


if __name__ == "__main__":  # --help says what it runs instead of running it
    argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter).parse_args()
    main()
