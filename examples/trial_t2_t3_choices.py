"""Trial (not installed): do T2's and T3's lengths and starts, which the thesis does not state, move their cells?

SPEC §7 gives T2 as a ramp at 10 mm/s of rack and T3 as a 0.5 Hz sine of 60 deg amplitude between 20 and
140 deg, nothing more. The twin chose the rest (``twin/physics/trajectories.py``):
- T2 starts at 30 deg, as T1 and T4 do, and ramps for 1 s (120 deg);
- T3 runs two periods (4 s) starting mid-stroke at 80 deg at full speed, because the thesis reports its
  largest error at T3's start.

A start transient weighs less in a longer run, and the start puts the motion on other friction. T2 and
T3 enter the fit (§8's T2 and T3 cells), sliding mode's two largest misses are there (T2 x1.49, T3 x1.30
on the tenth refit's preset), and T3 is the blind prediction's trajectory (its twelve Chapter 6 cells). So
these choices could move a miss or the prediction.

This script runs on the committed as-built preset (the tenth refit's, committed when it ran:
``twin/plants/data/tenth_refit.json``, digest 1c2dcd8c9f7f, so a later refit does not move what it prints) and
seeds 0-4 (the verdicts' seeds):
- T3, §8's PVA + DZC cell and the prediction's twelve cells (FF + PVA's and sliding mode's 0 g horizontal
  ones are §8's too): T3 for 10 s (five periods) from the committed start, read over each run's first 2,
  4, 6, 8 and 10 s (a run does not look ahead, so its first D seconds are a D-second run's: the script
  checks that the first 4 s give the committed runs' errors bit for bit), and T3 for 4 s from the trough,
  20 deg, at rest (80 - 60 cos(pi t) deg), the other natural start;
- T2, §8's three cells: the ramp from 30 deg for 1.2 s (to 174 deg, the friction fit's edge), read over
  its first 0.5, 0.75, 1.0 and 1.2 s, and 1 s ramps from 24 (the fit's lower edge), 40 and 50 deg.

It prints per cell the mean RMSE for each choice, the largest over the smallest, and the runs that stall
(a largest error past ``twin validate``'s 30 deg, its STALL_ERROR_DEG); then, for each T3 choice, in how
many of the six payload and orientation cells sliding mode tracks better than FF + PVA. Nothing is refitted
and the committed trajectories are not changed. The result is recorded in docs/prediction.md and
docs/as-built.md.

    python examples/trial_t2_t3_choices.py
"""

from __future__ import annotations

import argparse
import dataclasses
import math
from collections.abc import Callable

import numpy as np

import twin.sim.simulation as simulation
from twin.envs.runner import run_many
from twin.experiments.reference import THESIS_EXPERIMENT_RMSE_DEG
from twin.experiments.validate import STALL_ERROR_DEG
from twin.physics import trajectories
from twin.physics.model import Orientation
from twin.physics.trajectories import RAMP_SPEED, Reference, Segment, Trajectory
from twin.plants.as_built import TENTH_REFIT_FILE, as_built_plant, calibrated_values
from twin.sim.scenario import Scenario

SEEDS = range(5)
PLANT = as_built_plant(calibrated_values(TENTH_REFIT_FILE))  # named "as-built", as the preset it ran on
COMMITTED_TRAJECTORY = trajectories.trajectory

T3_LONG = 10.0  # s, five periods
T3_WINDOWS = (2.0, 4.0, 6.0, 8.0, 10.0)  # s; 4 is the committed length
T3_LENGTH = 4.0  # s, the committed length
MIDDLE, AMPLITUDE = math.radians(80.0), math.radians(60.0)  # §7's 20 - 140 deg
T3_CELLS = (("pva", 0.0, Orientation.HORIZONTAL),) + tuple(
    (law, grams * 1e-3, side) for law in ("ffpva", "smc") for side in Orientation for grams in (0.0, 6.5, 13.5))

T2_LONG = 1.2  # s, from 30 deg to 174 deg
T2_WINDOWS = (0.5, 0.75, 1.0, 1.2)  # s; 1 is the committed length
T2_LENGTH = 1.0  # s, the committed length
T2_STARTS = (24.0, 40.0, 50.0)  # deg; 30 is the committed start
T2_CELLS = tuple((law, 0.0, Orientation.HORIZONTAL) for law in ("pva", "ffpva", "smc"))


@dataclasses.dataclass(frozen=True)
class FromTrough(Trajectory):
    """A 0.5 Hz sine from its lowest point at rest: ``start`` (the trough) + a (1 - cos(pi t)) over its one
    segment, a = the segment's ``delta``; T3 with start 20 deg and a = 60 deg."""

    def sample(self, t: np.ndarray, spur_radius: float) -> Reference:
        (sine,) = self.segments
        w, a, middle = math.pi, sine.delta, self.start + sine.delta
        inside = t < self.duration
        theta = np.where(inside, middle - a * np.cos(w * t), middle - a * math.cos(w * self.duration))
        omega = np.where(inside, a * w * np.sin(w * t), 0.0)
        alpha = np.where(inside, a * w * w * np.cos(w * t), 0.0)
        return Reference(position=theta * spur_radius, velocity=omega * spur_radius, acceleration=alpha * spur_radius)


