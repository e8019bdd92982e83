"""``twin score --measured FILE --out DIR``: the blind T3 prediction held against the measured Chapter 6 T3
cells, by rules written down on 2026-11-26, before any T3 measurement was seen.

The prediction is the committed one (``data/t3_prediction.csv`` and ``data/t3_prediction_members.csv`` beside
this module: ``twin validate``'s ``prediction.csv`` and ``prediction_members.csv`` on the committed as-built
preset), or the one in a ``twin validate`` output folder (``--prediction DIR``). Either must be a prediction
on record before the data (:data:`REGISTERED`, by its files' SHA-256): a file changed since, or a refit's new
prediction, is refused unless ``--unregistered`` is given, and then every output says it is not on record.
The measurements are a CSV with one row per T3 cell, twelve in all (:data:`MEASURED_COLUMNS`; ``trajectory``,
``runs`` and ``stalled_runs`` may be left out: T3, five runs, not stated; ``runs`` and ``stalled_runs`` each on
every row or on none; no other column)::

    controller,payload_g,orientation,rmse_mean_deg,rmse_std_deg
    smc,13.5,vertical,3.1,0.4
    ...

``controller`` is ``ffpva`` or ``smc`` (or ``FF + PVA``, ``sliding mode``).

The rules (:func:`score`). Changing one after a measurement has been seen is a new rule, to be said so.

* Per cell: ``ratio`` = the committed preset's mean over the measured mean; ``within`` when it is within
  20 % (the tolerance of every measured RMSE in ``twin validate``); ``in_band`` when the measured mean lies in
  the ensemble's 10-90 % band; ``in_members`` when it lies in the members' range (lowest to highest member
  mean); ``z``, the committed mean's distance from the measured mean in the measured mean's standard errors
  (std / sqrt(runs)). Each is judged on the numbers as given and computed, unrounded (``score.md`` prints
  them to 3 decimals, or more where a band's end or the ratio would read equal to what it is compared with,
  so that a verdict can be read off its table; added 2026-11-27, before any T3 measurement was seen, after a
  review found a 2-decimal table that read "in" beside a "no").
* Per payload and orientation: which controller tracked better, measured and predicted (the committed
  means), or neither when the two means are equal; the measured order is **a toss** when the two measured
  means differ by less than two combined standard errors (or are equal). Right: the same answer.
* The thesis's three robustness conclusions, on T3, measured and predicted: (1) the cost of 13.5 g
  horizontal, 13.5 g over 0 g horizontal, per controller; (2) the cost of 13.5 g vertical, 13.5 g over 0 g
  vertical, per controller, and the stalled runs; (3) in how many of the six payload-and-orientation pairs
  sliding mode tracked better than FF + PVA. A cost ratio agrees when the predicted one is within 20 % of
  the measured one.
"""

from __future__ import annotations

import argparse
import csv
import dataclasses
import hashlib
import importlib.resources
import io
import math
import os
import pathlib

import numpy as np

from twin.batch.grid import plain_number
from twin.batch.tables import write_csv
from twin.exceptions import InvalidScenario
from twin.experiments import arguments
from twin.experiments.base import Experiment, Outcome, drawn
from twin.experiments.calibrate import THESIS_RUNS
from twin.experiments.reference import THESIS_EXPERIMENT_RMSE_DEG
from twin.experiments.validate import (
    PREDICTION_CELLS,
    PREDICTION_COLUMNS,
    PREDICTION_MEMBER_COLUMNS,
    RMSE_TOLERANCE,
    rmse_within,
)
from twin.experiments.validate import SEEDS as VALIDATE_SEEDS
from twin.physics.params import GearParams, SensorParams
from twin.sim.scenario import CONTROLLER_LABELS

COMMITTED = importlib.resources.files("twin.experiments") / "data"  # package data
COMMITTED_FILES = ("t3_prediction.csv", "t3_prediction_members.csv")
VALIDATE_FILES = ("prediction.csv", "prediction_members.csv")  # the same two, as `twin validate` names them
RULES_WRITTEN = "2026-11-26"  # before any T3 measurement was seen
MEASURED_COLUMNS = ("controller", "payload_g", "orientation", "rmse_mean_deg", "rmse_std_deg")
OPTIONAL_COLUMNS = ("trajectory", "runs", "stalled_runs")  # the measured file may give these too, nothing else
MAX_BYTES = 1_000_000  # a file of twelve cells is under 1 kB; past this it is the wrong file (or /dev/zero)
MAX_RUNS = 1000  # runs per measured cell: more is a typing error, not a rig's day (left out: the thesis's five)
# A measured RMSE below the Hall sensor's noise bound (0.02 mm of rack, 0.24 deg; SPEC §5) is no measurement of
# this rig (most likely radians); above half a turn, none either (the joint's range is 180 deg).
SMALLEST_MEAN_DEG = round(math.degrees(SensorParams().position_noise / GearParams().spur_radius), 2)  # 0.24 deg
LARGEST_DEG = 180.0


