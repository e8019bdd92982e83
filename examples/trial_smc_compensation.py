"""Trial (not installed): sliding mode with FF + PVA's dead-zone compensation, a reading of the law the
thesis does not give (its sliding mode has none).

The rig's sliding mode tracked the slow trajectories at 0.75 (T2) and 0.81 (T3) of its FF + PVA; the
twin's tracks them about as FF + PVA does, and misses both cells (x1.45, x1.33) and the controller order
on T2 and T3 (docs/validation.md). On slow motion the feed-forward asks for 8-13 % of duty, inside the
valve's dead zone, and FF + PVA's compensation (eq. 5.3.6: 20-30 % lifted to 30 %) opens the valve at a
smaller error than sliding mode's switching term does. The thesis's sliding mode has no compensation
(§6), and the twin's follows it. Had the rig's code kept FF + PVA's compensation inside sliding mode, its
slow motion would differ. This script runs that what-if two ways:

* ``on the held part``: sliding mode's u_FF+PVA, refreshed once per 16 ms period, compensated as FF +
  PVA's is, before the switching term is added every 1 ms;
* ``on the sum``: the compensation applied every 1 ms to u_FF+PVA plus the switching term;

beside the law as the thesis gives it, on the nine cells sliding mode was measured on (§8's T1-T4, §9's
five T1 payload cells), seeds 0-9, with FF + PVA and PVA + DZC on §8's cells for the controller order. It ran
first (2026-11-27) on the ninth refit's preset, committed then (``twin/plants/data/ninth_refit.json``, the
default); ``--preset tenth`` runs it on the tenth refit's (``twin/plants/data/tenth_refit.json``, digest
1c2dcd8c9f7f; added in stop 39, 2026-11-27, as ``--preset committed``, its first line saying "(committed)", when
the tenth was the committed preset). It also runs the six Chapter 6 T3 cells (0 / 6.5 / 13.5 g, horizontal and
vertical) with both laws, to show what each reading would predict there and which law would lead: a
what-if beside the blind prediction, which stays as committed. Nothing is refitted. The result is
recorded in docs/studies-and-whatifs.md.

About 40 s on 2 cores for either preset.

    python examples/trial_smc_compensation.py [--preset ninth|tenth]
"""

from __future__ import annotations

import argparse
import math

import numpy as np

from controllers import smc
from controllers.ffpva import FeedForwardPVAGains, compensate, ffpva_duty
from controllers.pva import PVAGains
from twin.envs.runner import run_many
from twin.experiments.reference import THESIS_EXPERIMENT_RMSE_DEG, THESIS_PAYLOADS_G, THESIS_ROBUSTNESS_T1_DEG
from twin.experiments.validate import PREDICTION_CELLS, controller_order, rmse_within
from twin.physics.model import Orientation
from twin.plants.as_built import NINTH_REFIT_FILE, TENTH_REFIT_FILE, as_built_plant, calibrated_values, preset_digest
from twin.sim.scenario import Scenario

SEEDS = range(10)
PRESETS = {"ninth": NINTH_REFIT_FILE, "tenth": TENTH_REFIT_FILE}  # which calibration file the trial runs on
BAND = FeedForwardPVAGains(pva=PVAGains()).compensation_band  # %, eq. 5.3.6, FF + PVA's compensation
# (trajectory, payload g, orientation, measured mean RMSE deg): §8's and §9's sliding mode cells
SMC_CELLS = (*((t, 0.0, "horizontal", THESIS_EXPERIMENT_RMSE_DEG["smc"][t][0]) for t in (1, 2, 3, 4)),
             *((1, g, o, THESIS_ROBUSTNESS_T1_DEG["smc", o][g][0]) for o in ("horizontal", "vertical")
               for g in THESIS_PAYLOADS_G if (g, o) != (0.0, "horizontal")))
T3_CELLS = tuple((g, o) for c, _, g, o in PREDICTION_CELLS if c == "smc")  # Chapter 6, held back


def on_the_held_part(self, t, measurement, setpoint):
    del t
    if self._calls % self._slow_every == 0:
        self._held = compensate(ffpva_duty(self.nominal, self.gains.pva, measurement, setpoint), BAND)
    self._calls += 1
    return np.clip(self._held + self.switching(measurement, setpoint), -100.0, 100.0)


def on_the_sum(self, t, measurement, setpoint):
    del t
    if self._calls % self._slow_every == 0:
        self._held = ffpva_duty(self.nominal, self.gains.pva, measurement, setpoint)
    self._calls += 1
    return np.clip(compensate(self._held + self.switching(measurement, setpoint), BAND), -100.0, 100.0)


