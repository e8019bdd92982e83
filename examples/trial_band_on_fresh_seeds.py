"""Trial (not installed): the T3 prediction's spread over the kept sets that fresh seeds do not show worse than the
best, beside the registered band; with ``--stalls``, whether any of their T3 runs stall.

The registered prediction (``twin/experiments/data/t3_prediction.csv`` and ``t3_prediction_members.csv``, the
committed preset 13aadbb61885 and its 13 ensemble members) gives each T3 cell the committed preset's mean, the
10-90 % band of the members' means and the members' range. The members are the sets whose cost on the fit seeds 0-9
is within the noise of the best's. The fresh-seed trial (``examples/trial_fresh_seed_costs.py``) found that this cut
does not sort sets the way 80 seeds no search ran do: on seeds 40-119, 12 of the 19 kept profile refits over the cut
are not told apart from the best. The team has to decide whether the band should widen; this trial shows, per T3
cell, by how much, under three readings of "fits as well", taken from a kept fresh-seed run
(``examples/trial_fresh_seed_costs/costs_40-119.json`` unless ``--costs`` names another complete kept run of that
trial on the committed preset, whose sets have the values on record):

- **not shown worse**: every distinct kept set (the 13 members and the kept profile results) whose reading there
  against member 0, the committed best, is not "worse" (the best, "not told apart" and "better");
- **not behind**: of those, the sets whose mean paired difference to member 0 is at most two standard errors, so
  not even an unsettled lag behind it;
- **not shown worse than** the set with the lowest mean on those seeds, by the fresh-seed trial's rule: each
  reference is the lowest of many on its own seeds, so each carries that pick's luck.

Each set's T3 cells are the ones on record, on seeds 0-4 as ``twin validate`` runs them: a member's from the
registered members' file, a profile result's from its kept profile file (``examples/kept_profiles.py`` reads them).
A set kept twice counts once. For each cell it prints the registered preset's mean, band and members' range, then
each reading's range over its sets, that range as a multiple of the members' range (like for like: lowest to
highest) and the set at each end; then, per reading, the median and span of those multiples and how many of its
sets have sliding mode ahead in all six T3 cells. That much runs nothing. ``--stalls`` then runs the twelve T3
cells of every set not shown worse again, on seeds 0-4 (70-85 s on 2 cores), and prints per cell the runs that
stall (an error past 30 deg, as ``twin validate`` counts them: the kept files hold the means only) and the range
over the sets with no stall in any cell, and whether each mean is the one on record. The first two readings were
written after seeing the fresh-seed run (stop 49) and before this trial first ran; ``--stalls`` was added after
seeing its first output, which put an 11 deg RMSE on one set, and the third reading after a review of that output
pointed out that the reference decides the count (2026-12-05, stop 50). No T3 measurement was seen, and nothing is
fitted or installed. Its output on the kept run is kept as ``examples/trial_fresh_seed_costs/band.txt``, and with
``--stalls`` as ``band_stalls.txt``.

``--split`` (2026-12-06, stop 51; runs nothing) tests one design the team is to decide on: the fit re-ranking its
candidates on fresh seeds alone. It splits the kept run's seed sets of ten into disjoint draws of four, two and one,
and on each draw alone takes the set with the lowest mean there as the reference and keeps the sets the rule above
does not read worse than it (on a single seed set, where a paired difference has no standard error, the fit's cut: a
mean within the reference's plus the noise, without the fit's cap of 13 members). Over every pair of disjoint draws
it prints how many sets each draw keeps (and how many are kept in every draw, in none and in some), how much two
draws' kept sets overlap (the sets both keep over the sets either keeps), how often they pick the same reference,
and per T3 cell how far the kept sets' lowest and highest means move from draw to draw, against the registered
band's width, and the highest without the set most often highest.
The draws are subsets of the same seeds (40-119 on the kept run), so the pairs are not independent samples; the
candidates are the kept sets, not a search's. It was written after a first look at the same split in a scratch
script (the four-set draws' overlap and the 13.5 g vertical tops); the counts of sets kept in every draw, the ends'
moves against the band and the highest without the set most often highest were added after a review of its first
output. Its output on the kept run is ``band_split.txt``.

    python examples/trial_band_on_fresh_seeds.py [--costs FILE] [--split] [--stalls] [--workers 2]
"""

from __future__ import annotations

import argparse
import collections
import csv
import itertools
import math
import pathlib
import sys

import numpy as np