@dataclasses.dataclass(frozen=True)
class Registration:
    """A blind T3 prediction on record before any T3 measurement was seen: its two files' SHA-256 (the
    cells', then the members'), as ``twin validate`` wrote them."""

    name: str  # how score.md names it
    registered: str  # the date it was put on record
    preset: str  # the as-built preset digest it was run on (twin.plants.as_built.preset_digest)
    cells_sha256: str
    members_sha256: str


# Every prediction `twin score` scores without --unregistered. Append-only: a refit's new prediction is added at the
# end, dated, only while no T3 measurement has been seen, and no entry is ever changed or removed (a test pins them).
# The packaged files must be one of them (a test holds them to it).
REGISTERED = (
    Registration("the sixth blind prediction (the tenth refit's)", "2026-11-27", "1c2dcd8c9f7f",
                 "aa932337bc6b2b5cbe920d14f1e46eb0f1955785740ec3371327bcd43b3d9765",
                 "32a6f6bce0291874960e0c1930f1bb583640573622aa0ae3cc85bb0c5e3ede8b"),
    Registration("the fifth blind prediction (the ninth refit's; examples/ninth_refit_prediction)", "2026-11-26",
                 "57ff10bf5b36", "4ca2fdca0a4787d6160e019683c8ce61155b0cf091b73cc28d26e35b3089c344",
                 "28fd859f4e2881dc5f83e518ec09c3349ac275a3a128c23edd07060447ae3e2a"),
    Registration("the air-box trial's prediction (examples/trial_air_box)", "2026-11-27", "3da50147f0ac",
                 "9a133fe747948cb0f2e545f1cfb91eb747337ec1cdcf50c050ae0803b764ea8f",
                 "37fe7c0cde01d1201163677fc6df1d5b2f16228b36ead834fa8185c0a122bcb5"),
    Registration("the seventh blind prediction (the eleventh refit's; the sixth's files now in "
                 "examples/tenth_refit_prediction)", "2026-11-28", "78c00bbdf7e4",
                 "45b22c579d3cffb7071c12532cd5728eda7af9905332ad1178ccf62049d9abb7",
                 "5af4f15319e6598089c10508607f6f0735b0a48ef078195803026f2eae1b2194"),
    Registration("the eighth blind prediction (the twelfth refit's; the seventh's files now in "
                 "examples/eleventh_refit_prediction)", "2026-11-28", "6bb9e9258023",
                 "c8422e3c611597f727a40d1e98002c5df2676fc132d40a3a4bc6f5c1fca0d99a",
                 "a7d63a492a6704b2573d16fe13982f682fcf319ff8a6c933d0d447dbabcd6bb1"),
    Registration("the ninth blind prediction (the thirteenth refit's; the eighth's files now in "
                 "examples/twelfth_refit_prediction)", "2026-11-28", "13aadbb61885",
                 "2d0fb3160c9d6f7b13547b5b7be4415490d953b64caa14de745542a70c7d9a6a",
                 "ec338bcdb86e2d0dc9a8a35bb064c244e089a11d50ecc956580a188aee28e807"),
)
TIE = "tie"  # the two means equal: neither tracked better (and the order is a toss)
ORDER_LABELS = {**CONTROLLER_LABELS, TIE: "neither (equal means)"}
TOSS_SE = 2.0  # measured means closer than this many combined standard errors: the order is a toss
SCORE_COLUMNS = ("controller", "payload_g", "orientation", "measured", "measured_std", "runs", "twin_mean",
                 "band_p10", "band_p90", "member_low", "member_high", "ratio", "within", "in_band", "in_members", "z",
                 "measured_stalled_runs", "twin_stalled_runs", "twin_runs", "registered")
ORDER_COLUMNS = ("payload_g", "orientation", "measured_better", "measured_toss", "predicted_better", "right",
                 "registered")  # registered: whether the prediction scored is on record (false: --unregistered)
CONTROLLER_NAMES = {**{name: name for name in CONTROLLER_LABELS}, **{label.lower(): name for name, label in
                                                                      CONTROLLER_LABELS.items()}}
CELL_KEYS = tuple((c, g, o) for c, _, g, o in PREDICTION_CELLS)  # (controller, payload g, orientation)


