"""``twin calibrate``: fit the as-built parameters the thesis does not give to every
measurement the twin may see: the experimental Chapter 5 table (SPEC §8) and the measured T1
cells of the Chapter 6 robustness study (§9). The T3 cells of Chapter 6 are held back for a
blind prediction and never enter.

Targets (:data:`TARGETS`): the mean RMSE of each cell (§8: PVA T1-T3, FF + PVA T1-T4, sliding
mode T1-T4, horizontal, no payload; §9: FF + PVA and sliding mode T1 with 0, 6.5 and 13.5 g,
horizontal and vertical, the two cells §8 already has counted once) and the T1 steady-error
range of each T1 cell. Residuals::

    r = ln(RMSE_twin / RMSE_exp)                       per cell
    r = sqrt(SSE_WEIGHT) * ln(range_twin / range_exp)  per T1 cell

with RMSE_twin the mean over the fit's noise seeds (:data:`FIT_SEEDS`) and range_twin the largest
|SSE| of five runs (the thesis's "+-"), averaged over the seeds taken five at a time
(:attr:`CellResult.sse_range`). Cost: the Cauchy loss ``sum of c^2 ln(1 + (r / c)^2)`` with its
scale c at the tolerance, ln 1.2: the squared residual near the table, an influence falling off
as 1/r far out, so a cell no plausible parameter reaches cannot steer the others. A run with
MuJoCo warnings adds 1. A stalled run needs no special term: its RMSE is tens of degrees.

Physical bounds enter as the box (:data:`twin.plants.as_built.FITTED`): the breakaway's top is
what §4.5.1's start from rest at 245 kPa allows, and the CCW Coulomb scale's top what the same runs'
slowest rack speed allows (eq. 4.3.6's steady state). Every §9 run lifted its payload; that enters
through the vertical cells' RMSE (a stalled twin run misses by a factor of ten).

Search, deterministic (the same code and seeds give the same file):

1. a scrambled Sobol design of :data:`SCAN_POINTS` points over the unit box (seed
   :data:`SCAN_SEED`), plus its centre;
2. Nelder-Mead from the best of them, at most :data:`SIMPLEX_EVALUATIONS` evaluations;
3. further starts: the values of :func:`previous_fits` (earlier fits: the ninth and tenth refits',
   four trial refits with the chambers' start pressure held at 0, 0.25, 0.75 and 1.0 of the
   supply, the ten sets of the start-angle trial's fits that cost less than the eleventh
   refit's cut from the committed start, and the three sets of the load-friction profile trial,
   the other parameters refitted, that cost less than the twelfth refit's cut), evaluated on the fit seeds like any other, so that a set
   known to fit is not lost to the ensemble because the profiles, one parameter at a time about the
   best, never reach it, and so that the noise and the profiles are taken about the best of them if
   one beats the search;
4. the seed-to-seed noise of the best cost: the best values so far on :data:`NOISE_SEED_SETS`
   (each as many seeds as the fit, disjoint), noise = the sample std of those costs and the fit's;
5. profiles (:data:`PROFILED`): the best values with the load friction at :data:`PROFILE_POINTS`
   points across its box, then the best of all so far with the breakaway likewise (the two the
   vertical predictions turn on), then with the observer gain likewise, then with the CCW Coulomb
   scale, then with the chambers' free air, then with their start pressure; the fitted values are
   then the lowest cost of all evaluations (a profile point may beat the simplex);
6. the ensemble: every evaluated parameter set whose cost is within the noise of the best
   (cost <= best + noise), at most :data:`ENSEMBLE_MAX` of them (the best first, then the
   lowest and highest of each profiled parameter, then by cost).
"""

from __future__ import annotations

import dataclasses
import importlib.resources
import json
import math
import os
import pathlib
import time
from collections.abc import Callable, Sequence

import numpy as np

from twin.batch.stops import raise_if_stopped
from twin.batch.sweep import code_version, fork_pool, kill_pool
from twin.experiments.base import named_error
from twin.experiments.reference import (
    THESIS_EXPERIMENT_RMSE_DEG,
    THESIS_EXPERIMENT_SSE_T1_RANGE_DEG,
    THESIS_ROBUSTNESS_T1_DEG,
)
from twin.plants.as_built import ASSUMED, FITTED, NINTH_REFIT_FILE, TENTH_REFIT_FILE, as_built_plant, calibrated_values
from twin.sim.metrics import spread
from twin.sim.scenario import Scenario

