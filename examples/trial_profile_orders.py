"""Trial (not installed): on each kept profile refit under the cut, the Chapter 5 controller order beside the T3 lead.

The cost ``twin calibrate`` fits and cuts the ensemble by weighs each measured cell's RMSE and SSE; it does not ask
whether the controllers come out in the measured order. The profile trial (``examples/trial_profile_likelihood.py``)
found sets under the cut with FF + PVA ahead of sliding mode in up to all six T3 cells, where the committed preset
has sliding mode ahead in all six. This prints, for every refit under the cut in the kept profile files given (by
default every ``examples/trial_profile_likelihood/*.json``, in name order; each file's values in the order run, after
a line naming the file and the preset it ran on), the Chapter 5 cells' order per trajectory on seeds 0-4 (as ``twin
validate`` ranks them) against the measured order, and how many of the six T3 cells sliding mode leads in the kept
file. A file that is not a complete kept profile run is refused in one line, before any run, in the words of
``examples/kept_profiles.py``, which reads them for the three trials. Nothing is fitted or installed; no T3
measurement was seen.

On 2026-11-28 (stop 47) its output on the five kept files was kept as
``examples/trial_profile_likelihood/orders.txt``; docs/investigations.md quotes it, and a slow test runs it again
and gets that text. On 2026-11-29 (stop 48) its output on the longer searches' seven files (given in name order)
was kept as ``examples/trial_profile_likelihood/longer/orders.txt``, also run again by a slow test; on 2026-11-29
(stop 49) its output on the four continued searches' files as ``continued/orders.txt``.

    python examples/trial_profile_orders.py [FILE ...] [--workers 2]
    python examples/trial_profile_orders.py examples/trial_profile_likelihood/longer/*.json
"""

from __future__ import annotations

import argparse
import pathlib
import sys

from twin.experiments import calibrate
from twin.experiments.validate import SEEDS, controller_order, known_orders, lead_counts

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))  # the sibling module, however this one is loaded
import kept_profiles  # noqa: E402


def smc_ahead(result: dict) -> int:
    """How many of the six T3 payload and orientation cells sliding mode leads in, from a kept result's cells
    (matched to :data:`PREDICTION_CELLS` by controller, payload and orientation)."""
    mean = {(t["controller"], t["payload_g"], t["orientation"]): t["twin_mean"] for t in result["t3"]}
    rows = kept_profiles.t3_rows()
    return lead_counts(rows, [mean[(r["controller"], r["payload_g"], r["orientation"])] for r in rows])[0].get(
        "smc", 0)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("files", nargs="*", type=pathlib.Path, metavar="FILE",
                        help="kept profile trial files (default: every one kept beside this script)")
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args(argv)
    if args.workers < 1:
        parser.error(f"--workers {args.workers}: give 1 or more")
    paths = args.files or sorted(kept_profiles.KEPT.glob("*.json"))
    kept = []
    for path in paths:
        try:
            kept.append((path, kept_profiles.read(path)))
        except kept_profiles.KeptFileError as error:
            parser.error(f"{path}: {error}")
    keys = [k for k in calibrate.CELLS if k in calibrate.EXPERIMENT_CELLS]
    measured = controller_order([{"controller": k[0], "trajectory": k[1],
                                  "measured": calibrate.TARGET_OF[k].rmse_deg} for k in keys], "measured")
    print("measured order: " + "; ".join(f"T{t} {order}" for t, order in measured.items()))
    with calibrate.Evaluator(seeds=SEEDS, workers=args.workers) as evaluator:
        for path, file in kept:
            under = [r for r in file["results"] if r["under_cut"]]
            print(f"{path.name} (preset {file.get('preset')}): {len(under)} of {len(file['results'])} under the cut",
                  flush=True)
            for result in under:
                twin = known_orders(evaluator.cells(result["values"], keys=keys))
                right = [t for t in measured if twin.get(t) == measured[t]]
                wrong = "; ".join(f"T{t} {twin[t]}" for t in measured if t not in right)
                print(f"  {result['parameter']} {result['at']:g}: cost {result['cost']:.4f}; Chapter 5 order right on "
                      f"{len(right)} of {len(measured)}" + (f" (wrong: {wrong})" if wrong else "")
                      + f"; sliding mode ahead in {smc_ahead(result)} of 6 T3 cells", flush=True)


if __name__ == "__main__":
    main()