def _read(path, what: str) -> tuple[list[str], list[tuple[int, dict]]]:
    """A CSV's column names and its rows, each with the line it ends on; blank rows left out, before the
    header too, and columns without a name whose every cell is blank (a spreadsheet's trailing commas).
    One-line :class:`InvalidScenario` errors for a file that cannot be read or is over :data:`MAX_BYTES`, a
    repeated column name, a column without a name that holds values, or a row with more values than the
    header or fewer fields than its named columns. ``path`` may be a package resource."""
    try:
        with importlib.resources.as_file(path) as real, open(real, newline="", encoding="utf-8-sig") as handle:
            text = handle.read(MAX_BYTES + 1)
        if len(text) > MAX_BYTES:
            raise InvalidScenario(f"{what} {str(path)!r} is over {MAX_BYTES // 1_000_000} MB: not a table of T3 cells")
        reader = csv.reader(io.StringIO(text, newline=""))
        lines = [(reader.line_num, [cell.strip() for cell in row]) for row in reader]
        lines = [(line, row) for line, row in lines if any(row)]  # blank rows, and rows of empty cells
        header = lines[0][1] if lines else []
        columns = [c for c in header if c]
        repeated = sorted({c for c in columns if columns.count(c) > 1})
        if repeated:
            raise InvalidScenario(f"{what} {str(path)!r} names the column(s) {', '.join(repeated)} more than once")
        rows = []
        named = max((i + 1 for i, name in enumerate(header) if name), default=0)
        for line, row in lines[1:]:
            if len(row) < named:  # padding it would name a wrong cell ("no T3 cell sliding mode 13.5 g  ...")
                raise InvalidScenario(f"{what} {str(path)!r} line {line} has fewer fields than its header "
                                      f"({len(row)} of {named})")
            row = row + [""] * (len(header) - len(row))
            extra = [cell for cell in row[len(header):] if cell]
            unnamed = [i for i, (name, cell) in enumerate(zip(header, row, strict=False)) if not name and cell]
            if extra:
                raise InvalidScenario(f"{what} {str(path)!r} line {line} has more fields than its header")
            if unnamed:
                raise InvalidScenario(f"{what} {str(path)!r} line {line} has a value in column {unnamed[0] + 1}, "
                                      "which has no name in the header")
            rows.append((line, {name: cell for name, cell in zip(header, row, strict=False) if name}))
        return columns, rows
    except FileNotFoundError:
        raise InvalidScenario(f"{what} {str(path)!r} does not exist") from None
    except IsADirectoryError:
        raise InvalidScenario(f"{what} {str(path)!r} is a folder, not a CSV file") from None
    except (OSError, UnicodeDecodeError, csv.Error) as error:
        raise InvalidScenario(f"cannot read {what} {str(path)!r}: {error}".splitlines()[0]) from None


def _number(text: str, where: str, column: str, *, low: float = 0.0, high: float = math.inf,
            hint: str = "", above: bool = False) -> float:
    """``text`` as a finite number from ``low`` (past it if ``above``) to ``high``, else a one-line error
    (ending in ``hint``)."""
    try:
        value = plain_number(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value) or not low <= value <= high or (above and value == low):
        bound = ("a finite number" if low == -math.inf else f"a number above {low:g}, at most {high:g}" if above
                 else f"a number of at least {low:g}" if high == math.inf else f"a number from {low:.3g} to {high:g}")
        raise InvalidScenario(f"{where}: {column} must be {bound}, got {text!r}{hint}")
    return value


def _whole(text: str, where: str, column: str, low: int, high: int) -> int:
    """``text`` as a whole number from ``low`` to ``high``, else a one-line error (leading zeros allowed)."""
    digits = text.lstrip("0") or "0"  # int() refuses over 4300 digits: the length is checked first
    if not (text.isascii() and text.isdigit()) or len(digits) > len(str(high)) or not low <= int(digits) <= high:
        raise InvalidScenario(f"{where}: {column} must be a whole number from {low} to {high}, got {text!r}")
    return int(digits)


def _cell_key(row: dict, where: str) -> tuple[str, float, str]:
    name = CONTROLLER_NAMES.get(row["controller"].lower())
    if name not in ("ffpva", "smc"):
        raise InvalidScenario(f"{where}: controller must be ffpva or smc (FF + PVA, sliding mode), "
                              f"got {row['controller']!r}")
    payload = _number(row["payload_g"], where, "payload_g")
    orientation = row["orientation"].lower()
    key = (name, payload, orientation)
    if key not in CELL_KEYS:
        raise InvalidScenario(f"{where}: no T3 cell {CONTROLLER_LABELS[name]} {row['payload_g']} g {row['orientation']}"
                              f" (payloads 0, 6.5, 13.5 g; horizontal or vertical)")
    if row.get("trajectory", "3") not in ("", "3"):
        raise InvalidScenario(f"{where}: only the T3 cells are scored, got trajectory {row['trajectory']!r}")
    return key