THESIS_RUNS = 5  # runs per cell in the thesis's tables
SSE_WEIGHT = 0.25
LOSS_SCALE = math.log(1.2)  # the Cauchy loss's scale: the tolerance, "within 20 %"
FIT_SEEDS = tuple(range(10))  # noise seeds every evaluation sees (two five-run groups per cell)
CHECK_SEEDS = (0, 1, 2, 3, 4)  # the thesis's five runs, for the residual table (cut from the fit's runs)
NOISE_SEED_SETS = (tuple(range(10, 20)), tuple(range(20, 30)), tuple(range(30, 40)))  # for the cost's noise
SCAN_POINTS = 16  # Sobol points (a power of two)
SCAN_SEED = 0
SIMPLEX_EVALUATIONS = 24
PROFILE_POINTS = 5  # per profiled parameter
# In this order; the vertical payload cells turn on the first two, sliding mode and the T1 endings on the third;
# the fourth, the CCW friction, moves the cells little (on the eighth refit a scale of 1.1 cost 0.564 against the
# best's 0.551 at 1.299, noise 0.173: found 2026-11-26, after that fit), so its spread belongs in the band.
# The fifth, the air, turns which law leads on T3 (docs/prediction.md); profiled since 2026-11-27, when its box
# was widened to 0-8 % (twin.plants.as_built.FITTED). The sixth, the chambers' start pressure, moves the 13.5 g
# vertical T3 cells past their band at about the same cost (docs/prediction.md); fitted and profiled since 2026-11-28.
PROFILED = ("load_friction", "stiction", "observer_gain", "ccw_coulomb_scale", "air_fraction",
            "initial_pressure_fraction")
ENSEMBLE_MAX = 1 + 2 * len(PROFILED)  # the best and each profiled parameter's two extremes
FILE_VERSION = 11  # 4: the solenoid valve, §9's T1 cells, the ensemble and the noise; 5: the load friction;
# 6: the observer gain; 7: the CCW scale's top from §4.5.1's slowest full-duty speed, and profiled;
# 8: the air's box 0-8 % and profiled, and the second start (previous_fits); 9: the chambers' start pressure
# fitted and profiled, six further starts, evaluated before the noise and the profiles; 10: sixteen further starts;
# 11: nineteen further starts
# File version 8's second start: the ninth refit's fitted values (file version 7, 2026-11-26;
# twin.plants.as_built.NINTH_REFIT_FILE), the best of the same search with the air's box 0-3 %. They cost 0.5587 on
# the fit seeds; the search with the box at 0-8 % settles at 4.6 % air for 0.5367, with a noise of 0.139, and its
# profiles alone put no set with less than 3.98 % air in the ensemble (its 2 % point costs 0.83). Added 2026-11-27,
# after seeing that (docs/calibration-history.md). Since file version 9 (2026-11-28) the tenth refit's fitted values
# and the four trial refits at fixed start pressures are starts too, chosen before this search first ran (the
# start-angle trial's fits are not: they were made with T1, T2 and T4 from another angle). Since file version 10
# (2026-11-28, stop 45) those fits' members are starts too where, run from the committed 30 deg, they cost less than
# the eleventh refit's cut (START_ANGLE_REFITS_FILE): the start-angle trial had found one (load friction 0.365,
# 13.5 g vertical T3 cells 4.10 / 3.82 deg) that fits as well but that the search had not reached, so the
# ensemble's edge was the search's. Chosen after seeing that, with no T3 measurement seen; the members over that
# cut are left out because this search, which evaluates the same best first, cannot take them into its ensemble
# unless one beat the best (0.5239), and none comes near it (of those over the cut the lowest costs 0.6506).
# Since file version 11 (2026-11-28, stop 46) three more: the load-friction profile trial's refits under the twelfth
# refit's cut (PROFILE_REFITS_FILE; load friction 0.40, 0.45 and 0.05 N/N, the other six refitted at each). The
# profiles here move one parameter with the others held; that trial refitted the others and found sets that fit as
# well with the load friction well past the ensemble's 0.15-0.36, and the 13.5 g vertical T3 cells with it. Chosen
# after seeing that, with no T3 measurement seen.
START_PRESSURE_REFITS_FILE = importlib.resources.files("twin.plants") / "data" / "start_pressure_refits.json"
START_ANGLE_REFITS_FILE = importlib.resources.files("twin.plants") / "data" / "start_angle_refits.json"
PROFILE_REFITS_FILE = importlib.resources.files("twin.plants") / "data" / "profile_refits.json"


