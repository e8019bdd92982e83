"""The blind T3 prediction over the calibration ensemble, and what each member does with the measured cells,
the Chapter 5 orders and the T3 lead."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from twin.experiments import calibrate
from twin.experiments.validate.common import PREDICTION_CELLS, SEEDS, rmse_within, stalled_runs
from twin.sim.scenario import CONTROLLER_LABELS


def prediction(evaluator: calibrate.Evaluator, committed: dict[str, float], progress=None,
               ran: Sequence[calibrate.CellResult] = ()) -> tuple[list[dict], list[calibrate.CellResult], dict]:
    """The T3 cells on each ensemble member and on the ``committed`` values (the runs of the member
    with those values, which the ensemble lists first, else their own); see the module docstring.
    ``ran``: cells already run on ``committed`` with the evaluator's seeds, not run again for it."""
    from twin.plants.as_built import calibration_cost_line, ensemble_costs, ensemble_values

    members, costs = ensemble_values(), ensemble_costs()
    # With the fitted cells: how each miss and each order fares on every member. Each cell runs once (T3's
    # 0 g flat cells are both predicted and fitted) and is picked by its key.
    keys = PREDICTION_CELLS + tuple(key for key in calibrate.CELLS if key not in PREDICTION_CELLS)
    per_member, fitted = [], []
    for values in members:
        found = {cell.key: cell for cell in ran} if values == committed else {}
        missing = [key for key in keys if key not in found]
        if missing:
            found.update((cell.key, cell) for cell in evaluator.cells(values, keys=missing))
        per_member.append([found[key] for key in PREDICTION_CELLS])
        fitted.append([found[key] for key in calibrate.CELLS])
        if progress:
            progress()
    experiment = [[c for c in m if c.key in calibrate.EXPERIMENT_CELLS] for m in fitted]
    own = next((cells for values, cells in zip(members, per_member, strict=True) if values == committed), None)
    own = own or evaluator.cells(committed, keys=PREDICTION_CELLS)
    rows = prediction_rows(per_member, own)
    detail = {"members": members, "runs": len(members) * len(SEEDS), "costs": costs, "cost_line": calibration_cost_line(),
              "committed": next((k for k, values in enumerate(members) if values == committed), None),
              "per_member": [[c.mean_rmse for c in m] for m in per_member],
              "orders": [known_orders(m) for m in experiment],
              "fitted_means": [{c.key: c.mean_rmse for c in m} for m in fitted]}
    return rows, own, detail


def prediction_rows(per_member: Sequence[Sequence[calibrate.CellResult]],
                    own: Sequence[calibrate.CellResult]) -> list[dict]:
    """``prediction.csv``'s rows (:data:`PREDICTION_COLUMNS`): per T3 cell, ``own``'s mean (the committed
    preset's), the 10/50/90 % percentiles of the members' means and the members' stalled runs; ``per_member`` and
    ``own`` hold the cells of :data:`PREDICTION_CELLS` in order."""
    rows = []
    for k, key in enumerate(PREDICTION_CELLS):
        means = [m[k].mean_rmse for m in per_member]
        p10, p50, p90 = (float(np.percentile(means, q)) for q in (10, 50, 90))
        rows.append({"controller": key[0], "trajectory": key[1], "payload_g": key[2], "orientation": key[3],
                     "twin_mean": own[k].mean_rmse, "band_p10": p10, "band_p50": p50, "band_p90": p90,
                     "stalled_runs": sum(stalled_runs(m[k]) for m in per_member)})
    return rows


def _member_within(m: dict, r: dict) -> bool | None:
    """Whether one member's mean (``m``, its ``fitted_means``) of the measured cell ``r`` is within tolerance;
    None where the member did not run it, or its runs give no mean (a failed run)."""
    x = m.get((r["controller"], r["trajectory"], r["payload_g"], r["orientation"]))
    return None if x is None or not math.isfinite(x) else bool(rmse_within(x, r["measured"]))


