"""Trial (not installed): does T1's direction move PVA + DZC's T1 miss?

The rig's PVA + DZC tracked T1 at 4.20 ± 0.76 deg with a 13.5 deg largest error; the twin's tracks it at about
1.9 deg with a largest error of about 8.7 (`twin validate`). The twin runs T1 from 30 to 150 deg, away from 0 deg,
where its Coulomb friction is the smaller: moving towards 0 deg it is scaled by the fitted CCW scale (the thesis
tracked worse CCW). SPEC §7's "+120 deg" is a rise, but the thesis does not say on which side of the stroke T1
starts or which way the angle counts on the rig, so which way the rig's PVA + DZC T1 runs went is not stated.

This script runs all three laws on T1 as committed and mirrored (from 150 down to 30 deg: the same cycloid and 2 s
hold, moving towards 0 deg), seeds 0-9, on the twelfth refit's kept values (``twin/plants/data/twelfth_refit.json``:
the committed preset's fitted values, so the same plant; a later refit does not change what this prints). It
prints per law and direction the RMSE (mean ± std over the runs), the largest error (mean; the largest in
brackets), the RMS error over the move (0-1 s) and over the hold, and the SSE ranges of seeds 0-4 and 5-9; then
per law what mirroring does seed by seed: the mean change of RMSE with its standard error (paired: each seed's
runs either way), and on how many seeds it is worse. Nothing is refitted. The result is recorded in
docs/investigations.md; a slow test in tests/experiments/test_trials_effects.py holds the printed numbers.

    python examples/trial_t1_direction.py
"""

from __future__ import annotations

import argparse
import math
import pathlib
import sys

import numpy as np

import twin.sim.simulation as simulation
from twin.envs.runner import run_many
from twin.physics.trajectories import Segment, Trajectory
from twin.plants.as_built import TWELFTH_REFIT_FILE, as_built_plant, calibrated_values, preset_digest
from twin.sim.scenario import Scenario

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))  # the sibling modules, however this one is loaded
from trial_t1_start import t1_move_hold_sse  # noqa: E402

SEEDS = range(10)
LAWS = ("pva", "ffpva", "smc")
PLANT = as_built_plant(calibrated_values(TWELFTH_REFIT_FILE))


def mirrored(committed):
    """``committed`` (simulation's trajectory function) with T1 run the other way: from its end back to its start."""

    def trajectory(number: int, *, spur_radius: float) -> Trajectory:
        t1 = committed(number, spur_radius=spur_radius)
        if number != 1:
            return t1
        return Trajectory(1, t1.end, tuple(Segment(s.kind, s.duration, -s.delta) for s in t1.segments))

    return trajectory


def runs_of(law: str) -> tuple[np.ndarray, str]:
    """``law`` on T1 as simulation runs it now, seeds :data:`SEEDS`: each run's RMSE, and a row as the module
    docstring says (deg)."""
    runs = run_many([Scenario(law, 1, plant=PLANT, seed=s) for s in SEEDS])
    rmse, largest = (np.degrees([getattr(r.metrics, k) for r in runs]) for k in ("rmse", "max_error"))
    move, hold, _, ranges = t1_move_hold_sse(runs)
    return rmse, (f"{rmse.mean():.2f} ± {rmse.std(ddof=1):.2f}, largest {largest.mean():.1f} ({largest.max():.1f}), "
                  f"move {move:.2f} hold {hold:.2f}, SSE {ranges}")


def main() -> None:
    print(f"T1 on the twelfth refit's values ({preset_digest(TWELFTH_REFIT_FILE)}; the committed preset's), seeds 0-9: "
          "RMSE mean ± std, largest error mean (largest), RMS over the move / the hold, SSE ranges of seeds 0-4 / 5-9 "
          "(deg)")
    committed = simulation.trajectory
    change = {}
    try:
        for law in LAWS:
            rmse = []
            for label, trajectory in (("30 to 150 deg", committed), ("150 to 30 deg", mirrored(committed))):
                simulation.trajectory = trajectory
                each, row = runs_of(law)
                rmse.append(each)
                print(f"{law:5s}  {label}  {row}", flush=True)
            change[law] = rmse[1] - rmse[0]
    finally:
        simulation.trajectory = committed  # T1 runs as committed for whatever runs after
    print("mirrored minus committed, seed by seed: RMSE change mean ± its standard error (deg), seeds worse")
    for law, d in change.items():
        se = d.std(ddof=1) / math.sqrt(len(d))
        print(f"{law:5s}  {d.mean():+.2f} ± {se:.2f} ({d.mean() / se:+.1f} standard errors), worse on "
              f"{int(np.sum(d > 0))} of {len(d)}")


if __name__ == "__main__":  # --help says what it runs instead of running it
    argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter).parse_args()
    main()