def _each_cell(rows: list[tuple[int, dict]], path, found: dict):
    """(where, cell key, row) for each of ``_read``'s rows, refusing a cell already in ``found``."""
    for line, row in rows:
        where = f"{path.name} line {line}"
        key = _cell_key(row, where)
        if key in found:
            raise InvalidScenario(f"{where}: {CONTROLLER_LABELS[key[0]]} {key[1]:g} g {key[2]} is given twice")
        yield where, key, row


def _complete(found: dict, what: str) -> None:
    missing = [k for k in CELL_KEYS if k not in found]
    if missing:
        names = ", ".join(f"{CONTROLLER_LABELS[c]} {g:g} g {o}" for c, g, o in missing)
        raise InvalidScenario(f"{what} lacks {len(missing)} of the 12 T3 cells: {names}")


def read_measured(path: pathlib.Path) -> dict[tuple, dict]:
    """The measured T3 cells, by (controller, payload g, orientation): mean, std, runs and stalled runs (None
    when not given). Raises :class:`InvalidScenario` with one line naming the first bad row."""
    columns, rows = _read(path, "measured file")
    lacking = [c for c in MEASURED_COLUMNS if c not in columns]
    if lacking:
        hint = " (its fields must be separated by commas)" if any(";" in c or "\t" in c for c in columns) else ""
        raise InvalidScenario(f"measured file {str(path)!r} lacks the column(s) {', '.join(lacking)} "
                              f"(it needs {', '.join(MEASURED_COLUMNS)}){hint}")
    unknown = [c for c in columns if c not in MEASURED_COLUMNS + OPTIONAL_COLUMNS]
    if unknown:
        raise InvalidScenario(f"measured file {str(path)!r} has the column(s) {', '.join(unknown)}, which are not "
                              f"read (it takes {', '.join(MEASURED_COLUMNS)}; optional: {', '.join(OPTIONAL_COLUMNS)})")
    found: dict[tuple, dict] = {}
    degrees = (f" (degrees, from the Hall sensor's noise, {SMALLEST_MEAN_DEG:g}, to half a turn; radians "
               f"would be about 57 times smaller)")
    runs_given = []
    for where, key, row in _each_cell(rows, path, found):
        runs = _whole(row.get("runs") or str(THESIS_RUNS), where, "runs", 2, MAX_RUNS)
        runs_given += [key] if row.get("runs") else []
        stalled = row.get("stalled_runs") or None
        found[key] = {"mean": _number(row["rmse_mean_deg"], where, "rmse_mean_deg", low=SMALLEST_MEAN_DEG,
                                      high=LARGEST_DEG, hint=degrees),
                      # above 0: the standard errors divide by it (a 0 made every z infinite until 2026-12-08)
                      "std": _number(row["rmse_std_deg"], where, "rmse_std_deg", high=LARGEST_DEG, above=True,
                                     hint=" (a std a table rounds to 0 is under half its last digit: give that)"),
                      "runs": runs,
                      "stalled": None if stalled is None else _whole(stalled, where, "stalled_runs", 0, runs)}
    _complete(found, f"measured file {str(path)!r}")
    if runs_given and len(runs_given) != len(found):  # a blank would silently be five beside stated tens
        blank = next(f"{CONTROLLER_LABELS[c]} {g:g} g {o}" for c, g, o in found if (c, g, o) not in runs_given)
        raise InvalidScenario(f"measured file {str(path)!r} gives runs on {len(runs_given)} of the 12 cells "
                              f"(not on {blank}): give it on every cell or on none (five runs)")
    given = [key for key, cell in found.items() if cell["stalled"] is not None]
    if given and len(given) != len(found):
        blank = next(f"{CONTROLLER_LABELS[c]} {g:g} g {o}" for (c, g, o), cell in found.items()
                     if cell["stalled"] is None)
        raise InvalidScenario(f"measured file {str(path)!r} gives stalled_runs on {len(given)} of the 12 cells "
                              f"(not on {blank}): give it on every cell or on none")
    return found


def prediction_files(folder: pathlib.Path | None) -> tuple:
    """The prediction's two files: the committed ones, or a ``twin validate`` output folder's."""
    if folder is None:
        return tuple(COMMITTED / name for name in COMMITTED_FILES)
    if not folder.is_dir():
        raise InvalidScenario(f"--prediction {str(folder)!r} is not a folder (give a twin validate --out folder)")
    return tuple(folder / name for name in VALIDATE_FILES)


def registration(folder: pathlib.Path | None = None) -> Registration | None:
    """The :data:`REGISTERED` prediction whose two files ``folder``'s are, byte for byte (the committed ones by
    default), or None. A file that cannot be read is left to :func:`read_prediction` to name."""
    try:
        digests = tuple(hashlib.sha256(path.read_bytes()).hexdigest() for path in prediction_files(folder))
    except OSError:
        return None
    return next((r for r in REGISTERED if (r.cells_sha256, r.members_sha256) == digests), None)


