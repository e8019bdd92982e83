"""Trial (not installed): would softer or leakier chambers account for two misses that look alike?

Two of `twin validate`'s misses point the same way. §4.6's open-loop test: the real joint lagged the
thesis's model at each reversal, the chamber pressures taking time to build (most after long closures); the
as-built twin lags *less* than the model. And PVA + DZC on T1: the rig's largest error was 13.5 deg, the
twin's 7.8; in the twin PVA's error is a saw-tooth, growing while the valves are shut and falling when a pulse
moves the joint, so a slower build-up after each closure would let it grow further.

The fit holds the two chamber parameters that set the build-up in a box: free air 0-3 % of the chamber volume
(the committed value, 2.83 %, sits near the top) and a leak past each discharge valve of 0-3e-14 m^3/(Pa s)
(committed 1.39e-14). This script runs the committed values (the ninth refit's, ``twin/plants/data/ninth_refit.json``) with one of the two moved, inside the box and past
it, and prints for each:

* the fit's cost on four seed sets (0-9, the fit's, then 10-19, 20-29, 30-39) and the difference from the
  committed values' set by set (the same seeds share the runs' noise);
* how many of the 21 fitted cells are within 20 % on seeds 0-39;
* PVA + DZC T1 (RMSE and largest error, mean over seeds 0-39; the rig 4.20 and 13.5 deg), sliding mode T2 and
  T3 (the rig 1.55 and 1.69) and FF + PVA T1 (the rig 1.40);
* the open-loop test's mean lag at the reversals (the thesis's model: 104 ms; the real joint lagged more);
* the blind prediction's twelve T3 cells (mean RMSE over seeds 0-4, as `twin validate` runs them): the
  ensemble's members all share the committed air fraction, so its band cannot show what the air does to them.

Nothing is refitted around the moved value, and nothing here is installed: past the box is a diagnosis, not a
fit. The result is recorded in docs/investigations.md (PVA T1 and the lag) and docs/prediction.md (the air and the T3
cells, which the README sums up); a slow test in tests/experiments/test_trials_effects.py holds the printed table (CI
runs three of its rows again, all fourteen with pytest's ``--every-kept-row``: docs/testing.md).

About 9 min on 2 cores for all fourteen rows; ``--only NAME`` (repeatable, as the rows are named: ``--only "air
0.12"``) runs the committed values and the named rows alone (CI's test runs three of them: docs/testing.md).

    python examples/trial_chamber_buildup.py [--only NAME ...]
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence

import numpy as np

from twin.experiments import calibrate
from twin.experiments.reference import THESIS_PAYLOADS_G
from twin.experiments.studies.openloop import openloop_run
from twin.experiments.validate import rmse_within
from twin.plants.as_built import NINTH_REFIT_FILE, as_built_plant, calibrated_values

AIR = (0.01, 0.02, 0.025, 0.03, 0.04, 0.05, 0.06, 0.08, 0.12)  # free air per chamber volume at 1 atm; the box is 0-0.03
LEAK = (0.0, 3e-14, 6e-14, 1.2e-13)  # m^3/(Pa s) past each discharge valve; the box is 0-3e-14
SEED_SETS = (calibrate.FIT_SEEDS, *calibrate.NOISE_SEED_SETS)
T3 = [(c, 3, g, o) for c in ("ffpva", "smc") for o in ("horizontal", "vertical") for g in THESIS_PAYLOADS_G]
SHOWN = (("smc", 2), ("smc", 3), ("ffpva", 1))  # printed after PVA T1: (controller, trajectory), 0 g flat
MOVED = tuple(f"air {x:g}" for x in AIR) + tuple(f"leak {x:g}" for x in LEAK)  # the rows after the committed one


def main(only: Sequence[str] | None = None) -> None:
    """Print the committed values' row, then every row of :data:`MOVED` (or the ``only`` ones, in that order)."""
    if only is not None and set(only) - set(MOVED):
        raise ValueError(f"no such row: {', '.join(sorted(set(only) - set(MOVED)))}; the rows are {', '.join(MOVED)}")
    best = calibrated_values(NINTH_REFIT_FILE)
    points = [("committed", best)]
    points += [(f"air {x:g}", {**best, "air_fraction": x}) for x in AIR]
    points += [(f"leak {x:g}", {**best, "leak_conductance": x}) for x in LEAK]
    points = [(name, values) for name, values in points if only is None or name == "committed" or name in only]
    all_seeds = tuple(s for seeds in SEED_SETS for s in seeds)
    print("values | cost on seeds 0-9 / 10-19 / 20-29 / 30-39 | over the committed's, set by set: mean (lowest to "
          "highest) | within 20 % of 21 (seeds 0-39) | PVA T1 (largest), SMC T2, SMC T3, FF+PVA T1 (deg, seeds "
          "0-39) | open-loop mean lag (ms) | T3 FF + PVA H 0 / 6.5 / 13.5 g, V 0 / 6.5 / 13.5 g; sliding mode the same "
          "(deg, seeds 0-4)")
    costs = {}
    with calibrate.Evaluator(seeds=all_seeds, workers=2) as evaluator:
        for name, values in points:
            cells = evaluator.cells(values)
            costs[name] = [calibrate.cost(calibrate._cells_of(cells, seeds)) for seeds in SEED_SETS]
            diff = np.subtract(costs[name], costs["committed"])
            by_key = {(c.controller, c.trajectory): c for c in cells if c.payload_g == 0 and c.orientation ==
                      "horizontal"}
            within = sum(bool(rmse_within(c.mean_rmse, calibrate.TARGET_OF[c.key].rmse_deg)) for c in cells)
            pva = by_key[("pva", 1)]
            shown = (f"{pva.mean_rmse:.2f} ({np.mean(pva.max_error_deg):.1f}), "
                     + ", ".join(f"{by_key[k].mean_rmse:.2f}" for k in SHOWN))
            t3 = [f"{c.mean_rmse:.2f}" for c in evaluator.cells(values, keys=T3, seeds=range(5))]
            lag = openloop_run(as_built_plant(values, name="as-built-trial")).mean_lag  # s
            print(f"{name:>12} | {' / '.join(f'{c:.3f}' for c in costs[name])} | {diff.mean():+.3f} "
                  f"({diff.min():+.3f} to {diff.max():+.3f}) | {within} | {shown} | {lag * 1e3:.0f} | "
                  f"{' / '.join(t3[:6])}; {' / '.join(t3[6:])}", flush=True)


if __name__ == "__main__":  # --help says what it runs instead of running it
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--only", action="append", choices=MOVED, metavar="NAME",
                        help="run the committed values and this row alone (repeatable): " + ", ".join(MOVED))
    main(parser.parse_args().only)
