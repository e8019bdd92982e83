"""Trial (not installed): what stopping the hydraulics of a batch's ended runs saves, as a ratio in one run.

A batch steps every scenario's solenoid valves and chambers each tick; since 2026-11-26 a run that has
ended (its trace is cut at its length) is no longer advanced (``PlantState(idle_after_end=True)``, which
``twin.sim.simulation.simulate`` asks for). This script times one calibration worker's share of an
evaluation (the 21 fitted cells x 5 seeds in one batch: 13 of the cells are 3 s T1 runs beside 6 s T4 ones)
with the ended runs idle and with them run on to the batch's end, alternately, ``REPEATS`` times each, and
prints the CPU times (less moved by other jobs on a shared machine than wall time), their ratio (fastest over
fastest, and each pair's) and whether every RMSE is the same bits. It runs the tenth refit's fitted values
(``twin/plants/data/tenth_refit.json``, digest 1c2dcd8c9f7f; first run on 2026-11-26 on the preset committed
then), so a later refit does not change what it times.

    python examples/trial_idle_after_end.py
"""

from __future__ import annotations

import argparse
import time

import twin.sim.simulation as simulation
from twin.experiments import calibrate
from twin.plants.as_built import TENTH_REFIT_FILE, calibrated_values
from twin.sim.plant_state import PlantState

REPEATS = 5
SEEDS = range(5)


def running_on(**kwargs) -> PlantState:
    return PlantState(**{**kwargs, "idle_after_end": False})


def main() -> None:
    values = calibrated_values(TENTH_REFIT_FILE)
    jobs = [(*key, seed) for key in calibrate.CELLS for seed in SEEDS]
    calibrate._run_cells(values, [(*key, 0) for key in calibrate.CELLS])  # compile, build every cell's model
    times: dict[str, list[float]] = {"idle": [], "run on": []}  # CPU seconds of this process
    rmse = {}
    for _ in range(REPEATS):
        for name, factory in (("run on", running_on), ("idle", PlantState)):
            simulation.PlantState = factory
            started = time.process_time()
            rows = calibrate._run_cells(values, jobs)
            times[name].append(time.process_time() - started)
            rmse[name] = [row[5] for row in rows]
    simulation.PlantState = PlantState
    pairs = [on / idle for on, idle in zip(times["run on"], times["idle"], strict=True)]
    print({name: [round(t, 2) for t in ts] for name, ts in times.items()})
    print(f"run on / idle, CPU time: fastest over fastest {min(times['run on']) / min(times['idle']):.2f}, "
          f"pairs {min(pairs):.2f}-{max(pairs):.2f}; same RMSE bits: {rmse['idle'] == rmse['run on']}")


if __name__ == "__main__":  # --help says what it runs instead of running it
    argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter).parse_args()
    main()