from twin.experiments import calibrate
from twin.experiments.validate import PREDICTION_CELLS, SEEDS, STALL_ERROR_DEG, lead_counts, stalled_runs
from twin.plants.as_built import CALIBRATION_FILE, ensemble_values, preset_digest
from twin.sim.scenario import CONTROLLER_LABELS

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))  # the sibling modules, however this one is loaded
import kept_profiles  # noqa: E402
from trial_fresh_seed_costs import paired, read_fresh, reading  # noqa: E402

COSTS = kept_profiles.ROOT / "examples" / "trial_fresh_seed_costs" / "costs_40-119.json"
REGISTERED = kept_profiles.ROOT / "twin" / "experiments" / "data"  # t3_prediction.csv, t3_prediction_members.csv
TIE = 2.0  # standard errors: the fresh-seed trial's, for "not behind"
ROW = {"set": str, "values": dict, "fresh_costs": list, "difference": float, "standard_error": float, "reading": str}


def _key(controller: str, payload: float, orientation: str) -> tuple[str, float, str]:
    return controller, float(payload), orientation


def registered() -> tuple[list[dict], dict[int, list[float]]]:
    """The registered prediction's rows (one per T3 cell, in :data:`PREDICTION_CELLS`' order) and each member's
    twelve means in that order."""
    order = [_key(c, g, o) for c, _, g, o in PREDICTION_CELLS]
    with open(REGISTERED / "t3_prediction.csv", newline="") as f:
        rows = {_key(r["controller"], r["payload_g"], r["orientation"]): r for r in csv.DictReader(f)}
    members: dict[int, dict] = {}
    with open(REGISTERED / "t3_prediction_members.csv", newline="") as f:
        for r in csv.DictReader(f):
            members.setdefault(int(r["member"]), {})[_key(r["controller"], r["payload_g"], r["orientation"])] = float(
                r["twin_mean"])
    return [rows[k] for k in order], {m: [means[k] for k in order] for m, means in sorted(members.items())}


def kept_t3(parser: argparse.ArgumentParser) -> dict[str, tuple[dict[str, float], list[float]]]:
    """Each kept profile result's values and twelve T3 means in :data:`PREDICTION_CELLS`' order, by the fresh-seed
    trial's label for it (its file from the kept folder, its parameter and value); a one-line parser error for a kept
    file that is not a complete kept profile run."""
    found = {}
    for path in kept_profiles.files():
        name = str(path.relative_to(kept_profiles.KEPT))
        try:
            results = kept_profiles.read(path)["results"]
        except kept_profiles.KeptFileError as error:
            parser.error(f"{name}: {error}")
        for r in results:
            mean = {_key(t["controller"], t["payload_g"], t["orientation"]): t["twin_mean"] for t in r["t3"]}
            found[f"{name} {r['parameter']} {r['at']:g}"] = (
                r["values"], [mean[_key(c, g, o)] for c, _, g, o in PREDICTION_CELLS])
    return found


def has_band_inputs(kept: dict) -> bool:
    """Whether a kept fresh-seed file (its shape checked by ``read_fresh``) holds what the band trial reads: some sets,
    two or more seed sets of seeds (a standard error needs two), the noise, and each set's row whole with finite costs."""
    return bool(kept["sets"] and len(kept["fresh_seed_sets"]) >= 2
                and all(isinstance(seeds, list) and seeds and all(isinstance(x, int) for x in seeds)
                        for seeds in kept["fresh_seed_sets"])
                and isinstance(kept.get("noise"), float)
                and all(all(isinstance(s.get(k), kind) for k, kind in ROW.items())
                        and all(isinstance(c, float) and math.isfinite(c) for c in s["fresh_costs"])
                        for s in kept["sets"]))


def read_costs(parser: argparse.ArgumentParser, path: pathlib.Path, digest: str) -> dict:
    """The kept fresh-seed run ``path``, or a one-line parser error: not such a complete run (on two or more seed
    sets, as a standard error needs) on the committed preset whose members are the committed file's."""
    kept = read_fresh(parser, "--costs", path, digest, more=has_band_inputs)
    members = [s["values"] for s in kept["sets"] if s["set"].startswith("member ")]
    if members != ensemble_values(CALIBRATION_FILE):
        parser.error(f"--costs {path}: its members are not the committed file's")
    return kept