def _same_file(a: pathlib.Path, b: pathlib.Path) -> bool:
    """Whether ``a`` and ``b`` are one file (False if either cannot be looked at)."""
    try:
        return os.path.samefile(a, b)
    except (OSError, ValueError, TypeError):
        return False


def read_prediction(folder: pathlib.Path | None = None) -> dict[tuple, dict]:
    """The prediction by (controller, payload g, orientation): the committed mean, the 10-90 % band, every
    member's mean, the stalled runs and the runs they are of (every member's). Whether it is on record is
    :func:`registration`'s question."""
    cells_path, members_path = prediction_files(folder)
    columns, rows = _read(cells_path, "prediction file")
    member_columns, member_rows = _read(members_path, "prediction file")
    if columns != list(PREDICTION_COLUMNS) or member_columns != list(PREDICTION_MEMBER_COLUMNS):
        raise InvalidScenario(f"{str(cells_path)!r} and {str(members_path)!r} are not twin validate's prediction files")
    found: dict[tuple, dict] = {}
    for where, key, row in _each_cell(rows, cells_path, found):
        found[key] = {**{name: _number(row[column], where, column, low=SMALLEST_MEAN_DEG, high=LARGEST_DEG)
                         for name, column in (("mean", "twin_mean"), ("p10", "band_p10"), ("p90", "band_p90"))},
            "stalled": _whole(row["stalled_runs"], where, "stalled_runs", 0, 10**9), "members": {}}
    for line, row in member_rows:
        where = f"{members_path.name} line {line}"
        key, member = _cell_key(row, where), _whole(row["member"], where, "member", 0, 10**6)
        if key not in found:
            raise InvalidScenario(f"{where}: {CONTROLLER_LABELS[key[0]]} {key[1]:g} g {key[2]} is not in "
                                  f"{cells_path.name}")
        members = found[key]["members"]
        if member in members:
            raise InvalidScenario(f"{where}: member {member} of the cell is given twice")
        members[member] = _number(row["twin_mean"], where, "twin_mean", low=SMALLEST_MEAN_DEG, high=LARGEST_DEG)
    _complete(found, f"prediction {str(cells_path.parent)!r}")
    counts = {len(cell["members"]) for cell in found.values()}
    if len(counts) != 1 or 0 in counts:
        raise InvalidScenario(f"{str(members_path)!r} does not give every T3 cell the same members")
    for cell in found.values():
        cell["members"] = [cell["members"][k] for k in sorted(cell["members"])]
        cell["runs"] = len(cell["members"]) * len(VALIDATE_SEEDS)
    return found


def _cost(cells: dict, controller: str, payload_g: float, orientation: str) -> float:
    """What a payload costs a controller: its cell's mean over the same controller's 0 g cell, same side."""
    return cells[controller, payload_g, orientation]["mean"] / cells[controller, 0.0, orientation]["mean"]


def _in_standard_errors(difference: float, se: float) -> float:
    """``difference / se``; with no spread measured (std 0), 0 or an infinity of the difference's sign."""
    if se > 0:
        return difference / se
    return math.copysign(math.inf, difference) if difference else 0.0


def _better(ffpva: float, smc: float) -> str:
    """Which controller tracked better (the lower RMSE), or :data:`TIE`."""
    return "smc" if smc < ffpva else "ffpva" if ffpva < smc else TIE


