"""Trial (not installed): does the rig's PVA + DZC T1 follow from its own T2 and T3, as the other laws' T1 do?

The rig's PVA + DZC tracked T1 at 4.20 ± 0.76 deg, T2 at 2.93 and T3 at 3.00; the twin's at about 1.9, 2.75 and
2.86 (`twin validate`): T2 and T3 within 20 %, T1 at x0.45. This script asks which of the rig's three numbers
is the odd one, from the rig's numbers alone, with the simplest model of tracking there is.

The model: a joint that follows its reference a fixed time tau behind, e(t) = theta_d(t) - theta_d(t - tau), at
rest at the start before it (exact on the twin's own T1-T3 references, sampled at its 1 ms ticks over their
committed lengths: twin.sim.metrics.lagging_metrics, which `twin validate` reads the rig's cells with too). A
run's RMSE is then a function of tau alone, for each trajectory. For each law the script
reads tau from its T2 RMSE and, apart, from its T3 RMSE, and predicts its T1 RMSE and largest T1 error with each
(beside the measured largest error: the rig's as the thesis gives it, one number per law; the twin's, the mean of its
runs').
It does so for the rig's three laws (SPEC §8) and, as a check of the model where every run is known, for the
twin's (the committed preset, seeds 0-4, scored as `twin validate` scores them). A law whose T1 the model
predicts from its T2 and T3 tracks T1 as its slower motions imply; one it does not is the odd one out by this
ruler. The model knows nothing of valves or friction: it is a ruler, not a plant. The ruler's T1 is taken over the
twin's 3 s run (T1's length is not stated, and a ruler's hold has no error), so the script also prints the rig's
ratios over other lengths. Nothing is
fitted to T1 and nothing of the twin is changed. Written after every number it reads was known. The result is
recorded in docs/investigations.md; a slow test in tests/experiments/test_trials_effects.py holds the printed
numbers.

    python examples/trial_lag_relation.py
"""

from __future__ import annotations

import argparse
import math

import numpy as np

from twin.envs.runner import run_many
from twin.experiments.reference import THESIS_EXPERIMENT_MAX_ERROR_DEG, THESIS_EXPERIMENT_RMSE_DEG
from twin.experiments.validate.readings import implied_t1
from twin.physics.trajectories import Segment, Trajectory, trajectory
from twin.plants import plant
from twin.sim.metrics import delay_for_rmse, lagging_metrics
from twin.sim.scenario import Scenario

SEEDS = range(5)  # the verdicts' seeds
LAWS = ("pva", "ffpva", "smc")
LENGTHS = (1.5, 2.0, 3.0, 5.0)  # s of T1 run, move included; 3 is the committed
PLANT = plant("as-built")


def lagging_rmse(number: int, delay: float, *, length: float | None = None) -> tuple[float, float]:
    """deg: the RMSE and the largest |error| of a joint that follows trajectory ``number`` ``delay`` s behind (T1
    held to ``length`` s in all, if given, instead of its committed 3 s)."""
    r = PLANT.params.gears.spur_radius
    path = trajectory(number, spur_radius=r)
    if length is not None:
        move = path.segments[0]
        path = Trajectory(1, path.start, (move, Segment("rest", length - move.duration)))
    m = lagging_metrics(path, delay, spur_radius=r, timestep=PLANT.timestep)
    return math.degrees(m.rmse), math.degrees(m.max_error)


def delay_for(number: int, rmse_deg: float) -> float:
    """s, the delay at which a lagging joint's RMSE on trajectory ``number`` is ``rmse_deg``."""
    r = PLANT.params.gears.spur_radius
    return delay_for_rmse(trajectory(number, spur_radius=r), math.radians(rmse_deg), spur_radius=r,
                          timestep=PLANT.timestep)


def twin_means() -> tuple[dict[str, dict[int, float]], dict[str, float]]:
    """deg, the twin's mean RMSE per law on T1-T3 and its mean largest T1 error (seeds :data:`SEEDS`)."""
    runs = run_many([Scenario(law, n, plant="as-built", seed=s) for law in LAWS for n in (1, 2, 3) for s in SEEDS])
    per = len(SEEDS)
    groups = [runs[k:k + per] for k in range(0, len(runs), per)]
    means = [np.mean([math.degrees(r.metrics.rmse) for r in group]) for group in groups]
    return ({law: {n: means[3 * i + n - 1] for n in (1, 2, 3)} for i, law in enumerate(LAWS)},
            {law: np.mean([math.degrees(r.metrics.max_error) for r in groups[3 * i]]) for i, law in enumerate(LAWS)})


def main() -> None:
    print("T1 as run (RMSE, largest error) and as predicted from T2 and from T3 by a joint that lags a fixed time: "
          "the delay each gives (ms), the T1 RMSE and largest T1 error it implies (deg), and T1 as run over that "
          "prediction")
    rig = {law: {n: cell[0] for n, cell in THESIS_EXPERIMENT_RMSE_DEG[law].items()} for law in LAWS}
    rig_largest = {law: THESIS_EXPERIMENT_MAX_ERROR_DEG[law][1] for law in LAWS}
    for source, (means, largest_of) in (("rig", (rig, rig_largest)), ("twin", twin_means())):
        for law in LAWS:
            t1, largest = means[law][1], largest_of[law]
            row = []
            for number in (2, 3):
                delay = delay_for(number, means[law][number])
                predicted, predicted_largest = lagging_rmse(1, delay)
                row.append(f"from T{number} ({means[law][number]:.2f}): {delay * 1e3:4.1f} ms, T1 {predicted:.2f} "
                           f"(largest {predicted_largest:.1f}) x{t1 / predicted:.2f}")
            print(f"{source:4s} {law:5s} T1 {t1:.2f}, largest {largest:.1f} | " + " | ".join(row))
    delay = delay_for(1, rig["pva"][1])
    print("T1's length is not stated; the ruler's T1 is taken over the twin's 3 s. Over other lengths, the rig's laws' "
          "T1 over what their T2 and T3 imply:")
    read = {law: implied_t1(law) for law in LAWS}  # the rig's delays from T2 and T3, as twin validate reads them
    for length in LENGTHS:
        ratio = {law: [rig[law][1] / lagging_rmse(1, d, length=length)[0] for d, _ in read[law]] for law in LAWS}
        others = ratio["ffpva"] + ratio["smc"]
        print(f"  {length:g} s: PVA + DZC x{min(ratio['pva']):.2f}-{max(ratio['pva']):.2f}, FF + PVA and sliding mode "
              f"x{min(others):.2f}-{max(others):.2f}; PVA + DZC's over theirs x{min(ratio['pva']) / max(others):.2f}"
              f"-{max(ratio['pva']) / min(others):.2f}")
    print(f"the delay that gives the rig's PVA + DZC T1 ({rig['pva'][1]:.2f}): {delay * 1e3:.1f} ms, which gives T2 "
          f"{lagging_rmse(2, delay)[0]:.2f} and T3 {lagging_rmse(3, delay)[0]:.2f} (the rig's "
          f"{rig['pva'][2]:.2f} and {rig['pva'][3]:.2f}) and a largest T1 error of {lagging_rmse(1, delay)[1]:.1f}")


if __name__ == "__main__":  # --help says what it runs instead of running it
    argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter).parse_args()
    main()