def spread(sets: list[dict], t3: dict[str, list[float]], cell: int) -> tuple[float, str, float, str]:
    """The lowest and highest mean of T3 cell ``cell`` over ``sets``, each with the set it belongs to."""
    low = min(sets, key=lambda s: t3[s["set"]][cell])
    high = max(sets, key=lambda s: t3[s["set"]][cell])
    return t3[low["set"]][cell], low["set"], t3[high["set"]][cell], high["set"]


def stalls(sets: list[dict], t3: dict[str, list[float]], workers: int) -> tuple[dict[str, list[int]], list[str]]:
    """Each of ``sets``' twelve T3 cells run again on seeds 0-4: its stalled runs per cell by set, and the sets whose
    means are not the ones on record (a member's to its file's twelve digits, a profile result's to the last bit)."""
    found, off = {}, []
    with calibrate.Evaluator(seeds=SEEDS, workers=workers) as evaluator:
        for s in sets:
            cells = evaluator.cells(s["values"], keys=PREDICTION_CELLS, seeds=SEEDS)
            found[s["set"]] = [stalled_runs(c) for c in cells]
            means, kept = [c.mean_rmse for c in cells], t3[s["set"]]
            same = all(abs(m - k) <= 1e-10 * abs(k) for m, k in zip(means, kept, strict=True)) if s["set"].startswith(
                "member ") else means == kept
            if not same:
                off.append(s["set"])
            print(f"  ran {s['set']}", file=sys.stderr, flush=True)
    return found, off


def against(sets: list[dict], reference: dict, noise: float) -> list[dict]:
    """Of ``sets``, those the fresh-seed trial's reading does not call worse than ``reference`` (itself among them),
    each paired with it on the same seed sets by that trial's :func:`paired`, as it pairs them with the best."""
    kept = []
    for s in sets:
        if s is reference or reading(*paired(s["fresh_costs"], reference["fresh_costs"]), noise) != "worse":
            kept.append(s)
    return kept


def draws(count: int, size: int) -> list[tuple[tuple[int, ...], tuple[int, ...]]]:
    """Every pair of disjoint draws of ``size`` of the ``count`` seed sets (indices), each pair once, in order."""
    chosen = list(itertools.combinations(range(count), size))
    return [(a, b) for i, a in enumerate(chosen) for b in chosen[i + 1:] if not set(a) & set(b)]


def rerank(sets: list[dict], draw: tuple[int, ...], noise: float) -> tuple[dict, list[dict]]:
    """The design "re-rank the candidates on fresh seeds", on the seed sets ``draw`` alone: the reference (the set
    with the lowest mean cost there) and the sets whose reading against it there is not worse, by :func:`against`'s
    rule (the reference among them). On one seed set, where a paired difference has no standard error, the fit's own
    choice instead (``calibrate.choose_ensemble``: a cost within the reference's plus the noise), its cap of 13
    members lifted."""
    on = [{**s, "fresh_costs": [s["fresh_costs"][i] for i in draw]} for s in sets]
    reference = min(on, key=lambda s: float(np.mean(s["fresh_costs"])))
    if len(draw) == 1:
        evaluations = [calibrate.Evaluation(s["values"], s["fresh_costs"][0], "fresh") for s in on]
        chosen = {id(e) for e in calibrate.choose_ensemble(evaluations, evaluations[on.index(reference)], noise,
                                                           limit=len(on))}
        kept = [s for s, e in zip(on, evaluations, strict=True) if id(e) in chosen]
    else:
        kept = against(on, reference, noise)
    return reference, kept