def previous_fits() -> tuple[dict[str, float], ...]:
    """The further starts' parameter sets, in this order: the ninth and the tenth refits' fitted values (read from
    their kept files, so with the chambers at half the supply, as fitted), then the four start-pressure trial refits'
    (:data:`START_PRESSURE_REFITS_FILE`, each with its fraction), then the ten start-angle trial members'
    (:data:`START_ANGLE_REFITS_FILE`), then the three load-friction profile refits' (:data:`PROFILE_REFITS_FILE`)."""
    trials = [*json.loads(START_PRESSURE_REFITS_FILE.read_text())["starts"],
              *json.loads(START_ANGLE_REFITS_FILE.read_text())["starts"],
              *json.loads(PROFILE_REFITS_FILE.read_text())["starts"]]
    return (calibrated_values(NINTH_REFIT_FILE), calibrated_values(TENTH_REFIT_FILE),
            *({f.name: float(t["values"][f.name]) for f in FITTED} for t in trials))


@dataclasses.dataclass(frozen=True)
class Target:
    """One measured cell: mean RMSE of five runs and its std, and (T1) the steady-error range, in degrees."""

    source: str  # "chapter 5 experiment" or "chapter 6 T1"
    controller: str
    trajectory: int
    payload_g: float
    orientation: str  # "horizontal" or "vertical"
    rmse_deg: float
    rmse_std_deg: float
    sse_range_deg: float | None  # +- max |SSE|, T1 only

    @property
    def key(self) -> tuple[str, int, float, str]:
        return self.controller, self.trajectory, self.payload_g, self.orientation


def _targets() -> tuple[Target, ...]:
    targets = [Target("chapter 5 experiment", c, t, 0.0, "horizontal", mean, std,
                      THESIS_EXPERIMENT_SSE_T1_RANGE_DEG[c] if t == 1 else None)
               for c, row in THESIS_EXPERIMENT_RMSE_DEG.items() for t, (mean, std) in row.items()]
    seen = {target.key for target in targets}
    for (controller, orientation), row in THESIS_ROBUSTNESS_T1_DEG.items():
        for payload_g, (mean, std, sse) in row.items():
            if (controller, 1, payload_g, orientation) not in seen:  # §9's 0 g horizontal row is §8's again
                targets.append(Target("chapter 6 T1", controller, 1, payload_g, orientation, mean, std, sse))
    return tuple(targets)


TARGETS = _targets()
CELLS = tuple(t.key for t in TARGETS)  # (controller, trajectory, payload g, orientation)
EXPERIMENT_CELLS = tuple(t.key for t in TARGETS if t.source == "chapter 5 experiment")  # §8's table alone
TARGET_OF = {t.key: t for t in TARGETS}  # cell key -> its Target


@dataclasses.dataclass(frozen=True)
class CellResult:
    controller: str
    trajectory: int
    rmse_deg: tuple[float, ...]  # per seed
    sse_deg: tuple[float, ...]  # per seed (nan when the trajectory ends moving)
    failed_seeds: tuple[int, ...] = ()  # the seeds of the runs with warnings
    seeds: tuple[int, ...] = ()  # of rmse_deg and sse_deg, in order
    payload_g: float = 0.0
    orientation: str = "horizontal"
    max_error_deg: tuple[float, ...] = ()  # per seed

    @property
    def key(self) -> tuple[str, int, float, str]:
        return self.controller, self.trajectory, self.payload_g, self.orientation

    @property
    def failed(self) -> int:
        return len(self.failed_seeds)

    @property
    def mean_rmse(self) -> float:
        return spread(self.rmse_deg).mean

    @property
    def sse_ranges(self) -> list[float]:
        """The thesis's "+-", the largest |SSE| of five runs, for each five runs in seed order; a last
        group of fewer than five is left out. With fewer than five runs in all, the largest of those
        (which understates a five-run range). Groups whose runs all end moving (nan) are left out."""
        groups = [self.sse_deg[i:i + THESIS_RUNS] for i in range(0, len(self.sse_deg), THESIS_RUNS)]
        whole = [g for g in groups if len(g) == THESIS_RUNS] or groups
        return [float(np.nanmax(np.abs(g))) for g in whole if not all(math.isnan(s) for s in g)]

    @property
    def sse_range(self) -> float:
        """The mean of :attr:`sse_ranges` (the largest of twenty runs would overstate what five runs
        show); nan if every group ends moving."""
        ranges = self.sse_ranges
        return float(np.mean(ranges)) if ranges else math.nan


