"""Trial (not installed): every kept parameter set's fit cost on noise seeds no search selected on, against the
committed best's on the same seeds.

``twin calibrate`` and the profile trial (``examples/trial_profile_likelihood.py``) pick sets by their cost on the fit
seeds 0-9, always the same ten, and the ensemble's cut is the best's cost there plus its seed-to-seed noise. A set
picked as the lowest of many on fixed seeds is also picked for a lucky draw of those seeds: the committed
calibration file's own noise costs show it (the best of its time cost 0.531 on seeds 0-9 and 0.784, 0.798 and 0.704
on seeds 10-19, 20-29 and 30-39). So two sets' costs on seeds 0-9 compare their luck as well as their fit. This
trial runs each kept set on seeds 40-79 (``twin validate``'s fresh seeds, which no step of the calibration and no
profile search ran), as four sets of ten, the fit's cost on each, and sets each against the committed best (the
ensemble's member 0) on the same seed sets: the mean paired difference and its standard error (the sample std of
the differences over the square root of their number). The seed sets are shared, so the difference is freer of the
seeds' draw than either cost.

A set is read as **worse** than the best on fresh seeds when its mean difference is above two standard errors and
above the cut's width (the noise, 0.1229 on the committed file); **better** the mirror; else **not told apart**.
These readings were written down before the trial first ran (stop 49). **Not told apart** means not shown worse or
better, not shown as good: with three or seven degrees of freedom, two standard errors are a loose test (about 86 %
and 91 % two-sided), and the noise carries the rule.

The sets: the committed file's ensemble members, then every result of every complete kept profile file in
``examples/trial_profile_likelihood/`` and its folders (in name order), under the cut or over it. A kept file that
is not a complete profile run is refused in one line, before any run (``examples/kept_profiles.py`` reads them, for
the three trials that do). ``--seed-sets N`` runs N sets of ten from 40
(default 4: 40-79); ``--reuse FILE`` takes the costs a kept run of this trial holds on its seed sets, when they are
the first of this run's, for each set with the same label and values, and runs only the rest. ``--out FILE`` keeps
the costs as JSON (refused if the file is there; written whole at the end; if it stops, what ran is written there,
marked ``"complete": false``). Nothing is fitted or installed, and no T3 cell is run. ``--roughness`` runs nothing:
it prints, over every pair of evaluations of one search in the kept profile files, how far apart their costs are by
how far apart they lie in the box (kept as ``examples/trial_fresh_seed_costs/roughness.txt``).

On 2026-11-29 (stop 49) it ran on the 13 members and the 34 kept profile results: on seeds 40-79 (795 s on 2 cores,
alone), kept as ``examples/trial_fresh_seed_costs/costs.json`` and ``.txt``; then, decided after seeing that run (one
set's standard error was too wide to read against the noise), on 40-119, reusing those costs and running 80-119,
kept as ``costs_40-119.json`` and ``.txt``. docs/investigations.md records both. (``costs.json`` was written before
``--reuse`` existed, so it has no ``reused`` key.) A set kept twice (a member that is also a profile result, or a
search that found nothing below its start) ran twice in those runs, to the same costs; since stop 50 it runs once
and its second row takes the first's costs.

    python examples/trial_fresh_seed_costs.py [--out FILE] [--seed-sets N] [--reuse FILE] [--workers 2]
    python examples/trial_fresh_seed_costs.py --seed-sets 8 --reuse examples/trial_fresh_seed_costs/costs.json \
        --out FILE
"""

from __future__ import annotations

import argparse
import json
import math
import pathlib
import sys
import time
from collections.abc import Callable

import numpy as np

from twin.experiments import calibrate
from twin.plants.as_built import (
    CALIBRATION_FILE,
    calibration_cost_line,
    ensemble_costs,
    ensemble_values,
    preset_digest,
)

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))  # the sibling module, however this one is loaded
import kept_profiles  # noqa: E402
from kept_profiles import shown  # noqa: E402

KEPT = kept_profiles.KEPT
SEED_SETS = 4  # sets of ten seeds from 40: validate's fresh seeds 40-79 (--seed-sets runs more, from 80)
TIE = 2.0  # standard errors a mean paired difference must pass (and the noise) to tell a set from the best


def kept_files() -> list[pathlib.Path]:
    """The kept profile files: the folder's own, then each sub-folder's, each in name order."""
    return kept_profiles.files(KEPT)


def read_kept(parser: argparse.ArgumentParser) -> dict[str, dict]:
    """Every kept profile file, read, by its name in the folder; a one-line parser error for one that is not a
    complete kept profile run."""
    files = {}
    for path in kept_files():
        name = str(path.relative_to(KEPT))
        try:
            files[name] = kept_profiles.read(path)
        except kept_profiles.KeptFileError as error:
            parser.error(f"{name}: {error}")
    return files


def kept_sets(files: dict[str, dict]) -> list[tuple[str, dict[str, float], float]]:
    """(label, values, cost on the fit seeds) of every result of the kept profile ``files``."""
    return [(f"{name} {r['parameter']} {r['at']:g}", r["values"], r["cost"])
            for name, file in files.items() for r in file["results"]]