def mean_rmse(plant, cells: list[tuple[str, int, float, str]]) -> list[float]:
    """Each (controller, trajectory, payload g, orientation) cell's mean RMSE on ``plant`` over :data:`SEEDS`
    (deg), all in one batch."""
    runs = run_many([Scenario(c, t, payload=g * 1e-3, orientation=Orientation(o), plant=plant, seed=s)
                     for c, t, g, o in cells for s in SEEDS])
    rmse = [math.degrees(r.metrics.rmse) for r in runs]
    return [float(np.mean(rmse[i:i + len(SEEDS)])) for i in range(0, len(rmse), len(SEEDS))]


def main(preset: str = "ninth") -> None:
    plant = as_built_plant(calibrated_values(PRESETS[preset]))
    flat = [(law, t, 0.0, "horizontal") for law in ("ffpva", "pva") for t in THESIS_EXPERIMENT_RMSE_DEG[law]]
    base = mean_rmse(plant, flat + [("ffpva", 3, g, o) for g, o in T3_CELLS])
    others, ffpva_t3 = dict(zip(flat, base[:len(flat)], strict=True)), base[len(flat):]
    ffpva = {t: others["ffpva", t, 0.0, "horizontal"] for t in (1, 2, 3, 4)}
    print(f"as-built preset {preset_digest(PRESETS[preset])} ({preset}), seeds 0-9, mean RMSE (deg) and x measured; "
          "FF + PVA T1-T4 "
          + " / ".join(f"{ffpva[t]:.2f}" for t in (1, 2, 3, 4)) + ", PVA + DZC T1-T3 "
          + " / ".join(f"{others['pva', t, 0.0, 'horizontal']:.2f}" for t in (1, 2, 3)))
    print("Chapter 6 T3 (0 / 6.5 / 13.5 g horizontal, then vertical), FF + PVA: "
          + " / ".join(f"{m:.2f}" for m in ffpva_t3))
    as_given = smc.SlidingMode.update
    try:
        for label, update in (("as the thesis gives it", as_given), ("on the held part", on_the_held_part),
                              ("on the sum", on_the_sum)):
            smc.SlidingMode.update = update
            everything = mean_rmse(plant, [("smc", t, g, o) for t, g, o, _ in SMC_CELLS]
                                   + [("smc", 3, g, o) for g, o in T3_CELLS])
            means, t3 = everything[:len(SMC_CELLS)], everything[len(SMC_CELLS):]
            within = sum(bool(rmse_within(m, c[3])) for m, c in zip(means, SMC_CELLS, strict=True))
            ahead = sum(m < ffpva[t] for m, (t, _, _, _) in zip(means[:4], SMC_CELLS[:4], strict=True))
            right = _orders_right({**others, **{("smc", t, 0.0, "horizontal"): means[t - 1] for t in (1, 2, 3, 4)}})
            cells = " | ".join(f"T{t} {g:g} g {o[0].upper()} {m:.2f} x{m / c:.2f}"
                               for m, (t, g, o, c) in zip(means, SMC_CELLS, strict=True))
            print(f"{label:24s} within 20 % {within} of 9, ahead of FF + PVA on {ahead} of 4, order right on "
                  f"{right} of 4 | {cells}", flush=True)
            print(f"{'':24s} T3 sliding mode " + " / ".join(f"{m:.2f}" for m in t3)
                  + f", ahead of FF + PVA on {sum(m < f for m, f in zip(t3, ffpva_t3, strict=True))} of 6",
                  flush=True)
    finally:
        smc.SlidingMode.update = as_given  # the thesis's law back, for whatever runs after


def _orders_right(twin: dict) -> int:
    """On how many of §8's trajectories ``twin`` ((law, trajectory, 0.0, "horizontal") -> mean RMSE) ranks
    the laws as the measured means do (`twin validate`'s ranking)."""
    rows = [{"controller": law, "trajectory": t, "measured": THESIS_EXPERIMENT_RMSE_DEG[law][t][0],
             "twin_mean": twin[law, t, 0.0, "horizontal"]} for law in THESIS_EXPERIMENT_RMSE_DEG
            for t in THESIS_EXPERIMENT_RMSE_DEG[law]]
    measured, ranked = controller_order(rows, "measured"), controller_order(rows, "twin_mean")
    return sum(measured[t] == ranked[t] for t in measured)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--preset", choices=sorted(PRESETS), default="ninth",
                        help="the calibration file to run on (default: the ninth refit's, as first run)")
    main(parser.parse_args().preset)