def score(measured: dict[tuple, dict], predicted: dict[tuple, dict]) -> dict:
    """The rules of the module docstring: ``cells`` (:data:`SCORE_COLUMNS`), ``orders``
    (:data:`ORDER_COLUMNS`) and ``conclusions``."""
    cells = []
    for key in CELL_KEYS:
        m, p = measured[key], predicted[key]
        se = m["std"] / math.sqrt(m["runs"])
        ratio = p["mean"] / m["mean"]
        low, high = min(p["members"]), max(p["members"])
        cells.append({"controller": key[0], "payload_g": key[1], "orientation": key[2], "measured": m["mean"],
                      "measured_std": m["std"], "runs": m["runs"], "twin_mean": p["mean"], "band_p10": p["p10"],
                      "band_p90": p["p90"], "member_low": low, "member_high": high,
                      "ratio": ratio, "within": bool(rmse_within(p["mean"], m["mean"])),
                      "in_band": p["p10"] <= m["mean"] <= p["p90"],
                      "in_members": low <= m["mean"] <= high,
                      "z": _in_standard_errors(p["mean"] - m["mean"], se), "measured_stalled_runs": m["stalled"],
                      "twin_stalled_runs": p["stalled"], "twin_runs": p["runs"]})
    orders = []
    for payload_g, orientation in dict.fromkeys((g, o) for _, g, o in CELL_KEYS):
        ff, smc = measured["ffpva", payload_g, orientation], measured["smc", payload_g, orientation]
        combined = math.hypot(ff["std"] / math.sqrt(ff["runs"]), smc["std"] / math.sqrt(smc["runs"]))
        better = _better(ff["mean"], smc["mean"])
        twin_better = _better(predicted["ffpva", payload_g, orientation]["mean"],
                              predicted["smc", payload_g, orientation]["mean"])
        orders.append({"payload_g": payload_g, "orientation": orientation, "measured_better": better,
                       "measured_toss": better == TIE or abs(smc["mean"] - ff["mean"]) < TOSS_SE * combined,
                       "predicted_better": twin_better, "right": better == twin_better})
    conclusions = {}
    for number, orientation in ((1, "horizontal"), (2, "vertical")):
        conclusions[number] = {c: {"measured": _cost(measured, c, 13.5, orientation),
                                   "predicted": _cost(predicted, c, 13.5, orientation)}
                               for c in ("ffpva", "smc")}
        for both in conclusions[number].values():
            both["agree"] = bool(rmse_within(both["predicted"], both["measured"]))
    heavy = [k for k in CELL_KEYS if k[1:] == (13.5, "vertical")]
    stalled = [measured[k]["stalled"] for k in heavy]
    conclusions[2]["stalled"] = {"predicted": sum(predicted[k]["stalled"] for k in heavy),
                                 "predicted_runs": sum(predicted[k]["runs"] for k in heavy),
                                 "measured": None if None in stalled else sum(stalled),
                                 "measured_runs": sum(measured[k]["runs"] for k in heavy)}
    conclusions[3] = {"measured": sum(o["measured_better"] == "smc" for o in orders),
                      "predicted": sum(o["predicted_better"] == "smc" for o in orders), "of": len(orders)}
    return {"cells": cells, "orders": orders, "conclusions": conclusions}


def _cell_name(row: dict) -> str:
    return f"{CONTROLLER_LABELS[row['controller']]} {row['payload_g']:g} g {row['orientation']}"


def _fitted_note() -> str:
    """The two cells that were not blind: Chapter 5's T3 experiment, which the calibration fitted."""
    fitted = "; ".join(f"{CONTROLLER_LABELS[c]} {THESIS_EXPERIMENT_RMSE_DEG[c][3][0]:.2f} ± "
                       f"{THESIS_EXPERIMENT_RMSE_DEG[c][3][1]:.2f}" for c in ("ffpva", "smc"))
    return (f"Not blind: the 0 g horizontal cells, if the measurements repeat Chapter 5's T3 experiment ({fitted}), "
            "which `twin calibrate` fitted. The other ten were predicted before any was seen.")


def _apart(value: float, other: float, decimals: int = 3) -> str:
    """``value`` to ``decimals`` places, or to as many more (up to 9) as tell it from ``other``, so that a verdict
    comparing the two can be read off the printed numbers."""
    for places in range(decimals, 10):
        text = f"{value:.{places}f}"
        if value == other or text != f"{other:.{places}f}":
            return text
    return repr(value)


def _stalls(row: dict) -> str:
    measured = ("not given" if row["measured_stalled_runs"] is None else
                f"{row['measured_stalled_runs']} of {row['runs']}")
    return f"{measured}, {row['twin_stalled_runs']} of {row['twin_runs']}"


def answer(s: dict) -> str:
    """One line: how the prediction fared (first saying so when it is not on record)."""
    cells, orders = s["cells"], s["orders"]
    c3 = s["conclusions"][3]
    unregistered = "" if s.get("registered", True) else "NOT a prediction on record before the data: "
    return (f"{unregistered}{sum(r['within'] for r in cells)} of {len(cells)} T3 cells within "
            f"{RMSE_TOLERANCE * 100:.0f} % of the measured mean; {sum(r['in_band'] for r in cells)} inside the 10-90 % band, {sum(r['in_members'] for r in cells)} "
            f"inside the members' range; controller order right in {sum(o['right'] for o in orders)} of "
            f"{len(orders)} pairs ({sum(o['measured_toss'] for o in orders)} a toss on the measured runs); sliding "
            f"mode better in {c3['measured']} of {c3['of']} measured, {c3['predicted']} predicted.")


