"""Trial (not installed): Chapter 5's T4 controller order on every calibration ensemble member.

The rig tracked T4 with sliding mode ahead of FF + PVA (1.82 against 1.95 deg); the ninth refit's
preset put FF + PVA ahead. This script runs both on T4 (0 g, horizontal) for each member of the ninth refit's
calibration ensemble (the committed one when it ran, kept in ``twin/plants/data/ninth_refit.json``), on seeds 0-4
(the verdict's) and on seeds 40-79 (which no step of the fit ran), and prints the members' profiled values and the
four means. Its result (2026-11-26) is in docs/investigations.md; a slow test in
tests/experiments/test_trials_effects.py holds the printed numbers.

About 40 s on 2 cores.

    python examples/trial_t4_order.py
"""

from __future__ import annotations

import argparse

from twin.experiments import calibrate
from twin.plants.as_built import NINTH_REFIT_FILE, ensemble_values

KEYS = [("ffpva", 4, 0.0, "horizontal"), ("smc", 4, 0.0, "horizontal")]
FRESH = tuple(range(40, 80))


def main() -> None:
    with calibrate.Evaluator(seeds=tuple(range(5)), workers=2) as evaluator:
        for k, m in enumerate(ensemble_values(NINTH_REFIT_FILE)):
            five = evaluator.cells(m, keys=KEYS)
            fresh = evaluator.cells(m, keys=KEYS, seeds=FRESH)
            print(f"{k} CCW {m['ccw_coulomb_scale']:.3f} load {m['load_friction']:.2f} K_OB {m['observer_gain']:.0f} "
                  f"leak {m['leak_conductance'] * 1e14:.2f}e-14 | seeds 0-4: FF + PVA {five[0].mean_rmse:.3f}, "
                  f"SMC {five[1].mean_rmse:.3f} | seeds 40-79: FF + PVA {fresh[0].mean_rmse:.3f}, "
                  f"SMC {fresh[1].mean_rmse:.3f}", flush=True)


if __name__ == "__main__":  # --help says what it runs instead of running it
    argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter).parse_args()
    main()