def values_at(u: Sequence[float]) -> dict[str, float]:
    """Parameter values at unit coordinates ``u`` (clipped into the box)."""
    return {f.name: f.low + float(np.clip(x, 0.0, 1.0)) * (f.high - f.low) for f, x in zip(FITTED, u, strict=True)}


def unit_of(values: dict[str, float]) -> tuple[float, ...]:
    """The unit coordinates of ``values`` (the inverse of :func:`values_at` inside the box)."""
    return tuple((values[f.name] - f.low) / (f.high - f.low) for f in FITTED)


def _run_cells(values: dict[str, float], jobs: list[tuple], without: tuple[str, ...] = ()) -> list[tuple]:
    from twin.envs.runner import thesis_controllers
    from twin.physics.model import Orientation
    from twin.sim.simulation import simulate_in_parts

    plant = as_built_plant(values, name="as-built-fit", without=without)
    scenarios = [Scenario(c, t, payload=g * 1e-3, orientation=Orientation(o), plant=plant, seed=s)
                 for c, t, g, o, s in jobs]
    numbers = simulate_in_parts(scenarios, controllers=thesis_controllers(scenarios), nthread=1, keep=lambda r: (
        math.degrees(r.metrics.rmse), math.degrees(r.metrics.sse), bool(r.warnings), math.degrees(r.metrics.max_error)))
    return [(*job[:4], job[4], *kept) for job, kept in zip(jobs, numbers, strict=True)]


class Evaluator:
    """Runs the target cells for parameter values over ``seeds``, on ``workers`` processes."""

    def __init__(self, *, seeds: Sequence[int], workers: int, cells: Sequence[tuple] = CELLS):
        self.seeds, self.workers, self.keys = tuple(seeds), workers, tuple(cells)
        self.pool = fork_pool(workers) if workers > 1 else None  # as a sweep's: Ctrl-C is the parent's

    def __enter__(self) -> Evaluator:
        return self

    def __exit__(self, kind, error, traceback) -> None:
        """The ``with`` block's end: :meth:`close` when its work is done, :meth:`abort` when it failed or
        was stopped."""
        if kind is None:
            self.close()
        else:
            self.abort()

    def close(self) -> None:
        """Let the workers finish and go (the work is done)."""
        if self.pool is not None:
            self.pool.shutdown()

    def abort(self) -> None:
        """Stop the workers now, without waiting for the share each may be running (on Ctrl-C, SIGTERM or
        an error: nobody will read it)."""
        if self.pool is not None:
            kill_pool(self.pool)

    def cells(self, values: dict[str, float], *, without: Sequence[str] = (), seeds: Sequence[int] | None = None,
              keys: Sequence[tuple] | None = None) -> list[CellResult]:
        """The cells (this evaluator's, or ``keys``) with the as-built plant at ``values`` (minus the effects
        in ``without``), on this evaluator's seeds or on ``seeds``."""
        keys = self.keys if keys is None else tuple(keys)
        jobs = [(*key, s) for key in keys for s in (self.seeds if seeds is None else seeds)]
        # Interleave so every worker gets a like mix of long and short runs.
        shares = [share for share in (jobs[i::self.workers] for i in range(self.workers)) if share]
        off = tuple(without)
        if self.pool is None:
            rows = _run_cells(values, jobs, off)
        else:
            rows = [row for part in self.pool.map(_run_cells, [values] * len(shares), shares, [off] * len(shares))
                    for row in part]
        found: dict[tuple, list] = {}
        for row in sorted(rows, key=lambda row: (row[:4], row[4])):
            found.setdefault(tuple(row[:4]), []).append(row[4:])
        return [CellResult(key[0], key[1], tuple(r for _, r, _, _, _ in found[key]),
                           tuple(s for _, _, s, _, _ in found[key]),
                           failed_seeds=tuple(seed for seed, _, _, f, _ in found[key] if f),
                           seeds=tuple(seed for seed, *_ in found[key]), payload_g=key[2], orientation=key[3],
                           max_error_deg=tuple(m for *_, m in found[key]))
                for key in keys]