def split_test(sets: list[dict], t3: dict[str, list[float]], noise: float, seed_sets: list[list[int]],
               bands: list[float]) -> list[str]:
    """Lines: for draws of 4, 2 and 1 of the ``seed_sets``, :func:`rerank` on each of two disjoint draws alone; how
    many sets each keeps and how many are kept in every draw, in none and in some; how much two disjoint draws' sets
    overlap (shared over either's); how often they pick the same reference; and per T3 cell how far the kept sets'
    lowest and highest means move over the draws, beside ``bands`` (the registered 10-90 % band's width, per cell in
    :data:`PREDICTION_CELLS`' order), and the highest once more without the set most often highest."""
    lines = []
    for size in (4, 2, 1):
        pairs = draws(len(seed_sets), size)
        if not pairs:
            continue
        found = {draw: rerank(sets, draw, noise) for pair in pairs for draw in pair}
        names = {draw: {s["set"] for s in kept} for draw, (_, kept) in found.items()}
        overlap = [len(names[a] & names[b]) / len(names[a] | names[b]) for a, b in pairs]
        sizes = [len(kept) for kept in names.values()]
        times_kept = [sum(s["set"] in kept for kept in names.values()) for s in sets]
        references = collections.Counter(reference["set"] for reference, _ in found.values())
        rule = "not shown worse than it" if size > 1 else "the fit's cut: a mean within its plus the noise, no cap"
        lines.append(
            f"  draws of {size} seed set{'s' if size > 1 else ''} ({sum(len(seed_sets[i]) for i in pairs[0][0])} seeds; "
            f"{len(found)} draws, {len(pairs)} disjoint pairs; kept: {rule}): kept {min(sizes)}-{max(sizes)} sets "
            f"(median {np.median(sizes):g}); of the {len(sets)}, {times_kept.count(len(found))} kept in every draw, "
            f"{times_kept.count(0)} in none, {sum(0 < n < len(found) for n in times_kept)} in some; two disjoint draws "
            f"share {np.median(overlap):.2f} of the sets either keeps (median; {min(overlap):.2f}-{max(overlap):.2f}); "
            f"the same reference in {sum(found[a][0]['set'] == found[b][0]['set'] for a, b in pairs)} of {len(pairs)} "
            "pairs; references: " + ", ".join(f"{name} {n}" for name, n in references.most_common()))
        wider = {"lowest": 0, "highest": 0}  # cells where that end moves more than the registered band is wide
        for i, (controller, _, payload, orientation) in enumerate(PREDICTION_CELLS):
            spans = [spread(kept, t3, i) for _, kept in found.values()]
            lows, highs = [s[0] for s in spans], [s[2] for s in spans]
            wider["lowest"] += max(lows) - min(lows) > bands[i]
            wider["highest"] += max(highs) - min(highs) > bands[i]
            top, times = collections.Counter(high_set for _, _, _, high_set in spans).most_common(1)[0]
            without = [spread([s for s in kept if s["set"] != top], t3, i)[2] for _, kept in found.values()
                       if any(s["set"] != top for s in kept)]
            lines.append(
                f"    {CONTROLLER_LABELS[controller]:12} {payload:4g} g {orientation:10}: lowest {min(lows):.2f}-"
                f"{max(lows):.2f} (moves {max(lows) - min(lows):.2f}), highest {min(highs):.2f}-{max(highs):.2f} "
                f"(moves {max(highs) - min(highs):.2f}) over the draws, the registered band {bands[i]:.2f} wide; the "
                f"highest is {top}'s in {times} of {len(spans)}; without it "
                + (f"{min(without):.2f}-{max(without):.2f}" if without else "no set is kept"))
        lines.append(f"    moving more than the registered band is wide: the highest in {wider['highest']} of "
                     f"{len(PREDICTION_CELLS)} cells, the lowest in {wider['lowest']}")
    return lines