def paired(costs: list[float], base: list[float]) -> tuple[float, float]:
    """The mean of ``costs`` minus ``base`` seed set by seed set, and its standard error (the differences' sample std
    over the square root of their number)."""
    differences = np.subtract(costs, base)
    return float(differences.mean()), float(differences.std(ddof=1) / math.sqrt(len(differences)))


def reading(difference: float, error: float, noise: float) -> str:
    """The fixed reading of a set's mean paired difference to the best (see the module docstring)."""
    if difference > TIE * error and difference > noise:
        return "worse"
    if difference < -TIE * error and difference < -noise:
        return "better"
    return "not told apart"


def seed_sets(count: int) -> list[list[int]]:
    """The first ``count`` sets of ten fresh seeds: 40-49, 50-59, ..."""
    return [list(range(40 + 10 * i, 50 + 10 * i)) for i in range(count)]


def fresh_costs(evaluator: calibrate.Evaluator, values: dict[str, float], count: int = SEED_SETS,
                known: list[float] = ()) -> list[float]:
    """The fit's cost of ``values`` on each of the first ``count`` fresh seed sets; ``known`` the costs already run
    on the first of them (--reuse), which are taken as they are."""
    return list(known) + [calibrate.cost(evaluator.cells(values, seeds=seeds)) for seeds in seed_sets(count)[len(known):]]


def read_fresh(parser: argparse.ArgumentParser, flag: str, path: pathlib.Path, digest: str,
               more: Callable[[dict], bool] = lambda kept: True) -> dict:
    """The kept fresh-seed trial file ``path``, given as ``flag``, or a one-line parser error: not JSON, not a complete
    such file (its sets' rows as this trial writes them, each with a cost per seed set, and whatever ``more`` asks of
    it), or run on another preset than the committed ``digest``. The band trial reads the same files through it."""
    try:
        kept = json.loads(pathlib.Path(path).read_text())
    except (OSError, UnicodeDecodeError, ValueError) as error:
        parser.error(f"{flag} {path}: cannot read it as JSON ({error.__class__.__name__})")
    if not (isinstance(kept, dict) and isinstance(kept.get("sets"), list) and kept.get("complete") is True
            and isinstance(kept.get("fresh_seed_sets"), list) and all(
                isinstance(row, dict) and {"set", "values", "fresh_costs"} <= set(row)
                and isinstance(row["fresh_costs"], list) and len(row["fresh_costs"]) == len(kept["fresh_seed_sets"])
                for row in kept["sets"]) and more(kept)):
        parser.error(f"{flag} {path}: not a complete kept fresh-seed trial file")
    if kept.get("preset") != digest:
        parser.error(f"{flag} {path}: run on preset {kept.get('preset')}, not the committed {digest}")
    return kept


def reused(parser: argparse.ArgumentParser, path: pathlib.Path, digest: str, count: int) -> dict[str, dict]:
    """The kept fresh-seed file ``path``'s sets by label (--reuse), or a one-line parser error: not such a file, run
    on another preset, or on seed sets that are not the first of this run's."""
    kept = read_fresh(parser, "--reuse", path, digest)
    held = kept["fresh_seed_sets"]
    if held != seed_sets(len(held)) or len(held) > count:
        parser.error(f"--reuse {path}: its seed sets are not the first of this run's {count}")
    return {row["set"]: row for row in kept["sets"]}


ROUGHNESS_BINS = (0.0, 0.005, 0.01, 0.02, 0.05, 0.1, 0.2)  # the largest unit-box difference of a pair, bins' edges


