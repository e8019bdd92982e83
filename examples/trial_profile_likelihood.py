"""Trial (not installed): a profile of the fit's cost in one fitted parameter with the others refitted at each point,
and the T3 prediction where it stays under the ensemble's cut.

``twin calibrate``'s profiles move one parameter about the best with the other six held at the best's values, and
the ensemble keeps the evaluated sets whose cost is within the best's seed-to-seed noise (the cut). A set with the
parameter further out and the others moved to make up for it is in no profile and, unless the search reached it, in
no ensemble; the stop-44 trial found one such set (docs/prediction.md). This trial asks the question for one
parameter at values past the ensemble's range: at each value, hold the parameter there and refit the other six by
Nelder-Mead from the nearest set already known (an ensemble member, or this trial's refit at the value before),
on the fit's seeds and cost, as ``twin calibrate`` evaluates them. A refit's cost is an upper bound of the true
profile there (a longer search can only find lower), so a point under the cut shows a set that fits as well, and
a point over it shows only that this search found none. For each refit it prints the cost against the cut, the
refitted values, the measured RMSE cells within 20 % on seeds 0-4, and the twelve T3 cells (seeds 0-4, as
``twin validate`` runs them) beside the ensemble's members' range.

The calibration file is the committed one (``twin/plants/data/as_built.json``) unless ``--calibration`` names
another; its preset digest is printed. Nothing is installed or refitted in the package, and no T3 measurement was
seen. ``--out FILE`` keeps every evaluation and each point's result as JSON (written whole once the trial ends,
refused if the file is there; on a stop, what ran is written before it stops). ``--check FILE`` runs a kept file's
results again (each value's refitted set on the fit seeds, and its T3 cells) and prints whether they give the kept
costs and cells, in about a minute; it exits 1 if any does not. ``--start FILE AT`` starts the first value from
the refit a kept trial file holds at AT instead of the nearest set (a longer search from where a kept one stopped, or
another start); the later values start from the nearest set known, the kept start among them. The kept file records
the start as its file and AT; that file names the preset it ran on.

On 2026-11-28 (stop 46) it ran the load friction at 0.40, 0.45, 0.50, 0.10 and 0.05 N/N on the twelfth refit
(``--calibration twin/plants/data/twelfth_refit.json``, digest 6bb9e9258023; 120 evaluations, 543 s on 2 cores):
``examples/trial_profile_likelihood/load_friction.json`` and ``.txt`` (what it printed; the file's ``calibration``
names the committed file as it then was, the twelfth refit, whose digest it keeps). The sets under the cut are
further starts of ``twin calibrate`` since file version 11 (``twin/plants/data/profile_refits.json``). On
2026-11-28 (stop 47) it ran the breakaway, the leak, the free air and then the observer gain on the thirteenth
refit, the committed one (digest 13aadbb61885), each file beside the first: ``stiction``, ``leak_conductance``,
``air_fraction`` and ``observer_gain``. The first three were given ``--calibration twin/plants/data/as_built.json``,
the file the default reads; the fourth ran on the default. Its file and ``load_friction.json`` name the calibration
by the absolute path of the checkout they ran in (kept files name it from the checkout's root since). Every result
is recorded in docs/investigations.md. On 2026-11-29 (stop 48) it searched longer (``--evaluations 48``) on the
thirteenth refit, each run from a kept refit (``--start``): the load friction at 0.50 (from its 0.50 refit), 0.55
and 0.60, at 0.10 (from its 0.10 refit) and at 0 (from its 0.05 refit); the free air at 8 % and the observer gain at
250 and at 700 1/s, each from its refit; and the breakaway at 2.10 N from the load friction's 0.05 N/N refit, a start
with little load friction. 432 evaluations in 2048 s on 2 cores, alone; kept in
``examples/trial_profile_likelihood/longer/``, each file named for its parameter and values. On 2026-11-29 (stop 49)
four of those that had stopped over the cut went on, each from its own kept refit: the load friction at 0.55 and at
0.60 (``--evaluations 96``), the breakaway at 2.10 N and the observer gain at 700 1/s (48); 288 evaluations in
1339 s; kept in ``examples/trial_profile_likelihood/continued/``.

    python examples/trial_profile_likelihood.py --parameter load_friction --at 0.40 0.45 0.50 0.10 0.05 \
        --calibration twin/plants/data/twelfth_refit.json --out FILE
    python examples/trial_profile_likelihood.py --parameter stiction --at 2.1 2.35 2.55 1.0 --out FILE
    python examples/trial_profile_likelihood.py --parameter leak_conductance --at 1e-14 5e-15 0 3e-14 --out FILE
    python examples/trial_profile_likelihood.py --parameter air_fraction --at 0.02 0.01 0.065 0.08 --out FILE
    python examples/trial_profile_likelihood.py --parameter observer_gain --at 250 150 700 900 --out FILE
    python examples/trial_profile_likelihood.py --parameter load_friction --at 0.50 0.55 0.60 --evaluations 48 \
        --start examples/trial_profile_likelihood/load_friction.json 0.50 --out FILE
    python examples/trial_profile_likelihood.py --check examples/trial_profile_likelihood/load_friction.json
"""