def _cells_of(cells: Sequence[CellResult], wanted: Sequence[int]) -> list[CellResult]:
    """``cells`` cut down to the ``wanted`` seeds, or [] if they did not run them all: the runs are
    deterministic, so the fit's own runs serve for any subset of its seeds."""
    wanted = sorted(set(wanted))
    if not wanted or not all(set(wanted) <= set(cell.seeds) for cell in cells):
        return []
    picked = []
    for cell in cells:
        keep = [cell.seeds.index(s) for s in wanted]
        picked.append(dataclasses.replace(cell, rmse_deg=tuple(cell.rmse_deg[i] for i in keep),
                                          sse_deg=tuple(cell.sse_deg[i] for i in keep), seeds=tuple(wanted),
                                          max_error_deg=tuple(cell.max_error_deg[i] for i in keep)
                                          if cell.max_error_deg else (),
                                          failed_seeds=tuple(s for s in cell.failed_seeds if s in wanted)))
    return picked


def residuals(cells: Sequence[CellResult]) -> list[float]:
    """The fit's residuals (see the module docstring): one per cell, then one per T1 steady-error range."""
    rmse, sse = [], []
    for cell in cells:
        target = TARGET_OF[cell.key]
        rmse.append(math.log(max(cell.mean_rmse, 1e-6) / target.rmse_deg))
        if target.sse_range_deg is not None:
            sse.append(math.sqrt(SSE_WEIGHT) * math.log(max(cell.sse_range, 1e-3) / target.sse_range_deg))
    return rmse + sse


def cauchy_loss(r: float) -> float:
    """c^2 ln(1 + (r/c)^2), c = :data:`LOSS_SCALE`: r^2 near zero, logarithmic far out."""
    return LOSS_SCALE ** 2 * math.log1p((r / LOSS_SCALE) ** 2)


def cost(cells: Sequence[CellResult]) -> float:
    """The fit's cost (see the module docstring). Every run with warnings adds 1, more than nine
    factor-e misses (0.11 each): a numerical failure must never be the cheaper way to fit."""
    return sum(cauchy_loss(r) for r in residuals(cells)) + sum(cell.failed for cell in cells)


@dataclasses.dataclass(frozen=True)
class Evaluation:
    values: dict[str, float]
    cost: float
    stage: str  # "scan", "simplex" or "profile"


@dataclasses.dataclass
class Calibration:
    values: dict[str, float]
    cost: float
    evaluations: int
    history: list[Evaluation]
    fit_cells: list[CellResult]
    check_cells: list[CellResult]
    noise_costs: list[float]  # the best values' cost on the fit seeds, then on each noise seed set
    ensemble: list[Evaluation]  # the best first
    wall_time: float
    max_evaluations: int
    fit_seeds: tuple[int, ...]
    check_seeds: tuple[int, ...]
    noise_seed_sets: tuple[tuple[int, ...], ...]

    @property
    def noise(self) -> float:
        """The seed-to-seed noise of the best cost (:func:`cost_noise` of :attr:`noise_costs`)."""
        return cost_noise(self.noise_costs)


def cost_noise(costs: Sequence[float]) -> float:
    """The seed-to-seed noise of a cost: the sample std of its values on disjoint seed sets (0 from one)."""
    return spread(costs).std if len(costs) > 1 else 0.0


FITTED_INDEX = {f.name: i for i, f in enumerate(FITTED)}  # a fitted parameter's place in the unit box
SAME_VALUE_DIGITS = 9  # unit-box coordinates equal to this many digits are one value (Nelder-Mead's round-off)


def _box_key(values: dict[str, float]) -> tuple[float, ...]:
    """``values`` as unit-box coordinates rounded to :data:`SAME_VALUE_DIGITS`: values that differ only by
    floating-point round-off (1e-13 of a box, as the simplex's arithmetic leaves them) are the same value."""
    return tuple(round(x, SAME_VALUE_DIGITS) for x in unit_of(values))


def choose_ensemble(evaluations: Sequence[Evaluation], best: Evaluation, noise: float,
                    limit: int = ENSEMBLE_MAX) -> list[Evaluation]:
    """The evaluations within ``noise`` of the best cost (duplicates once), at most ``limit``: the best
    first, then those with the lowest and the highest value of each :data:`PROFILED` parameter (so the
    band shows what each does; the cheapest of those sharing an extreme), then the rest by cost. Values
    are compared on the unit box to :data:`SAME_VALUE_DIGITS` digits, so round-off makes no extreme."""
    unique: dict[tuple, Evaluation] = {}  # unit-box key -> the first evaluation there
    for e in evaluations:
        unique.setdefault(_box_key(e.values), e)
    near = sorted(((key, e) for key, e in unique.items() if e.cost <= best.cost + noise), key=lambda ke: ke[1].cost)
    chosen = {_box_key(best.values): best}
    extremes = []
    for name in PROFILED:
        i = FITTED_INDEX[name]
        lowest = min(near, key=lambda ke: (ke[0][i], ke[1].cost))
        highest = min(near, key=lambda ke: (-ke[0][i], ke[1].cost))
        if lowest[0][i] < highest[0][i]:  # one value shared tells nothing
            extremes += [lowest, highest]
    for key, e in [*extremes, *near]:
        if len(chosen) >= limit:
            break
        chosen.setdefault(key, e)
    return list(chosen.values())


