"""The kept profile files (not installed, not a trial): where they lie, how one is read and checked, and how a kept
file names a path.

``examples/trial_profile_likelihood.py`` writes them; it (``--check``), ``trial_profile_orders.py`` and
``trial_fresh_seed_costs.py`` read them through :func:`read`, so the three refuse a file that is not one in the same
words. The trials that read them also take from here the T3 cells' rows (:func:`t3_rows`) and the key that makes two
kept rows one set (:func:`set_key`). A trial loads this module from its own folder (``sys.path``), however the trial
itself is loaded.
"""

from __future__ import annotations

import json
import math
import pathlib

from twin.experiments.validate import PREDICTION_CELLS
from twin.plants.as_built import FITTED

ROOT = pathlib.Path(__file__).resolve().parent.parent  # the checkout
KEPT = ROOT / "examples" / "trial_profile_likelihood"  # the profile trial's kept files, and sub-folders of them
CELLS = sorted((c, g, o) for c, _, g, o in PREDICTION_CELLS)  # the T3 cells a kept result holds, by key
EVALUATION = {"parameter", "at", "cost", "values"}  # what a kept evaluation holds


def t3_rows() -> list[dict]:
    """The twelve T3 cells as ``twin validate``'s ``lead_counts`` reads them (controller, payload g, orientation), in
    :data:`PREDICTION_CELLS`' order: a new list each call."""
    return [{"controller": c, "payload_g": g, "orientation": o} for c, _, g, o in PREDICTION_CELLS]


def set_key(values: dict[str, float]) -> str:
    """One key for a parameter set's values, whatever label it is kept under: two kept rows with the same key are one
    set (the same values to the last bit; not ``twin calibrate``'s test of a repeated evaluation in the unit box)."""
    return json.dumps(values, sort_keys=True)


class KeptFileError(ValueError):
    """A file that is not a kept profile trial file (or not a complete one): its one-line reason."""


def files(folder: pathlib.Path | None = None) -> list[pathlib.Path]:
    """The kept profile files in ``folder`` (by default :data:`KEPT`, read when called): its own, then each
    sub-folder's, each in name order."""
    folder = KEPT if folder is None else folder
    return sorted(folder.glob("*.json")) + sorted(folder.glob("*/*.json"))


def _number(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def is_result(r) -> bool:
    """Whether ``r`` is a result as the profile trial keeps it: the parameter, its value, a finite cost and the cut's
    reading, every fitted parameter's value and the twelve T3 cells."""
    return (isinstance(r, dict) and {"parameter", "at", "cost", "under_cut", "values", "t3"} <= set(r)
            and isinstance(r["parameter"], str) and _number(r["at"])
            and isinstance(r["cost"], float) and math.isfinite(r["cost"])
            and isinstance(r["values"], dict) and set(r["values"]) == {f.name for f in FITTED}
            and isinstance(r["t3"], list)
            and all(isinstance(t, dict) and isinstance(t.get("controller"), str) and _number(t.get("payload_g"))
                    and isinstance(t.get("orientation"), str) and _number(t.get("twin_mean")) for t in r["t3"])
            and sorted((t["controller"], t["payload_g"], t["orientation"]) for t in r["t3"]) == CELLS)


def read(path: pathlib.Path, complete: bool = True) -> dict:
    """The kept profile trial file ``path``; a :class:`KeptFileError` when it is not JSON, has not the results and
    evaluations the trial writes, or (``complete``) is a stopped run."""
    try:
        kept = json.loads(pathlib.Path(path).read_text())
    except (OSError, UnicodeDecodeError, ValueError) as error:
        raise KeptFileError(f"cannot read it as JSON ({error.__class__.__name__})") from None
    if not (isinstance(kept, dict) and isinstance(kept.get("results"), list)
            and all(is_result(r) for r in kept["results"])):
        raise KeptFileError("not a kept profile trial file (no results as the trial writes them)")
    if complete and kept.get("complete") is not True:
        raise KeptFileError("a stopped profile run (not complete): run it whole first")
    if not (kept["results"] and isinstance(kept.get("evaluations"), list) and all(
            isinstance(e, dict) and EVALUATION <= set(e) for e in kept["evaluations"])):
        raise KeptFileError("not a kept profile trial file (no results as the trial writes them)")
    return kept


def shown(path) -> str:
    """``path`` as a kept file names it: from the checkout's root when it lies in it, else as given."""
    try:
        return str(pathlib.Path(str(path)).resolve().relative_to(ROOT))
    except ValueError:
        return str(path)