def report(s: dict, *, prediction: str, measured: str) -> str:
    """``score.md``: the tables and the conclusions, readable on their own."""
    lines = [
        "# The blind T3 prediction against the measurements", "",
        f"Written by `twin score`. Prediction: {prediction}. Measurements: {measured}. The rules were written on "
        f"{RULES_WRITTEN}, before any T3 measurement was seen (twin/experiments/score.py). Degrees.", "",
        "## Summary", "", answer(s), "", _fitted_note(), "",
        "## Per cell", "",
        f"`ratio`: the committed preset's mean over the measured mean (above 1: the twin predicted a larger error). "
        f"`within`: that ratio within {RMSE_TOLERANCE * 100:.0f} % of 1. `in band`: the measured mean inside the "
        "ensemble's 10-90 % band; `in members`: inside the members' range (lowest to highest member mean). `z`: "
        "the committed mean less the measured mean, in the measured mean's standard errors (std / sqrt(runs)); "
        "positive: the twin predicted a larger error. Every verdict is on the unrounded numbers; the twin's are "
        "printed to 3 decimals, or to as many more as tell a band's end or the ratio from what it is compared with, "
        "so that each verdict can be read off the table.", "",
        "| cell | measured | committed | ratio | within | band p10-p90 | in band | members | in members | z | "
        "stalled runs: measured, twin |",
        "|---|---|---|---|---|---|---|---|---|---|---|"]
    yes = {True: "yes", False: "no"}
    for r in s["cells"]:
        m = r["measured"]
        edge = 1 + math.copysign(RMSE_TOLERANCE, r["ratio"] - 1)  # the tolerance's nearer end
        lines.append(f"| {_cell_name(r)} | {m:g} ± {r['measured_std']:g} | {r['twin_mean']:.3f} | "
                     f"x{_apart(r['ratio'], edge)} | {yes[r['within']]} | {_apart(r['band_p10'], m)}-"
                     f"{_apart(r['band_p90'], m)} | {yes[r['in_band']]} | {_apart(r['member_low'], m)}-"
                     f"{_apart(r['member_high'], m)} | {yes[r['in_members']]} | {r['z']:+.1f} | {_stalls(r)} |")
    lines += ["", "## Which controller tracked better", "",
              f"A toss: the measured means differ by less than {TOSS_SE:g} combined standard errors.", "",
              "| payload | orientation | measured | predicted | right |", "|---|---|---|---|---|"]
    for o in s["orders"]:
        toss = " (a toss)" if o["measured_toss"] else ""
        lines.append(f"| {o['payload_g']:g} g | {o['orientation']} | {ORDER_LABELS[o['measured_better']]}{toss} | "
                     f"{ORDER_LABELS[o['predicted_better']]} | {yes[o['right']]} |")
    c = s["conclusions"]
    lines += ["", "## The thesis's three robustness conclusions, measured and predicted", ""]
    stalled = c[2]["stalled"]
    measured_stalls = ("not given" if stalled["measured"] is None else
                       f"{stalled['measured']} of {stalled['measured_runs']}")
    stalls = (f"; stalled runs at 13.5 g vertical: predicted {stalled['predicted']} of {stalled['predicted_runs']} "
              f"(every member's), measured {measured_stalls}")
    for number, text, more in ((1, "13.5 g horizontal over 0 g horizontal", ""),
                               (2, "13.5 g vertical over 0 g vertical", stalls)):
        parts = [f"{CONTROLLER_LABELS[name]} measured x{c[number][name]['measured']:.2f}, predicted "
                 f"x{c[number][name]['predicted']:.2f} ({'agrees' if c[number][name]['agree'] else 'does not agree'}"
                 f" within {RMSE_TOLERANCE * 100:.0f} %)" for name in ("ffpva", "smc")]
        lines.append(f"{number}. *{text}*: " + "; ".join(parts) + more + ".")
    tosses = sum(o["measured_toss"] and o["measured_better"] == "smc" for o in s["orders"])
    of_them = f" ({tosses} of them a toss on the measured runs)" if tosses else ""
    lines.append(f"3. *Sliding mode tracks better than FF + PVA*: in {c[3]['measured']} of {c[3]['of']} pairs "
                 f"measured{of_them}, {c[3]['predicted']} predicted.")
    return "\n".join(lines) + "\n"


def figure(s: dict, path: pathlib.Path) -> None:
    """Each cell: the members' range (thin), the 10-90 % band (thick), the committed mean (dot) and the
    measured mean with two standard errors; the legend outside the axes, so that it hides no cell."""
    from viz.figures import finish, plt

    cells = s["cells"]
    x = np.arange(len(cells))
    fig, ax = plt.subplots(figsize=(11, 4.2))
    ax.vlines(x, [r["member_low"] for r in cells], [r["member_high"] for r in cells], color="tab:blue", lw=1,
              label="members' range")
    ax.vlines(x, [r["band_p10"] for r in cells], [r["band_p90"] for r in cells], color="tab:blue", lw=6, alpha=0.4,
              label="10-90 % band")
    ax.plot(x, [r["twin_mean"] for r in cells], "o", color="tab:blue", label="predicted (its preset)")
    ax.errorbar(x + 0.18, [r["measured"] for r in cells],
                yerr=[2 * r["measured_std"] / math.sqrt(r["runs"]) for r in cells], fmt="s", color="black",
                capsize=3, label="measured ± 2 SE")
    ax.set_xticks(x, [f"{'FF+PVA' if r['controller'] == 'ffpva' else 'SMC'}\n{r['payload_g']:g} g "
                      f"{r['orientation'][0].upper()}" for r in cells], fontsize=8)
    ax.set_title(f"{s.get('short_name', 'Blind T3 prediction')} against the measurements", fontsize=10)
    fig.subplots_adjust(bottom=0.2, right=0.8)  # room for the two-line cell names and the legend
    finish(fig, ax, path, xlabel="T3 cell", ylabel="RMSE (deg)",
           legend_at={"loc": "upper left", "bbox_to_anchor": (1.01, 1.0)})