class _BudgetSpent(Exception):
    """The simplex has used its evaluations."""


def planned_evaluations(*, scan_points: int = SCAN_POINTS, simplex_evaluations: int = SIMPLEX_EVALUATIONS,
                        profile_points: int = PROFILE_POINTS,
                        noise_seed_sets: Sequence[Sequence[int]] = NOISE_SEED_SETS,
                        previous: Sequence[dict[str, float]] | None = None) -> int:
    """The most evaluations :func:`calibrate` makes with these settings (the simplex may stop sooner)."""
    previous = previous_fits() if previous is None else previous
    return (scan_points + 1 + simplex_evaluations + profile_points * len(PROFILED) + len(noise_seed_sets)
            + len(previous))


def calibrate(*, workers: int = 2, fit_seeds: Sequence[int] = FIT_SEEDS, check_seeds: Sequence[int] = CHECK_SEEDS,
              noise_seed_sets: Sequence[Sequence[int]] = NOISE_SEED_SETS, scan_points: int = SCAN_POINTS,
              simplex_evaluations: int = SIMPLEX_EVALUATIONS, profile_points: int = PROFILE_POINTS,
              previous: Sequence[dict[str, float]] | None = None,
              progress: Callable[[int, int, str, float, dict], None] | None = None) -> Calibration:
    """Fit :data:`twin.plants.as_built.FITTED` (see the module docstring). ``previous``: the further starts'
    values (each must lie in the box; None: :func:`previous_fits`). ``progress(done, total, stage, cost, values)``
    after each evaluation."""
    previous = previous_fits() if previous is None else tuple(previous)
    for values in previous:
        if set(values) != {f.name for f in FITTED}:
            raise ValueError(f"a further start must give exactly the fitted parameters {[f.name for f in FITTED]}, "
                             f"not {sorted(values)}")
        outside = [f.name for f in FITTED if not f.low <= values[f.name] <= f.high]
        if outside:
            raise ValueError(f"a further start's {', '.join(outside)} lies outside the box")
    from scipy.optimize import minimize
    from scipy.stats import qmc

    started = time.perf_counter()
    planned = planned_evaluations(scan_points=scan_points, simplex_evaluations=simplex_evaluations,
                                  profile_points=profile_points, noise_seed_sets=noise_seed_sets,
                                  previous=previous)
    history: list[Evaluation] = []
    seen: dict[tuple[float, ...], tuple[Evaluation, list[CellResult]]] = {}
    evaluator = Evaluator(seeds=fit_seeds, workers=workers)
    stage, done, budget = "scan", 0, math.inf  # budget: evaluations allowed (the simplex's, while it runs)

    def report(c: float, values: dict) -> None:
        nonlocal done
        raise_if_stopped()  # a stop Python swallowed stops the fit here, not after it
        done += 1
        if progress is not None:
            progress(done, planned, stage, c, values)

    def objective(u: Sequence[float], values: dict[str, float] | None = None) -> float:
        """The cost at unit coordinates ``u`` (``values``: the values there, if given exactly)."""
        key = tuple(float(np.clip(x, 0.0, 1.0)) for x in u)
        if key not in seen:
            if len(history) >= budget:
                raise _BudgetSpent
            values = values_at(key) if values is None else dict(values)
            cells = evaluator.cells(values)
            seen[key] = (Evaluation(values, cost(cells), stage), cells)
            history.append(seen[key][0])
            report(seen[key][0].cost, values)
        return seen[key][0].cost

    def lowest() -> tuple[float, ...]:
        return min(seen, key=lambda k: seen[k][0].cost)

    with evaluator:  # its workers killed, not waited for, if the fit fails or is stopped
        design = qmc.Sobol(len(FITTED), scramble=True, seed=SCAN_SEED).random(scan_points) if scan_points else []
        for u in [np.full(len(FITTED), 0.5), *design]:
            objective(u)
        start = np.array(lowest())
        if simplex_evaluations:
            stage = "simplex"
            step = np.where(start > 0.5, -0.15, 0.15)  # into the box
            simplex = np.vstack([start] + [start + step[i] * np.eye(len(FITTED))[i] for i in range(len(FITTED))])
            budget = len(history) + simplex_evaluations
            try:
                minimize(objective, start, method="Nelder-Mead",
                         options={"initial_simplex": simplex, "xatol": 0.01, "fatol": 1e-3})
            except _BudgetSpent:
                pass
            budget = math.inf
        stage = "previous"
        for values in previous:  # evaluated as given (the unit box's round trip would move their last bits)
            objective(unit_of(values), {f.name: values[f.name] for f in FITTED})
        best_key = lowest()
        stage = "noise"
        noise_costs = [seen[best_key][0].cost]
        for seeds in noise_seed_sets:
            noise_costs.append(cost(evaluator.cells(seen[best_key][0].values, seeds=seeds)))
            report(noise_costs[-1], seen[best_key][0].values)
        stage = "profile"
        for name in PROFILED:  # each about the best of all so far (the first profile may move it)
            index, centre = FITTED_INDEX[name], lowest()
            for x in np.linspace(0.0, 1.0, profile_points):
                objective([x if i == index else centre[i] for i in range(len(FITTED))])
        # A profile point may beat the simplex (the cost is flat along the breakaway, within the noise):
        # the fitted values are the lowest cost evaluated.
        best, fit_cells = seen[lowest()]
        check_cells = _cells_of(fit_cells, check_seeds) or (evaluator.cells(best.values, seeds=check_seeds)
                                                            if check_seeds else [])
    return Calibration(values=best.values, cost=best.cost, evaluations=len(history), history=history,
                       fit_cells=fit_cells, check_cells=check_cells, noise_costs=noise_costs,
                       ensemble=choose_ensemble(history, best, cost_noise(noise_costs)),
                       wall_time=time.perf_counter() - started, max_evaluations=planned,
                       fit_seeds=tuple(fit_seeds), check_seeds=tuple(check_seeds),
                       noise_seed_sets=tuple(tuple(s) for s in noise_seed_sets))


