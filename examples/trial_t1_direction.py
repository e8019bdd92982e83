"""Trial (not installed): does T1's direction move PVA + DZC's T1 miss?

The rig's PVA + DZC tracked T1 at 4.20 ± 0.76 deg with a 13.5 deg largest error; the twin's tracks it at about
1.9 deg with a largest error of about 8.7 (`twin validate`). SPEC §7 gives T1 as +120 deg, and the twin runs it
from 30 to 150 deg (away from 0 deg: clockwise in the twin's friction, whose Coulomb force is larger moving towards
0 deg by the fitted CCW scale, since the thesis tracked worse CCW). Which way the rig's PVA + DZC T1 runs went is
not stated. This script runs all three laws on T1 as committed and mirrored (from 150 down to 30 deg: the same
cycloid and 2 s hold, moving towards 0 deg), on the committed as-built preset (its digest is printed), seeds 0-9,
and prints per law and direction the RMSE (mean ± std over the runs), the largest error (mean; the largest in
brackets), the RMS error over the move (0-1 s) and over the hold, and the largest |SSE| of seeds 0-4 and of 5-9.
Nothing is refitted. The result is recorded in docs/investigations.md; a slow test in
tests/experiments/test_trials_effects.py holds the printed numbers.

    python examples/trial_t1_direction.py
"""

from __future__ import annotations

import argparse
import math

import numpy as np

import twin.sim.simulation as simulation
from twin.envs.runner import run_many
from twin.physics.trajectories import Segment, Trajectory
from twin.plants.as_built import CALIBRATION_FILE, preset_digest
from twin.sim.scenario import Scenario

SEEDS = range(10)
LAWS = ("pva", "ffpva", "smc")


def mirrored(committed):
    """``committed`` (simulation's trajectory function) with T1 run the other way: 150 to 30 deg."""

    def trajectory(number: int, *, spur_radius: float) -> Trajectory:
        t1 = committed(number, spur_radius=spur_radius)
        if number != 1:
            return t1
        top = t1.start + sum(s.change for s in t1.segments)  # rad, where the committed T1 ends
        return Trajectory(1, top, tuple(Segment(s.kind, s.duration, -s.delta) for s in t1.segments))

    return trajectory


def row(law: str) -> str:
    """``law`` on T1 as simulation runs it now, seeds :data:`SEEDS`, as the module docstring says (deg)."""
    runs = run_many([Scenario(law, 1, plant="as-built", seed=s) for s in SEEDS])
    rmse, largest, sse = (np.degrees([getattr(r.metrics, k) for r in runs]) for k in ("rmse", "max_error", "sse"))
    t = runs[0].trace.time
    error = np.degrees([r.trace.desired_angle - r.scored_angle for r in runs])
    move, hold = (math.sqrt(float(np.mean(error[:, t < 1.0] ** 2))), math.sqrt(float(np.mean(error[:, t >= 1.0] ** 2))))
    return (f"{rmse.mean():.2f} ± {rmse.std(ddof=1):.2f}, largest {largest.mean():.1f} ({largest.max():.1f}), "
            f"move {move:.2f} hold {hold:.2f}, SSE ±{np.abs(sse[:5]).max():.2f} / ±{np.abs(sse[5:]).max():.2f}")


def main() -> None:
    print(f"T1 on the committed as-built preset ({preset_digest(CALIBRATION_FILE)}), seeds 0-9: RMSE mean ± std, "
          "largest error mean (largest), RMS over the move / the hold, largest |SSE| of seeds 0-4 / 5-9 (deg)")
    committed = simulation.trajectory
    try:
        for law in LAWS:
            for label, trajectory in (("30 to 150 deg", committed), ("150 to 30 deg", mirrored(committed))):
                simulation.trajectory = trajectory
                print(f"{law:5s}  {label}  {row(law)}", flush=True)
    finally:
        simulation.trajectory = committed  # T1 runs as committed for whatever runs after


if __name__ == "__main__":  # --help says what it runs instead of running it
    argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter).parse_args()
    main()