def prediction_name(record: Registration | None, folder: pathlib.Path | None) -> str:
    """How ``score.md`` names the prediction it scores: the registration's name, date and preset (and the
    committed preset, if that has changed since), or that it is not on record."""
    from twin.plants.as_built import preset_digest

    where = "the package's `twin/experiments/data/`" if folder is None else f"`{folder}`"
    if record is None:
        return (f"**NOT a prediction on record before the data** ({where}; scored with --unregistered: its files "
                "match no registered prediction's)")
    now = preset_digest()
    preset = (f"as-built preset {record.preset}" if now == record.preset else
              f"as-built preset {record.preset}; the committed preset is now {now}")
    return f"{record.name}, registered {record.registered} ({where}; `twin validate` on {preset})"


class ScoreExperiment(Experiment):
    name = "score"
    help = "the blind T3 prediction against measured T3 cells, by rules fixed before the data"

    def add_arguments(self, parser: argparse.ArgumentParser) -> None:
        parser.add_argument("--measured", type=arguments.named_path, required=True, metavar="FILE",
                            help="CSV of the measured T3 cells: " + ", ".join(MEASURED_COLUMNS) +
                                 " (optional: trajectory, runs, stalled_runs)")
        parser.add_argument("--prediction", type=arguments.named_path, default=None, metavar="DIR",
                            help="a twin validate --out folder (default: the committed prediction)")

        parser.add_argument("--unregistered", action="store_true",
                            help="score a prediction that is not on record before the data (a refit's, a what-if's); "
                                 "every output then says so")

    def check(self, args: argparse.Namespace) -> None:
        """Reads both inputs and the prediction's registration once; :meth:`run` uses them (as other experiments
        keep what their check parsed on ``args``). An input that is one of the files this command writes into
        ``--out`` is refused: the write would replace the rig's measurements (or the prediction) with the score."""
        inputs = [("--measured", args.measured)] + [("--prediction", path) for path in prediction_files(args.prediction)]
        for flag, given in inputs:
            for name in self.file_names():
                if _same_file(given, args.out / name):
                    raise InvalidScenario(f"{flag} {str(given)!r} is {name}, a file this command writes into "
                                          f"{str(args.out)!r}: move it, or choose another --out")
        args.measured_cells = read_measured(args.measured)
        args.predicted_cells = read_prediction(args.prediction)
        args.record = registration(args.prediction)
        if args.record is None and not args.unregistered:
            which = ("the packaged prediction (twin/experiments/data/)" if args.prediction is None
                     else f"--prediction {str(args.prediction)!r}")
            raise InvalidScenario(f"{which} is not a prediction on record before the T3 data: its files match none "
                                  "in twin/experiments/score.py's REGISTERED (--unregistered scores it, marked so)")

    def run(self, args: argparse.Namespace, out: pathlib.Path) -> Outcome:
        s = score(args.measured_cells, args.predicted_cells)
        record = args.record
        s["registered"] = record is not None
        for row in (*s["cells"], *s["orders"]):
            row["registered"] = s["registered"]
        s["short_name"] = "Unregistered T3 prediction" if record is None else record.name.split(" (")[0].capitalize()
        s["report"] = report(s, measured=f"`{args.measured}`", prediction=prediction_name(record, args.prediction))
        return Outcome(rows=s["cells"], answer=answer(s), detail=s)

    def file_names(self) -> tuple[str, ...]:
        return ("score.csv", "orders.csv", "score.md", "score.png")

    def outputs(self, outcome: Outcome, out: pathlib.Path, undrawn: list[tuple[str, str]]) -> list[pathlib.Path]:
        """``score.csv`` (per cell), ``orders.csv``, ``score.md`` and ``score.png``."""
        s = outcome.detail
        paths = [out / "score.csv", out / "orders.csv", out / "score.md"]
        write_csv(s["cells"], SCORE_COLUMNS, paths[0])
        write_csv(s["orders"], ORDER_COLUMNS, paths[1])
        paths[2].write_text(s["report"], encoding="utf-8")
        return paths + drawn(lambda path: figure(s, path), out / "score.png", undrawn)


EXPERIMENT = ScoreExperiment()