def cell_rows(cells: Sequence[CellResult]) -> list[dict]:
    """One row per cell: the measured RMSE and std, the twin's, their ratio, the T1 SSE ranges."""
    rows = []
    for cell in cells:
        target = TARGET_OF[cell.key]
        rows.append({"source": target.source, "controller": cell.controller, "trajectory": cell.trajectory,
                     "payload_g": cell.payload_g, "orientation": cell.orientation,
                     "experiment_rmse_deg": target.rmse_deg, "experiment_std_deg": target.rmse_std_deg,
                     "twin_rmse_deg": round(cell.mean_rmse, 4), "twin_std_deg": round(spread(cell.rmse_deg).std, 4),
                     "ratio": round(cell.mean_rmse / target.rmse_deg, 4),
                     "twin_sse_range_deg": None if math.isnan(cell.sse_range) else round(cell.sse_range, 4),
                     "experiment_sse_range_deg": target.sse_range_deg,
                     "failed_runs": cell.failed})
    return rows


def fit_presets(values: dict[str, float]) -> dict:
    """The plant registry's presets as they stand once a fit with ``values`` is installed (its ``as-built``
    in place of whatever is installed, or added if nothing is): what its file's ``code_version`` hashes, so
    that it names the fit's own preset (the sweep store's version of the code, with it installed)."""
    from twin.plants import PLANTS

    presets = {name: (as_built_plant(values) if name == "as-built" else PLANTS[name]) for name in PLANTS}
    return presets if "as-built" in presets else {**presets, "as-built": as_built_plant(values)}