from __future__ import annotations

import argparse
import json
import math
import pathlib
import sys
import time

import numpy as np

from twin.exceptions import TwinError
from twin.experiments import calibrate
from twin.experiments.validate import PREDICTION_CELLS, SEEDS, lead_counts, rmse_within
from twin.plants.as_built import (
    CALIBRATION_FILE,
    FITTED,
    calibration_cost_line,
    ensemble_costs,
    ensemble_values,
    preset_digest,
)

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))  # the sibling module, however this one is loaded
import kept_profiles  # noqa: E402
from kept_profiles import shown  # noqa: E402

STEP = 0.10  # the initial simplex's step per refitted parameter, in unit-box coordinates (into the box)
EVALUATIONS = 24  # per point: twin calibrate's simplex budget
MEASURED_SEEDS = SEEDS  # the verdict's five runs, cut from the fit's ten


class _Spent(Exception):
    """A point's refit has used its evaluations."""


def refit(evaluator: calibrate.Evaluator, name: str, value: float, start: dict[str, float], budget: int,
          log: list[dict]) -> tuple[dict[str, float], float, list[calibrate.CellResult]]:
    """The other fitted parameters refitted with ``name`` held at ``value``, by Nelder-Mead from ``start`` (its
    ``name`` replaced) over at most ``budget`` evaluations; each evaluation appended to ``log``. Returns the lowest
    cost's values, cost and cells."""
    free = [i for i, f in enumerate(FITTED) if f.name != name]
    base = np.array(calibrate.unit_of({**start, name: value}))
    seen: dict[tuple, tuple[float, dict, list]] = {}

    def objective(x: np.ndarray) -> float:
        u = base.copy()
        u[free] = np.clip(x, 0.0, 1.0)
        key = tuple(round(float(c), calibrate.SAME_VALUE_DIGITS) for c in u[free])
        if key not in seen:
            if len(seen) >= budget:
                raise _Spent
            values = {**calibrate.values_at(u), name: value}  # held exactly, not through the box's round trip
            cells = evaluator.cells(values)
            seen[key] = (calibrate.cost(cells), values, cells)
            log.append({"parameter": name, "at": value, "cost": seen[key][0], "values": values})
            print(f"  [{len(seen)}/{budget}] cost {seen[key][0]:.4f}", file=sys.stderr, flush=True)
        return seen[key][0]

    x0 = base[free]
    step = np.where(x0 > 0.5, -STEP, STEP)
    simplex = np.vstack([x0] + [x0 + step[i] * np.eye(len(free))[i] for i in range(len(free))])
    try:
        from scipy.optimize import minimize
        minimize(objective, x0, method="Nelder-Mead", options={"initial_simplex": simplex, "xatol": 0.01,
                                                                "fatol": 1e-3})
    except _Spent:
        pass
    best_cost, values, cells = min(seen.values(), key=lambda s: s[0])
    return values, best_cost, cells


def nearest(name: str, value: float, known: list[tuple[dict[str, float], float]]) -> tuple[dict[str, float], float]:
    """Of the ``known`` (values, cost) sets, the one whose ``name`` is nearest ``value``, the cheapest of a tie."""
    return min(known, key=lambda k: (abs(k[0][name] - value), k[1]))


def t3_cells(evaluator: calibrate.Evaluator, values: dict[str, float]) -> list[float]:
    """The twelve T3 cells' mean RMSE (deg) on seeds 0-4, in PREDICTION_CELLS' order."""
    return [c.mean_rmse for c in evaluator.cells(values, keys=PREDICTION_CELLS, seeds=SEEDS)]


def read_json(parser: argparse.ArgumentParser, path: pathlib.Path, flag: str) -> dict:
    """The JSON object in ``path``, or a one-line parser error naming ``flag``."""
    try:
        data = json.loads(pathlib.Path(path).read_text())
    except (OSError, UnicodeDecodeError, ValueError) as error:
        parser.error(f"{flag} {path}: cannot read it as JSON ({error.__class__.__name__})")
    if not isinstance(data, dict):
        parser.error(f"{flag} {path}: not a JSON object")
    return data