def runs(number: int, cells, make: Callable[[float], Trajectory] | None = None) -> list[list]:
    """Every cell's runs of trajectory ``number`` on :data:`SEEDS`, that trajectory as ``make(spur_radius)``
    gives it (None: the committed one)."""
    def patched(n: int, *, spur_radius: float) -> Trajectory:
        return make(spur_radius) if n == number else COMMITTED_TRAJECTORY(n, spur_radius=spur_radius)

    simulation.trajectory = COMMITTED_TRAJECTORY if make is None else patched
    try:
        flat = run_many([Scenario(law, number, payload=m, orientation=side, plant=PLANT, seed=s)
                         for law, m, side in cells for s in SEEDS])
    finally:
        simulation.trajectory = COMMITTED_TRAJECTORY
    return [flat[i:i + len(SEEDS)] for i in range(0, len(flat), len(SEEDS))]


def errors(cell_runs: list) -> np.ndarray:
    """Each run's tracking error at every tick (rad), runs by ticks."""
    return np.array([r.trace.desired_angle - r.scored_angle for r in cell_runs])


def window_rmses(cell_runs: list, windows: tuple[float, ...]) -> list[float]:
    """The runs' mean RMSE (deg) over their first ``seconds``, for each of ``windows``."""
    time, error = cell_runs[0].trace.time, errors(cell_runs)
    return [float(np.mean(np.degrees(np.sqrt(np.mean(np.square(error[:, time < seconds - 1e-9]), axis=1)))))
            for seconds in windows]


def mean_rmse(cell_runs: list) -> float:
    return float(np.mean([math.degrees(r.metrics.rmse) for r in cell_runs]))


def stalled(cell_runs: list) -> int:
    """Runs whose largest error passes :data:`STALL_ERROR_DEG`."""
    return sum(math.degrees(r.metrics.max_error) > STALL_ERROR_DEG for r in cell_runs)


def windows_give_the_runs(long: list[list], plain: list[list]) -> bool:
    """Whether each long run's first ticks are the committed run's errors, bit for bit."""
    def same(lo: list, p: list) -> bool:
        short = errors(p)
        return np.array_equal(errors(lo)[:, :short.shape[1]], short)

    return all(same(lo, p) for lo, p in zip(long, plain, strict=True))


def row(law: str, mass: float, side: Orientation, number: int, values: list[float], stalls: int) -> str:
    """One cell's printed line: its mean RMSEs, their spread, the stalls and, for a §8 cell, x the rig's."""
    text = (f"{law} T{number} {mass * 1e3:g} g {side.name.lower()}: " + " / ".join(f"{v:.2f}" for v in values)
            + f" | x{max(values) / min(values):.3f} | stalled {stalls}")
    if mass == 0.0 and side is Orientation.HORIZONTAL:
        rig = THESIS_EXPERIMENT_RMSE_DEG[law][number][0]
        committed = values[T3_WINDOWS.index(T3_LENGTH) if number == 3 else T2_WINDOWS.index(T2_LENGTH)]
        text += f" | the rig {rig:.2f}: x{committed / rig:.2f} as committed, x{min(values) / rig:.2f}-x{max(values) / rig:.2f}"
    return text


def t3() -> None:
    plain = runs(3, T3_CELLS)
    long = runs(3, T3_CELLS, lambda r: Trajectory(3, MIDDLE, (Segment("sine", T3_LONG, AMPLITUDE),)))
    trough = runs(3, T3_CELLS, lambda r: FromTrough(3, MIDDLE - AMPLITUDE, (Segment("sine", T3_LENGTH, AMPLITUDE),)))
    print(f"T3: the 10 s runs' first 4 s give the committed runs bit for bit: {windows_give_the_runs(long, plain)}")
    print("T3, as-built, seeds 0-4: mean RMSE (deg) over the first 2 / 4 (committed) / 6 / 8 / 10 s, then from "
          "the trough (4 s); the largest over the smallest; stalled runs of the 10 s and trough runs")
    table = {}
    for cell, lo, tr in zip(T3_CELLS, long, trough, strict=True):
        table[cell] = window_rmses(lo, T3_WINDOWS) + [mean_rmse(tr)]
        print(row(*cell, 3, table[cell], stalled(lo) + stalled(tr)), flush=True)
    choices = [f"{w:g} s" for w in T3_WINDOWS] + ["trough"]
    leads = []
    for k, choice in enumerate(choices):
        ahead = sum(table["smc", m, side][k] < table["ffpva", m, side][k] for _, m, side in T3_CELLS[1:7])
        leads.append(f"{choice} {ahead}")
    print("T3, sliding mode ahead of FF + PVA in how many of the 6 cells: " + " / ".join(leads))


def t2() -> None:
    plain = runs(2, T2_CELLS)
    long = runs(2, T2_CELLS, lambda r: Trajectory(2, trajectories.START, (Segment("ramp", T2_LONG, RAMP_SPEED * T2_LONG / r),)))
    starts = [runs(2, T2_CELLS, lambda r, s=s: Trajectory(2, math.radians(s), (Segment("ramp", T2_LENGTH, RAMP_SPEED * T2_LENGTH / r),)))
              for s in T2_STARTS]
    print(f"T2: the 1.2 s runs' first 1 s give the committed runs bit for bit: {windows_give_the_runs(long, plain)}")
    print("T2, as-built, seeds 0-4: mean RMSE (deg) over the first 0.5 / 0.75 / 1 (committed) / 1.2 s from 30 "
          "deg, then 1 s from 24 / 40 / 50 deg; the largest over the smallest; stalled runs of all")
    for i, cell in enumerate(T2_CELLS):
        values = window_rmses(long[i], T2_WINDOWS) + [mean_rmse(s[i]) for s in starts]
        print(row(*cell, 2, values, stalled(long[i]) + sum(stalled(s[i]) for s in starts)), flush=True)


def main() -> None:
    t3()
    t2()


if __name__ == "__main__":  # --help says what it runs instead of running it
    argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter).parse_args()
    main()