def roughness(files: list[dict]) -> list[tuple[float, float, int, float, float]]:
    """How far apart in cost two evaluations of one search are, by how far apart in the fitted box they are: over
    every pair of evaluations at one held value in the kept profile ``files`` (read), binned by the largest difference of
    their unit-box coordinates (every fitted parameter's share of its box), each bin's (low, high, pairs, median and
    90th percentile of the cost difference)."""
    distances, differences = [], []
    for file in files:
        runs: dict[tuple, list[dict]] = {}
        for e in file["evaluations"]:
            runs.setdefault((e["parameter"], e["at"]), []).append(e)
        for run in runs.values():
            box = np.array([calibrate.unit_of(e["values"]) for e in run])
            cost = np.array([e["cost"] for e in run])
            i, j = np.triu_indices(len(run), 1)
            distances.append(np.abs(box[i] - box[j]).max(axis=1))
            differences.append(np.abs(cost[i] - cost[j]))
    distance, difference = np.concatenate(distances), np.concatenate(differences)
    rows = []
    for low, high in zip(ROUGHNESS_BINS[:-1], ROUGHNESS_BINS[1:], strict=True):
        inside = difference[(distance > low) & (distance <= high)]
        rows.append((low, high, len(inside), float(np.median(inside)), float(np.percentile(inside, 90))))
    return rows


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=pathlib.Path, metavar="FILE", help="keep the costs as JSON")
    parser.add_argument("--seed-sets", type=int, default=SEED_SETS, metavar="N",
                        help=f"sets of ten fresh seeds from 40 (default {SEED_SETS}: 40-79)")
    parser.add_argument("--reuse", type=pathlib.Path, metavar="FILE", help="take the costs a kept file holds on "
                        "its seed sets (the first of this run's) for the same sets, and run only the rest")
    parser.add_argument("--roughness", action="store_true", help="print how far apart in cost the kept profile "
                        "evaluations of one search are, by how far apart they are in the box, and stop (no runs)")
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args(argv)
    files = read_kept(parser)
    if args.roughness:
        print(f"every pair of evaluations at one held value in the {len(files)} kept profile files: the cost "
              "difference by the largest unit-box difference")
        for low, high, pairs, median, top in roughness(list(files.values())):
            print(f"  {low:g}-{high:g} of the box: {pairs} pairs, median {median:.3f}, 90th percentile {top:.3f}")
        return
    if args.workers < 1:
        parser.error(f"--workers {args.workers}: at least 1")
    if not 2 <= args.seed_sets <= 16:
        parser.error(f"--seed-sets {args.seed_sets}: from 2 (a standard error needs two) to 16")
    part = None if args.out is None else args.out.with_name(args.out.name + ".part")
    if args.out is not None and (args.out.exists() or part.exists()):
        parser.error(f"{args.out if args.out.exists() else part} is there already: give another --out")
    if args.out is not None and not args.out.parent.is_dir():
        parser.error(f"{args.out.parent} is not a folder")
    best_cost, noise = calibration_cost_line(CALIBRATION_FILE)
    members = [(f"member {i}", v, math.nan if c is None else c) for i, (v, c) in enumerate(zip(
        ensemble_values(CALIBRATION_FILE), ensemble_costs(CALIBRATION_FILE), strict=True))]
    sets = members + kept_sets(files)
    digest = preset_digest(CALIBRATION_FILE)
    before = {} if args.reuse is None else reused(parser, args.reuse, digest, args.seed_sets)
    if part is not None:
        try:  # found out now, not after the whole run
            part.write_text("")
        except OSError as error:
            parser.error(f"--out {args.out}: cannot write beside it ({error.strerror})")
    seeds = seed_sets(args.seed_sets)
    print(f"preset {digest}: cut {best_cost + noise:.4f} (cost {best_cost:.4f} + noise {noise:.4f}); {len(sets)} sets "
          f"on seeds {seeds[0][0]}-{seeds[-1][-1]} as {len(seeds)} sets of ten; "
          f"difference to member 0 (the best) on the same seeds, mean ± standard error", flush=True)
    rows: list[dict] = []
    started = time.perf_counter()
    try:
        with calibrate.Evaluator(seeds=calibrate.FIT_SEEDS, workers=args.workers) as evaluator:
            base: list[float] = []
            ran: dict[str, list[float]] = {}  # costs by values: a set kept twice runs once
            for label, values, kept_cost in sets:
                kept_row = before.get(label)
                known = kept_row["fresh_costs"] if kept_row and kept_row["values"] == values else []
                same = kept_profiles.set_key(values)
                costs = ran.get(same) or fresh_costs(evaluator, values, args.seed_sets, known)
                ran[same] = costs
                base = base or costs  # member 0's, the first set's
                difference, error = paired(costs, base)
                said = "the best" if not rows else reading(difference, error, noise)
                rows.append({"set": label, "values": values, "kept_cost": None if math.isnan(kept_cost) else kept_cost,
                             "fresh_costs": costs, "mean": float(np.mean(costs)), "difference": difference,
                             "standard_error": error, "reading": said})
                kept = "" if math.isnan(kept_cost) else f"seeds 0-9 {kept_cost:.4f}; "
                print(f"  {label}: {kept}fresh {' '.join(f'{c:.3f}' for c in costs)}, mean {np.mean(costs):.4f}; "
                      f"{difference:+.4f} ± {error:.4f}: {said}", flush=True)
    finally:
        if part is not None and not rows:
            part.unlink(missing_ok=True)
        elif part is not None:
            try:
                part.write_text(json.dumps({"preset": digest, "noise": noise, "fresh_seed_sets": seeds,
                                            "reused": None if args.reuse is None else shown(args.reuse),
                                            "sets": rows, "complete": len(rows) == len(sets),
                                            "wall_time_s": time.perf_counter() - started}, indent=1) + "\n")
                part.replace(args.out)
                print(f"wrote {args.out}", file=sys.stderr)
            except OSError as error:
                print(f"could not keep the costs in {args.out}: {error}", file=sys.stderr)
    told = {r: sum(row["reading"] == r for row in rows) for r in ("worse", "not told apart", "better")}
    print(f"{len(rows)} sets in {time.perf_counter() - started:.0f} s: " + ", ".join(f"{n} {r}" for r, n in told.items()))


if __name__ == "__main__":
    main()
