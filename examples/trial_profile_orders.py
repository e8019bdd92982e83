"""Trial (not installed): on each kept profile refit under the cut, the Chapter 5 controller order beside the T3 lead.

The cost ``twin calibrate`` fits and cuts the ensemble by weighs each measured cell's RMSE and SSE; it does not ask
whether the controllers come out in the measured order. The profile trial (``examples/trial_profile_likelihood.py``)
found sets under the cut with FF + PVA ahead of sliding mode in up to all six T3 cells, where the committed preset
has sliding mode ahead in all six. This prints, for every refit under the cut in the kept profile files
(``examples/trial_profile_likelihood/*.json``, in name order, each file's values in the order run), the Chapter 5
cells' order per trajectory on seeds 0-4 (as ``twin validate`` ranks them) against the measured order, and how many
of the six T3 cells sliding mode leads in the kept file. Nothing is fitted or installed; no T3 measurement was seen.

On 2026-11-28 (stop 47) its output was kept as ``examples/trial_profile_likelihood/orders.txt``; docs/investigations.md
quotes it, and a slow test runs it again and gets that text.

    python examples/trial_profile_orders.py
"""

from __future__ import annotations

import json
import pathlib

from twin.experiments import calibrate
from twin.experiments.validate import PREDICTION_CELLS, SEEDS, _known_orders, _order, lead_counts

KEPT = pathlib.Path(__file__).resolve().parent / "trial_profile_likelihood"


def under_cut_refits(folder: pathlib.Path = KEPT) -> list[tuple[str, dict]]:
    """(label, result) of every kept refit under its file's cut, files in name order, values in the order run."""
    out = []
    for path in sorted(folder.glob("*.json")):
        for result in json.loads(path.read_text())["results"]:
            if result["under_cut"]:
                out.append((f"{result['parameter']} {result['at']:g}", result))
    return out


def main() -> None:
    rows = [{"controller": c, "payload_g": g, "orientation": o} for c, _, g, o in PREDICTION_CELLS]
    keys = [k for k in calibrate.CELLS if k in calibrate.EXPERIMENT_CELLS]
    with calibrate.Evaluator(seeds=SEEDS, workers=2) as evaluator:
        measured = None
        for label, result in under_cut_refits():
            cells = evaluator.cells(result["values"], keys=keys)
            if measured is None:
                measured = _order([{"controller": c.controller, "trajectory": c.trajectory,
                                    "measured": calibrate.TARGET_OF[c.key].rmse_deg} for c in cells], "measured")
                print("measured order: " + "; ".join(f"T{t} {order}" for t, order in measured.items()))
            twin = _known_orders(cells)
            right = [t for t in measured if twin.get(t) == measured[t]]
            wrong = "; ".join(f"T{t} {twin[t]}" for t in measured if t not in right)
            ahead = lead_counts(rows, [c["twin_mean"] for c in result["t3"]])[0].get("smc", 0)
            print(f"{label}: cost {result['cost']:.4f}; Chapter 5 order right on {len(right)} of {len(measured)}"
                  + (f" (wrong: {wrong})" if wrong else "") + f"; sliding mode ahead in {ahead} of 6 T3 cells",
                  flush=True)


if __name__ == "__main__":
    main()
