"""Trial (not installed): discharge pulses that end at their exact duty instead of on the 1 ms tick.

The twin switches each coil on the DAQ's 1 ms tick, so a held duty d opens the discharge coil for
rint(d x 16 / 100) ticks of the 16 ms period, and a pulse opens the valve from 28.1 %. If the rig's PWM
ended each pulse at its exact duty, the threshold would be the valve's own 26 %. This script runs the
eighth refit's values (``examples/eighth_refit.json``, the committed preset when it first ran, 2026-11-25) both
ways (FF + PVA and sliding mode, T1-T4, seeds 0-9) by swapping the two compiled valve kernels for sub-tick
versions, and prints the mean RMSE per trajectory (deg). The result is recorded in docs/investigations.md; a slow
test in tests/experiments/test_trials_effects.py holds the printed numbers.

About 10 s on 2 cores.

    python examples/trial_subtick_coil.py
"""

from __future__ import annotations

import argparse
import json
import math
import pathlib

import numba
import numpy as np

import twin.physics.solenoid as solenoid
import twin.physics.valves as valves
from twin.envs.runner import run_many
from twin.plants.as_built import as_built_plant
from twin.sim.scenario import Scenario

# The preset this script's numbers in docs/investigations.md were measured on: the eighth refit's values, kept beside
# the scripts since the ninth refit (2026-11-26) replaced it as the committed preset.
EIGHTH_REFIT = json.loads(pathlib.Path(__file__).with_name("eighth_refit.json").read_text())["fitted"]

SEEDS = range(10)
TRAJECTORIES = (1, 2, 3, 4)


@numba.njit(cache=False)
def _coils_subtick(duty, tick, duty_steps, period_ticks, coil):  # pragma: no cover - compiled
    """As valves._solenoid_coils, but the discharge coil's value is the fraction of this tick it is on."""
    for i in range(duty.shape[0]):
        magnitude = min(abs(duty[i]), 100.0)
        on = np.rint(magnitude / 100.0 * duty_steps) * (100.0 / duty_steps) > 0.0
        fraction = min(max(magnitude / 100.0 * period_ticks - tick % period_ticks, 0.0), 1.0) if on else 0.0
        supply = 1.0 if on else 0.0
        coil[i, 0] = supply if duty[i] > 0 else 0.0
        coil[i, 1] = fraction if duty[i] < 0 else 0.0
        coil[i, 2] = supply if duty[i] < 0 else 0.0
        coil[i, 3] = fraction if duty[i] > 0 else 0.0


@numba.njit(cache=False)
def _openings_subtick(coil, substeps, h, tau_on, tau_off, force_ratio, gap_ratio, spring_ratio, omega, zeta, state,
                      opening, live):  # pragma: no cover - compiled
    """As solenoid.tick_openings, with each coil on for the first fraction of the tick's sub-steps."""
    rise, fall = 1.0 - math.exp(-h / tau_on), 1.0 - math.exp(-h / tau_off)
    for a in range(coil.shape[0]):
        if not live[a]:
            opening[a, :] = 0.0
            continue
        for b in range(coil.shape[1]):
            on_steps = int(round(coil[a, b] * substeps))
            i, x, v = state[a, b, 0], state[a, b, 1], state[a, b, 2]
            total = 0.0
            for k in range(substeps):
                s = 1.0 if k < on_steps else 0.0
                i, x, v = solenoid._step(s, i, x, v, h, rise, fall, force_ratio, gap_ratio, spring_ratio, omega,
                                         zeta)
                total += x
            state[a, b, 0], state[a, b, 1], state[a, b, 2] = i, x, v
            opening[a, b] = total / substeps


def mean_rmse(plant) -> dict[tuple[str, int], float]:
    keys = [(c, t) for c in ("ffpva", "smc") for t in TRAJECTORIES]
    results = run_many([Scenario(c, t, plant=plant, seed=s) for c, t in keys for s in SEEDS])
    n = len(SEEDS)
    return {key: float(np.mean([math.degrees(r.metrics.rmse) for r in results[k * n:(k + 1) * n]]))
            for k, key in enumerate(keys)}


def main() -> None:
    plant = as_built_plant(EIGHTH_REFIT)
    ticks = mean_rmse(plant)
    original = valves._solenoid_coils, solenoid.tick_openings
    valves._solenoid_coils, solenoid.tick_openings = _coils_subtick, _openings_subtick
    try:
        subtick = mean_rmse(plant)
    finally:
        valves._solenoid_coils, solenoid.tick_openings = original
    for name, table in (("whole ticks", ticks), ("sub-tick", subtick)):
        print(f"{name:12s}", "  ".join(f"{c} " + " / ".join(f"{table[(c, t)]:.2f}" for t in TRAJECTORIES)
                                      for c in ("ffpva", "smc")))


if __name__ == "__main__":  # --help says what it runs instead of running it
    argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter).parse_args()
    main()
