"""Trial (not installed): could a lag between the controller and the valves explain PVA + DZC's T1?

The rig's PVA + DZC tracked T1 at 4.20 deg with a 13.5 deg largest error, and T2 and T3 at 2.93 and
3.00; the twin's tracks T1 at about 1.7 deg and T2 and T3 within 8 % (docs/investigations.md). A laboratory
DAQ may put its outputs out some samples after it reads its inputs. The thesis gives no such lag, and
the twin's loop has none: the duty computed from tick k's sample drives the coils from tick k on.

This script delays the coils' whole signal by ``d`` ticks (1 ms each): the coils at tick k get the
signal the undelayed loop would give them at tick k - d (the duty in force then, at that tick's place
in the 16 ms PWM period), and are shut for the first d ticks. The controllers, sensors and hydraulics
run at tick k as before; only what reaches the coils is late, for all three laws alike (a lag of the
rig's, not of one law). It runs §8's eleven experimental cells on the ninth refit's as-built preset (``twin/plants/data/ninth_refit.json``, the committed one when this ran), seeds
0-9, for each delay, and prints per cell the mean RMSE, the mean largest error and the ratio to the
measured mean, then PVA + DZC's T1 error over the move and over the hold, its SSE ranges and how far
off its runs end. With d = 0 the delayed runs are the plain runs to the last bit; the script checks
that first. Nothing is refitted around the delay. The result is recorded in docs/investigations.md.

(A first version of this trial delayed the duty at the controller instead. With the PWM period's phase
fixed to the tick, that did not delay a 16 ms law's pulses, only cut or stretched their first ticks; a
review caught it on 2026-11-27 before the result was kept.)

About 1 min on 2 cores.

    python examples/trial_actuation_delay.py
"""

from __future__ import annotations

import argparse
import math
import pathlib
import sys

import numpy as np

from twin.envs.runner import run_many
from twin.physics.valves import ValveBank
from twin.plants.as_built import NINTH_REFIT_FILE, as_built_plant, calibrated_values
from twin.sim.scenario import Scenario

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))  # the sibling modules, however this one is loaded
from trial_t1_start import t1_move_hold_sse  # noqa: E402

SEEDS = range(10)
DELAYS = (0, 1, 2, 3, 4, 5, 6, 8)  # ticks of 1 ms
CELLS = (("pva", 1), ("pva", 2), ("pva", 3), ("ffpva", 1), ("ffpva", 2), ("ffpva", 3), ("ffpva", 4),
         ("smc", 1), ("smc", 2), ("smc", 3), ("smc", 4))
PLAIN_UPDATE = ValveBank.update  # the valves as they are
PLANT = as_built_plant(calibrated_values(NINTH_REFIT_FILE))


def lagged(delay: int):
    """A ``ValveBank.update`` whose coils get, at tick k, the signal of tick k - ``delay``: the bank's
    own update called with that tick (which places it in the PWM period) and that tick's duty. The
    plungers and the flow are still integrated through tick k."""
    update = PLAIN_UPDATE

    def late(self, tick, duty, live=None):
        history = self.__dict__.setdefault("_sent", {})
        history[tick] = np.array(duty, dtype=float)
        earlier = tick - delay
        if earlier < 0:
            return update(self, tick, np.zeros_like(history[tick]), live)
        return update(self, earlier, history.pop(earlier), live)

    return late


def runs(delay: int | None) -> list:
    """Every cell's runs in one batch; ``delay`` None: the valves as they are, unpatched."""
    scenarios = [Scenario(c, t, plant=PLANT, seed=s) for c, t in CELLS for s in SEEDS]
    if delay is None:
        return run_many(scenarios)
    ValveBank.update = lagged(delay)
    try:
        return run_many(scenarios)
    finally:
        ValveBank.update = PLAIN_UPDATE  # the valves back as they are, for whatever runs after


def main() -> None:
    from twin.experiments.reference import THESIS_EXPERIMENT_RMSE_DEG
    from twin.experiments.validate import rmse_within

    plain, unlagged = runs(None), runs(0)
    same = all(np.array_equal(a.trace.angle, b.trace.angle) and np.array_equal(a.trace.valve_open, b.trace.valve_open)
               for a, b in zip(plain, unlagged, strict=True))
    print(f"delay 0 gives the plain runs bit for bit: {same}")
    print("as-built, seeds 0-9: mean RMSE (mean largest error) and x the measured mean, per cell (deg)")
    for delay in DELAYS:
        results = unlagged if delay == 0 else runs(delay)
        parts, within = [], 0
        for i, (controller, trajectory) in enumerate(CELLS):
            cell = results[i * len(SEEDS):(i + 1) * len(SEEDS)]
            rmse = float(np.mean([math.degrees(r.metrics.rmse) for r in cell]))
            largest = float(np.mean([math.degrees(r.metrics.max_error) for r in cell]))
            measured = THESIS_EXPERIMENT_RMSE_DEG[controller][trajectory][0]
            within += rmse_within(rmse, measured)
            parts.append(f"{controller} T{trajectory} {rmse:.2f} ({largest:.1f}) x{rmse / measured:.2f}")
        print(f"delay {delay} ms: within 20 % {within} of {len(CELLS)} | " + " | ".join(parts)
              + " | pva T1 " + _t1_ending(results[:len(SEEDS)]), flush=True)


def _t1_ending(runs: list) -> str:
    """PVA + DZC's T1: the RMS error over the move (0-1 s) and over the hold (from 1 s), the SSE ranges of
    seeds 0-4 and 5-9 (the rig's: ±0.41), the smallest and largest |SSE| of the runs, and how many end
    more than 1 deg off."""
    move, hold, sse, ranges = t1_move_hold_sse(runs)
    return (f"move {move:.2f} hold {hold:.2f} SSE {ranges}, runs end {np.nanmin(np.abs(sse)):.2f}-"
            f"{np.nanmax(np.abs(sse)):.2f} off, {int(np.sum(np.abs(sse) > 1.0))} of {len(sse)} over 1 deg")


if __name__ == "__main__":  # --help says what it runs instead of running it
    argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter).parse_args()
    main()