def check(kept: dict, path: pathlib.Path, workers: int) -> bool:
    """Run each result of the kept trial file ``kept`` (read from ``path``) again (its refitted values on the fit
    seeds, then its T3 cells) and print whether the cost and the twelve cells are the kept ones, to the last bit;
    True when every one is."""
    print(f"{path}: preset {kept['preset']}, {len(kept['results'])} values of {kept['results'][0]['parameter']}")
    same = True
    with calibrate.Evaluator(seeds=calibrate.FIT_SEEDS, workers=workers) as evaluator:
        for result in kept["results"]:
            cost = calibrate.cost(evaluator.cells(result["values"]))
            t3 = t3_cells(evaluator, result["values"])
            both = (cost == result["cost"], t3 == [c["twin_mean"] for c in result["t3"]])
            same = same and all(both)
            print(f"  {result['at']:g}: cost {cost:.4f}, as kept: {both[0]}; T3 cells as kept: {both[1]}", flush=True)
    return same


def kept_start(parser: argparse.ArgumentParser, path: str, at: str) -> tuple[dict[str, float], float]:
    """The refitted values and cost of the kept trial file ``path``'s result at ``at`` (``--start``), or a one-line
    parser error."""
    try:
        value = float(at)
    except ValueError:
        parser.error(f"--start {path} {at}: AT must be a number")
    kept = read_json(parser, pathlib.Path(path), "--start")
    results = kept.get("results")
    found = [r for r in results if isinstance(r, dict) and r.get("at") == value] if isinstance(results, list) else []
    if not found:
        parser.error(f"--start {path}: no kept result at {value:g}")
    if len(found) > 1:
        parser.error(f"--start {path}: {len(found)} kept results at {value:g}, so which to start from is not clear")
    values, cost = found[0].get("values"), found[0].get("cost")
    if not (isinstance(values, dict) and set(values) == {f.name for f in FITTED} and all(
            isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in values.values())
            and isinstance(cost, float) and math.isfinite(cost)):
        parser.error(f"--start {path}: its result at {value:g} has not the fitted values and a finite cost")
    for f in FITTED:  # a set outside the box would be clipped into it: its first evaluation would not be the kept set
        if not f.low <= values[f.name] <= f.high:
            parser.error(f"--start {path}: its result at {value:g} has {f.name} outside its box, {f.low:g}-{f.high:g}")
    return {k: float(v) for k, v in values.items()}, cost


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    names = [f.name for f in FITTED]
    parser.add_argument("--parameter", default="load_friction", choices=names, help="the profiled parameter")
    parser.add_argument("--at", type=float, nargs="+", metavar="VALUE",
                        help="its values (SI, as the calibration file), each inside its box; run in the order given")
    parser.add_argument("--check", type=pathlib.Path, metavar="FILE", help="run a kept trial file's results again")
    parser.add_argument("--calibration", type=pathlib.Path, default=None, help="the calibration file (default: the "
                        "committed one)")
    parser.add_argument("--evaluations", type=int, default=EVALUATIONS, help="refit budget per value")
    parser.add_argument("--start", nargs=2, metavar=("FILE", "AT"), help="start the first value from a kept trial "
                        "file's refit at AT (a longer search from where one stopped, or another start)")
    parser.add_argument("--out", type=pathlib.Path, metavar="FILE", help="keep the evaluations and results as JSON")
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args(argv)
    if (args.at is None) == (args.check is None):
        parser.error("give --at VALUE ... (a profile now) or --check FILE (a kept one run again), one of them")
    if args.check is not None:
        if args.out is not None:
            parser.error("--out keeps a profile run now (--at); --check writes nothing")
        if args.start is not None:
            parser.error("--start starts a profile run now (--at); --check runs the kept results as they are")
        try:  # a stopped run's results can be checked too
            kept = kept_profiles.read(args.check, complete=False)
        except kept_profiles.KeptFileError as error:
            parser.error(f"--check {args.check}: {error}")
        if "preset" not in kept:
            parser.error(f"--check {args.check}: names no preset, so what it ran on is not known")
        if not check(kept, args.check, args.workers):
            sys.exit(1)
        return
    box = FITTED[calibrate.FITTED_INDEX[args.parameter]]
    outside = [v for v in args.at if not box.low <= v <= box.high]
    if outside:
        parser.error(f"--at {outside[0]:g}: {args.parameter} must lie in its box, {box.low:g}-{box.high:g}")
    if args.evaluations < len(FITTED):
        parser.error(f"--evaluations {args.evaluations}: the first simplex alone needs {len(FITTED)}")
    start_from = None if args.start is None else kept_start(parser, *args.start)
    part = None if args.out is None else args.out.with_name(args.out.name + ".part")
    if args.out is not None and (args.out.exists() or part.exists()):
        parser.error(f"{args.out if args.out.exists() else part} is there already: give another --out")
    if args.out is not None and not args.out.parent.is_dir():
        parser.error(f"{args.out.parent} is not a folder")
    path = CALIBRATION_FILE if args.calibration is None else args.calibration
    read_json(parser, path, "--calibration")  # a file that is not JSON, said as --check says it
    try:  # the as-built readers' checks: every member's values in the box, the cost line finite
        best, noise = calibration_cost_line(path)
        costs = [math.inf if c is None else c for c in ensemble_costs(path)]  # no cost: the last of a tie
        members = list(zip(ensemble_values(path), costs, strict=True))
        digest = preset_digest(path)
    except TwinError as error:
        parser.error(f"--calibration {path}: not a calibration file with an ensemble of the fitted parameters "
                     f"({str(error).splitlines()[0]})")
    if part is not None:
        try:  # found out now, not after the whole run
            part.write_text("")
        except OSError as error:
            parser.error(f"--out {args.out}: cannot write beside it ({error.strerror})")
    cut = best + noise
    lows = [m[0][args.parameter] for m in members]
    print(f"preset {digest}: cut {cut:.4f} (cost {best:.4f} + noise {noise:.4f}); the ensemble's "
          f"{args.parameter} {min(lows):.4g}-{max(lows):.4g}; each value refitted over {args.evaluations} evaluations "
          f"of the other {len(FITTED) - 1}, fit seeds {calibrate.FIT_SEEDS[0]}-{calibrate.FIT_SEEDS[-1]}")
    rows = kept_profiles.t3_rows()
    log: list[dict] = []
    results: list[dict] = []
    known = list(members) + ([] if start_from is None else [start_from])
    started = time.perf_counter()
    try:
        with calibrate.Evaluator(seeds=calibrate.FIT_SEEDS, workers=args.workers) as evaluator:
            ensemble_t3 = np.array([t3_cells(evaluator, m) for m, _ in members])  # (members, cells)
            first = start_from  # --start's set, for the first value only
            for value in args.at:
                start, start_cost = first or nearest(args.parameter, value, known)
                print(f"{args.parameter} {value:g}: from the set at {start[args.parameter]:.4g} (cost "
                      f"{start_cost:.4f}{', ' + ' '.join(args.start) if first else ''})", flush=True)
                first = None
                values, cost, cells = refit(evaluator, args.parameter, value, start, args.evaluations, log)
                known.append((values, cost))
                measured = calibrate._cells_of(cells, MEASURED_SEEDS)
                within = sum(bool(rmse_within(c.mean_rmse, calibrate.TARGET_OF[c.key].rmse_deg)) for c in measured)
                t3 = t3_cells(evaluator, values)
                ahead = lead_counts(rows, t3)[0].get("smc", 0)
                results.append({"parameter": args.parameter, "at": value, "cost": cost, "under_cut": cost <= cut,
                                "start": start, "start_cost": start_cost, "values": values,
                                "measured_rmse_cells_within": within,
                                "t3": [{**r, "twin_mean": m} for r, m in zip(rows, t3, strict=True)]})
                print(f"  cost {cost:.4f} ({'under' if cost <= cut else 'over'} the cut by {abs(cost - cut):.4f}); "
                      f"{within} of {len(measured)} measured RMSE cells within 20 % (seeds 0-4); "
                      + ", ".join(f"{k} {v:.4g}" for k, v in values.items()), flush=True)
                for r, m, span in zip(rows, t3, ensemble_t3.T, strict=True):
                    outside_span = "" if span.min() <= m <= span.max() else " (outside the members' range)"
                    print(f"    T3 {r['controller']:6} {r['payload_g']:4g} g {r['orientation']:10} {m:.2f}  members "
                          f"{span.min():.2f}-{span.max():.2f}{outside_span}", flush=True)
                print(f"    sliding mode ahead in {ahead} of 6 T3 cells", flush=True)
    finally:
        if part is not None and not log:
            part.unlink(missing_ok=True)  # nothing ran: no file
        elif part is not None:
            try:
                part.write_text(json.dumps({"calibration": shown(path), "preset": digest, "cut": cut,
                                            "evaluations_per_value": args.evaluations,
                                            "start": None if args.start is None else [shown(args.start[0]),
                                                                                      float(args.start[1])],
                                            "results": results,
                                            "evaluations": log, "wall_time_s": time.perf_counter() - started,
                                            "complete": len(results) == len(args.at)}, indent=1) + "\n")
                if args.out.exists():  # it appeared while the trial ran: not replaced
                    print(f"{args.out} appeared while the trial ran; kept its results in {part}", file=sys.stderr)
                else:
                    part.replace(args.out)
                    print(f"wrote {args.out}", file=sys.stderr)
            except OSError as error:  # said, and not in place of why the run stopped
                print(f"could not keep the results in {args.out}: {error}", file=sys.stderr)
    print(f"{len(log)} evaluations in {time.perf_counter() - started:.0f} s")


if __name__ == "__main__":
    main()