def ratio(low: float, high: float, column: list[float]) -> float:
    """The range ``low``-``high`` as a multiple of the members' range ``column`` (lowest to highest); nan when the
    members agree to the last bit."""
    width = max(column) - min(column)
    return (high - low) / width if width > 0 else math.nan


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--costs", type=pathlib.Path, default=COSTS, metavar="FILE",
                        help="a complete kept run of the fresh-seed trial (default: its seeds 40-119 run)")
    parser.add_argument("--stalls", action="store_true", help="run the sets not shown worse again (T3, seeds 0-4) "
                        "and print the runs that stall, cell by cell")
    parser.add_argument("--split", action="store_true", help="test re-ranking on fresh seeds alone: the seed sets "
                        "split into disjoint draws of 4, 2 and 1, the rule applied on each draw alone (runs nothing)")
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args(argv)
    if args.workers < 1:
        parser.error(f"--workers {args.workers}: at least 1")
    digest = preset_digest(CALIBRATION_FILE)
    kept = read_costs(parser, args.costs, digest)
    rows, members = registered()
    t3 = {f"member {m}": means for m, means in members.items()}
    for label, (values, means) in kept_t3(parser).items():
        row = next((s for s in kept["sets"] if s["set"] == label), None)
        if row is not None and row["values"] != values:
            parser.error(f"--costs {args.costs}: {label} has other values than its kept profile result")
        t3.setdefault(label, means)
    missing = [s["set"] for s in kept["sets"] if s["set"] not in t3]
    if missing:
        parser.error(f"--costs {args.costs}: no T3 cells on record for {missing[0]}")
    distinct: dict[str, dict] = {}
    for s in kept["sets"]:  # a set kept twice counts once, under its first label
        distinct.setdefault(kept_profiles.set_key(s["values"]), s)
    lowest = min(distinct.values(), key=lambda s: float(np.mean(s["fresh_costs"])))
    readings = {
        "not shown worse": [s for s in distinct.values() if s["reading"] != "worse"],
        "not behind": [s for s in distinct.values() if s["reading"] != "worse"
                       and s["difference"] <= TIE * s["standard_error"]],
        f"not shown worse than {lowest['set']}": against(list(distinct.values()), lowest, kept["noise"]),
    }
    seeds = kept["fresh_seed_sets"]
    print(f"preset {digest}; readings from {kept_profiles.shown(args.costs)} (seeds {seeds[0][0]}-{seeds[-1][-1]}): "
          f"{len(distinct)} distinct sets; against {kept['sets'][0]['set']} (the best on the fit's seeds) "
          + ", ".join(f"{len(v)} {k}" for k, v in readings.items())
          + " (the lowest on these seeds, the same rule); T3 means on seeds 0-4 (deg); each range also as a "
          "multiple of the members' range")
    widest = {name: [] for name in readings}
    for i, (row, (controller, _, payload, orientation)) in enumerate(zip(rows, PREDICTION_CELLS, strict=True)):
        column = [means[i] for means in members.values()]
        p10, p90 = float(row["band_p10"]), float(row["band_p90"])
        print(f"  {CONTROLLER_LABELS[controller]:12} {payload:4g} g {orientation:10}: preset "
              f"{float(row['twin_mean']):.2f}, band {p10:.2f}-{p90:.2f}, members {min(column):.2f}-{max(column):.2f}")
        for name, sets in readings.items():
            low, low_set, high, high_set = spread(sets, t3, i)
            widest[name].append(ratio(low, high, column))
            print(f"    {name}: {low:.2f}-{high:.2f}, {widest[name][-1]:.1f}x (low {low_set}; high {high_set})")
    cells = kept_profiles.t3_rows()
    for name, sets in readings.items():
        leads = [lead_counts(cells, t3[s["set"]])[0] for s in sets]
        times = sorted(w for w in widest[name] if not math.isnan(w))
        print(f"{name}: its range {np.median(times):.1f}x the members' (median of the cells; "
              f"{times[0]:.1f}x-{times[-1]:.1f}x); sliding mode ahead in all six T3 cells on "
              f"{sum(lead.get('smc', 0) == 6 for lead in leads)} of {len(sets)} sets, FF + PVA ahead in one or more "
              f"on {sum(lead.get('ffpva', 0) > 0 for lead in leads)}")
    if args.split:
        print(f"re-ranked on fresh seeds, by split (a design the fit could use, tested on these costs): the "
              f"{len(seeds)} seed sets drawn apart; on each draw alone the reference is the set with the lowest "
              f"mean there and the kept sets those the rule does not read worse than it; T3 means on seeds 0-4 (deg)")
        bands = [float(row["band_p90"]) - float(row["band_p10"]) for row in rows]
        print("\n".join(split_test(list(distinct.values()), t3, kept["noise"], seeds, bands)))
    if args.stalls:
        sets = readings["not shown worse"]
        stalled, off = stalls(sets, t3, args.workers)
        steady = [s for s in sets if not any(stalled[s["set"]])]
        print(f"run again on seeds 0-4: the {len(stalled)} sets not shown worse; runs whose error passes "
              f"{STALL_ERROR_DEG:g} deg (stalled), per T3 cell, and the range over the {len(steady)} sets with no "
              "stall in any cell; means as on record: " + ("all" if not off else "not on " + ", ".join(off)))
        for i, (controller, _, payload, orientation) in enumerate(PREDICTION_CELLS):
            which = [f"{name} ({n[i]})" for name, n in stalled.items() if n[i]]
            low, _, high, _ = spread(steady, t3, i)
            column = [means[i] for means in members.values()]
            print(f"  {CONTROLLER_LABELS[controller]:12} {payload:4g} g {orientation:10}: "
                  f"{sum(n[i] for n in stalled.values())} of {len(SEEDS) * len(stalled)} runs"
                  + (f" ({'; '.join(which)})" if which else "")
                  + f"; with no stall {low:.2f}-{high:.2f}, {ratio(low, high, column):.1f}x")


if __name__ == "__main__":
    main()