def known_orders(cells: Sequence[calibrate.CellResult]) -> dict[int, str | None]:
    """Per trajectory of ``cells`` (one member's Chapter 5 cells) the controllers' order, best first; None
    where a cell's runs give no mean (a failed run): its order is not known."""
    rows = [{"controller": c.controller, "trajectory": c.trajectory, "twin_mean": c.mean_rmse} for c in cells]
    known = controller_order([r for r in rows if math.isfinite(r["twin_mean"])], "twin_mean")
    return {t: (known.get(t) if all(math.isfinite(r["twin_mean"]) for r in rows if r["trajectory"] == t) else None)
            for t in sorted({r["trajectory"] for r in rows})}


def member_orders(detail: dict, measured: dict[int, str]) -> dict[int, list[int]]:
    """Per trajectory of ``measured`` (its controller order), the ensemble members (their places in
    ``detail["members"]``) whose Chapter 5 runs put the controllers in that order; {} when ``prediction``'s
    detail has no orders. A member whose order is not known (None) is not among them."""
    orders = detail.get("orders")
    if not orders:
        return {}
    return {t: [k for k, order in enumerate(orders) if order.get(t) == rig] for t, rig in measured.items()}


def _unknown_orders(detail: dict, t: int) -> list[int]:
    """The members whose Chapter 5 order on trajectory ``t`` is not known (a run failed)."""
    return [k for k, order in enumerate(detail.get("orders") or []) if order.get(t) is None]


def lead_counts(prediction: Sequence[dict], means: Sequence[float]) -> tuple[dict[str, int], int]:
    """In how many of the T3 payload and side cells each controller has the lower of ``means`` (one per row of
    ``prediction``, in its order), and how many cells were ranked: a cell where a mean is not a number is left
    out, and a tie counts for neither."""
    cells: dict[tuple, dict[str, float]] = {}
    for r, mean in zip(prediction, means, strict=True):
        if mean is not None and math.isfinite(mean):
            cells.setdefault((r["payload_g"], r["orientation"]), {})[r["controller"]] = float(mean)
    ranked = [pair for pair in cells.values() if len(pair) == 2]
    count: dict[str, int] = {}
    for pair in ranked:
        if len(set(pair.values())) == 2:
            best = min(pair, key=pair.get)
            count[best] = count.get(best, 0) + 1
    return count, len(ranked)


def member_leads(prediction: Sequence[dict], detail: dict) -> list[dict[str, int]]:
    """Per ensemble member, :func:`lead_counts` of its T3 means."""
    return [lead_counts(prediction, column)[0] for column in member_means(detail).T]


def member_means(detail: dict) -> np.ndarray:
    """Each ensemble member's five-run mean RMSE per T3 cell, (cells, members), from ``prediction``'s
    detail."""
    return np.array(detail["per_member"]).T


def prediction_member_rows(prediction_rows: Sequence[dict], detail: dict) -> list[dict]:
    """One row per T3 cell and ensemble member (:data:`PREDICTION_MEMBER_COLUMNS`), the cells in
    ``prediction_rows``' order."""
    return [{**{k: r[k] for k in ("controller", "trajectory", "payload_g", "orientation")}, "member": m,
             "twin_mean": float(mean)}
            for r, means in zip(prediction_rows, member_means(detail), strict=True) for m, mean in enumerate(means)]


def controller_order(rows: Sequence[dict], value: str) -> dict[int, str]:
    """Per trajectory, the controllers from best to worst by ``value`` ("measured" or "twin_mean")."""
    out: dict[int, str] = {}
    for t in sorted({r["trajectory"] for r in rows}):
        ranked = sorted((r for r in rows if r["trajectory"] == t), key=lambda r: r[value])
        out[t] = " < ".join(CONTROLLER_LABELS[r["controller"]] for r in ranked)
    return out
