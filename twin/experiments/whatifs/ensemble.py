"""What the ensemble what-ifs share (``pva-rate``, ``observer``, ``next-experiment``): the Chapter 6
cells, runs of many cases on every member of the as-built calibration ensemble, and the band.

Each member of the calibration ensemble (:func:`twin.plants.as_built.ensemble_plants`; member 0 has
the committed preset's values) runs every case over the same seeds, in one batch per member, the
members shared out over worker processes. A case's number is its committed-preset value (member
0's mean over the seeds) and its band the 10 / 90 % percentiles of the members' means: the spread
that comes from what the measurements could not pin down, not from the sensor noise.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence

import numpy as np

from twin.exceptions import InvalidScenario
from twin.experiments.reference import ROBUSTNESS_CELLS

BAND_PERCENTILES = (10.0, 90.0)


def study_cells(controllers: Sequence[str] = ("ffpva", "smc")) -> tuple[tuple, ...]:
    """T1-T4 horizontal without payload (Chapter 5), then the Chapter 6 cells that are not among them."""
    first = [(c, t, 0.0, "horizontal") for c in controllers for t in (1, 2, 3, 4)]
    return tuple(first + [cell for cell in ROBUSTNESS_CELLS if cell[0] in controllers and cell not in first])


def cell_scenario(cell: tuple, plant, seed: int):
    """The scenario of ``cell`` (controller, trajectory, payload g, orientation) on ``plant``."""
    from twin.physics.model import Orientation
    from twin.sim.scenario import Scenario

    controller, number, payload_g, orientation = cell
    return Scenario(controller, number, payload=payload_g * 1e-3, orientation=Orientation(orientation), plant=plant,
                    seed=seed)


def cells_batch(plant, cases: tuple, seeds: tuple) -> dict:
    """Every cell of ``cases`` with the controller it names, over ``seeds`` on ``plant``, one batch."""
    from twin.envs.runner import run_many

    jobs = [(case, s) for case in cases for s in seeds]
    results = run_many([cell_scenario(case, plant, s) for case, s in jobs], nthread=1)
    return {job: summarise_run(r) for job, r in zip(jobs, results, strict=True)}


@dataclasses.dataclass(frozen=True)
class Run:
    """What the what-ifs keep of one run (degrees; m/s for the observer's errors)."""

    rmse_deg: float
    failed: bool
    velocity_rms_error: float  # m/s, observer v_hat against the true rack velocity
    acceleration_rms_error: float  # m/s^2, a_hat against the true velocity's difference quotient


def summarise_run(result) -> Run:
    trace = result.trace
    true_acceleration = np.gradient(trace.velocity, trace.time) if len(trace.time) > 1 else np.zeros(1)
    return Run(rmse_deg=math.degrees(result.metrics.rmse), failed=bool(result.warnings),
               velocity_rms_error=float(np.sqrt(np.mean((trace.estimated_velocity - trace.velocity) ** 2))),
               acceleration_rms_error=float(np.sqrt(np.mean((trace.estimated_acceleration - true_acceleration) ** 2))))


def check_members(members: int | None) -> None:
    """``--members``: a calibration file must exist, and N at most its ensemble's size."""
    from twin.plants.as_built import CALIBRATION_FILE

    if not CALIBRATION_FILE.exists():
        raise InvalidScenario("no as-built calibration: run `twin calibrate` first")
    count = member_count()
    if members is not None and members > count:
        raise InvalidScenario(f"--members: the calibration ensemble has {count} members, got {members}")


def add_ensemble_arguments(parser, *, seeds: int, least: int = 1) -> None:
    """``--seeds`` and ``--members``, the flags every ensemble what-if has; ``least``: the fewest of each the
    what-if's ``check`` takes, said in the help."""
    from twin.experiments.arguments import positive_int, seed_count

    at_least = f"; at least {least}" if least > 1 else ""
    parser.add_argument("--seeds", type=seed_count, default=seeds,
                        help=f"noise seeds per case and ensemble member (default {seeds}{at_least})")
    parser.add_argument("--members", type=positive_int, default=None,
                        help=f"only the first N calibration ensemble members (default: all{at_least})")


def members_to_run(members: int | None) -> int:
    """``--members``: the first ``members`` of the ensemble, or all of them."""
    return member_count() if members is None else members


def member_count() -> int:
    from twin.plants.as_built import ensemble_values

    return len(ensemble_values())


def _run_member(batch: Callable, member: int, cases: tuple, seeds: tuple) -> tuple[int, dict]:
    """``batch(plant, cases, seeds)`` on ensemble member ``member``: {(case, seed): Run}; called on parts of at
    most :data:`twin.sim.simulation.RUN_PART` (case, seed) pairs, so that memory holds one part's traces (each
    run is its own: the same numbers as one call). A pair is one run for most batches, more for some (the
    breakaway maps' 8 rest positions a bisection round)."""
    from twin.plants import ENSEMBLE_PREFIX, plant
    from twin.sim.simulation import RUN_PART

    member_plant = plant(f"{ENSEMBLE_PREFIX}{member}")
    seed_part = min(len(seeds), RUN_PART) or 1
    case_part = max(1, RUN_PART // seed_part)
    out: dict = {}
    for c in range(0, len(cases), case_part):
        for s in range(0, len(seeds), seed_part):
            out.update(batch(member_plant, cases[c:c + case_part], seeds[s:s + seed_part]))
    return member, out


def over_ensemble(batch: Callable, cases: Sequence, *, seeds: Sequence[int], workers: int = 2,
                  members: int | None = None, progress: Callable[[], None] | None = None) -> list[dict]:
    """``batch(plant, cases, seeds) -> {(case, seed): Run}`` (a module-level function, so it reaches
    the workers) on every ensemble member (or the first ``members``), members in parallel on
    ``workers`` processes; ``progress()`` after each member. One dict per member, in member order."""
    count = members_to_run(members)
    done: dict[int, dict] = {}
    if workers <= 1:
        for m in range(count):
            done[m] = _run_member(batch, m, tuple(cases), tuple(seeds))[1]
            if progress:
                progress()
    else:
        from twin.batch.sweep import run_forked  # workers die with their parent, and on Ctrl-C

        def finished(result: tuple[int, dict]) -> None:
            done[result[0]] = result[1]
            if progress:
                progress()

        run_forked([(_run_member, (batch, m, tuple(cases), tuple(seeds))) for m in range(count)], workers, finished)
    return [done[m] for m in range(count)]


def run_cases(batch: Callable, cases: Sequence, *, seeds: Sequence[int], members: int | None = None,
              workers: int = 2, bar=None) -> tuple[list[dict], int]:
    """:func:`over_ensemble` with a progress ``bar`` (tqdm, optional) given the number of runs first and
    counting them; also the number of members run."""
    count = members_to_run(members)
    per_member_runs = len(cases) * len(seeds)
    if bar is not None:
        bar.reset(total=count * per_member_runs)
    per_member = over_ensemble(batch, cases, seeds=seeds, workers=workers, members=count,
                               progress=None if bar is None else lambda: bar.update(per_member_runs))
    return per_member, count


def band(per_member: Sequence[dict], case, seeds: Sequence[int], field: str = "rmse_deg") -> dict:
    """The committed preset's value (member 0's seed mean) and the 10 / 90 % band of the members'
    seed means of ``field`` for ``case``."""
    means = member_means(per_member, case, seeds, field)
    low, high = (float(np.percentile(means, q)) for q in BAND_PERCENTILES)
    return {"value": means[0], "p10": low, "p90": high}


def member_means(per_member: Sequence[dict], case, seeds: Sequence[int], field: str = "rmse_deg") -> list[float]:
    """Each member's mean of ``field`` over ``seeds`` for ``case``, in member order."""
    return [float(np.mean([getattr(runs[case, s], field) for s in seeds])) for runs in per_member]


def failed_runs(per_member: Sequence[dict]) -> int:
    return sum(run.failed for runs in per_member for run in runs.values())