def record(result: Calibration) -> dict:
    """The versioned data file's content."""
    return {
        "version": FILE_VERSION,
        "code_version": code_version(plants=fit_presets(result.values)),
        "made_by": f"twin calibrate (Sobol scan of {SCAN_POINTS} + centre, Nelder-Mead, profiles of "
                   f"{' and '.join(PROFILED)}; "
                   + (f"further starts from earlier fits ({starts}, stage 'previous'); "
                      if (starts := sum(e.stage == "previous" for e in result.history)) else "")
                   + f"{result.evaluations} evaluations on fit seeds {list(result.fit_seeds)})",
        "loss": f"Cauchy, scale ln 1.2 = {LOSS_SCALE:.4f}; SSE-range residuals weighted sqrt({SSE_WEIGHT})",
        "targets": [dataclasses.asdict(t) for t in TARGETS],
        "fitted": dict(result.values),  # full precision: the preset is exactly what was scored
        "bounds": {f.name: {"low": f.low, "high": f.high, "unit": f.unit, "why": f.why} for f in FITTED},
        "assumed": dict(ASSUMED),  # a copy: the file keeps what held when it was written
        "cost": result.cost,
        "noise": {"how": "the best values after the further starts, before the profiles: their cost on the fit seeds and on each further seed set "
                         "of the same size; noise = their sample std; the ensemble is every evaluated set with "
                         "cost <= best + noise",
                  "seed_sets": [list(result.fit_seeds), *(list(s) for s in result.noise_seed_sets)],
                  "costs": result.noise_costs, "std": result.noise},
        "ensemble": [{"values": dict(e.values), "cost": e.cost, "stage": e.stage} for e in result.ensemble],
        "evaluations": result.evaluations,
        "wall_time_s": round(result.wall_time, 1),
        "residuals_fit_seeds": cell_rows(result.fit_cells),
        "residuals_check_seeds": cell_rows(result.check_cells),
        "check_seeds": list(result.check_seeds),
        "history": [{"values": dict(e.values), "cost": e.cost, "stage": e.stage} for e in result.history],
    }


FILE_NAME = "as_built.json"  # what a fit writes in --out (and, installed, the as-built preset's name)


def write(data: dict, out: pathlib.Path, name: str = FILE_NAME) -> pathlib.Path:
    """``data`` as ``out/name``, whole or not at all: written beside it, then renamed over it (an
    earlier file stays as it was if the write fails). An OSError names ``out/name``, not its temporary
    (a full disk's names no file of its own)."""
    path = out / name
    tmp = path.with_name(f".{path.name}.tmp-{os.getpid()}")
    try:
        tmp.write_text(json.dumps(data, indent=1) + "\n")
        raise_if_stopped()
        tmp.replace(path)
    except OSError as error:
        if error.filename not in (None, str(tmp)):
            raise
        raise named_error(error, path) from None
    finally:
        tmp.unlink(missing_ok=True)
    return path


def format_residuals(data: dict) -> str:
    """The check-seed residual table as text, with the fit seeds' ratio beside it."""
    wide = {(r["controller"], r["trajectory"], r["payload_g"], r["orientation"]): r
            for r in data.get("residuals_fit_seeds", [])}
    n = len(data.get("noise", {}).get("seed_sets", [[]])[0])
    lines = [f"{'controller':10} {'T':>2} {'payload':>8} {'orient.':10} {'experiment':>12} {'twin':>12} "
             f"{'twin/exp':>8} {'SSE range exp/twin':>19} {f'{n} seeds: twin/exp':>19}"]
    for r in data["residuals_check_seeds"]:
        sse = (f"{r['experiment_sse_range_deg']:.2f} / {r['twin_sse_range_deg']:.2f}"
               if r["experiment_sse_range_deg"] is not None and r["twin_sse_range_deg"] is not None else "")
        other = wide.get((r["controller"], r["trajectory"], r["payload_g"], r["orientation"]))
        lines.append(f"{r['controller']:10} {r['trajectory']:>2} {r['payload_g']:6g} g {r['orientation']:10} "
                     f"{r['experiment_rmse_deg']:6.2f} ± {r['experiment_std_deg']:.2f}"
                     f" {r['twin_rmse_deg']:6.2f} ± {r['twin_std_deg']:.2f} {r['ratio']:8.2f} {sse:>19}"
                     + (f" {other['ratio']:19.2f}" if other else ""))
    fitted = ", ".join(f"{k} = {v:g}" for k, v in data["fitted"].items())
    lines.append(f"fitted: {fitted}; cost {data['cost']:.4f}")
    if "noise" in data:
        lines.append(f"seed-to-seed noise of the best cost: {data['noise']['std']:.4f} (costs "
                     + ", ".join(f"{c:.4f}" for c in data["noise"]["costs"]) + f"); ensemble of {len(data['ensemble'])}"
                     " within it, breakaway " + ", ".join(f"{m['values']['stiction']:.2f}" for m in data["ensemble"])
                     + " N")
    return "\n".join(lines)
