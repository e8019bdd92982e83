"""The ensemble's members: the table the report ends with, ``members.csv``, and the lines on what each
member does with the measured cells and the T3 lead."""

from __future__ import annotations

from collections.abc import Sequence

from twin.batch.tables import counted
from twin.experiments.validate.common import PARAMETER_TEXT, RMSE_TOLERANCE
from twin.experiments.validate.ensemble import (
    _member_within,
    _unknown_orders,
    controller_order,
    member_leads,
    member_orders,
)
from twin.experiments.validate.run import Validation
from twin.experiments.validate.text import _cell_name, _numbers_text, _profiled, _with_unit
from twin.plants.as_built import FITTED
from twin.sim.scenario import CONTROLLER_LABELS


def _measured_rmse_rows(v: Validation) -> list[dict]:
    """The measured RMSE cells of ``v`` (Chapter 5 experiments and Chapter 6 T1) that the fit ran."""
    return [r for r in v.rows if r["source"] in ("chapter 5 experiment", "chapter 6 T1")]


def member_cells_within(v: Validation) -> list[int]:
    """Per ensemble member, how many of the measured RMSE cells its five-run means put within tolerance
    ([] when the members did not run them)."""
    rows = _measured_rmse_rows(v)
    return [sum(_member_within(m, r) is True for r in rows) for m in v.prediction_detail.get("fitted_means") or []]


def _why_members(v: Validation) -> list[str]:
    """How many of the measured RMSE cells each ensemble member puts within tolerance, and which cells are
    out on every member ([] when the members did not run them)."""
    means = v.prediction_detail.get("fitted_means")
    rows = _measured_rmse_rows(v)
    if not means or not rows:
        return []
    counts = member_cells_within(v)
    everywhere = [r for r in rows if all(_member_within(m, r) is False for m in means)]
    some = [r for r in rows if not r["within_tolerance"] and any(_member_within(m, r) is True for m in means)]
    return [f"- **The misses on every member** (the {len(means)} ensemble members, seeds 0-4): each puts "
            f"{min(counts)}-{max(counts)} of the {len(rows)} measured RMSE cells within {RMSE_TOLERANCE * 100:.0f} % "
            f"(the committed preset {sum(bool(r['within_tolerance']) for r in rows)}; each member's count is in the "
            "members' table at the end). "
            + (("Out on every member, so not a matter of which of the equally good fits is committed: "
                + ", ".join(_cell_name(r) for r in everywhere) + ". ") if everywhere else "")
            + (("Out on the committed preset but within on some member: " + ", ".join(_cell_name(r) for r in some)
                + ".") if some else "No cell the committed preset misses is within on any member.")]


def _leads_text(count: dict[str, int], cells: int) -> str:
    """"sliding mode ahead in 6 of 6" (the controller ahead in more cells first), from one member's leads."""
    ranked = sorted(count.items(), key=lambda cn: (-cn[1], cn[0]))
    return ", ".join(f"{CONTROLLER_LABELS[c]} ahead in {n} of {cells}" for c, n in ranked) or "no lead"


def _members_lead_text(v: Validation) -> tuple[str, list[int]]:
    """The T3 leads over the ensemble's members, grouped ("on 10 members, sliding mode ahead in 6 of 6; on 1 member
    (member 1), FF + PVA ahead in 5 of 6, sliding mode ahead in 1 of 6"), and the members whose majority law differs from
    most members' (empty if they all agree)."""
    leads = member_leads(v.prediction, v.prediction_detail)
    cells = len({(r["payload_g"], r["orientation"]) for r in v.prediction})
    groups: dict[str, list[int]] = {}
    for m, count in enumerate(leads):
        groups.setdefault(_leads_text(count, cells), []).append(m)
    text = "; ".join(f"on {counted(len(ms), 'member')}" + (f" ({_numbers_text(ms)})" if len(ms) <= 3 else "") + f", {t}"
                     for t, ms in sorted(groups.items(), key=lambda g: -len(g[1])))
    majority = [max(count, key=count.get) if count else None for count in leads]
    usual = max(sorted(set(majority), key=str), key=majority.count)  # sorted: the same pick on every run
    return text, [m for m, c in enumerate(majority) if c != usual]


def _cost_line_text(detail: dict, costs: Sequence[float] | None) -> str:
    """The members' table's sentence on the fit cost: how many members lie within the best cost plus its
    seed-to-seed noise, counted from the recorded costs ("" without costs)."""
    if not costs:
        return ""
    text = "The fit cost is the one the calibration recorded, on its fit seeds"
    line = detail.get("cost_line")
    if line:
        best, noise = line
        inside = sum(c <= best + noise for c in costs)
        text += (f" (the best {best:.3f}, its seed-to-seed noise {noise:.3f}): {inside} of {len(costs)} members lie "
                 "within the best plus the noise")
    return text + ". "


def _orders_right_text(detail: dict, orders: dict[int, list[int]], k: int) -> str:
    """Member ``k``'s Chapter 5 trajectories whose controller order is right ("T1, T3"), then those whose order
    is not known (a run failed); "none" if none is right."""
    right = ", ".join(f"T{t}" for t, members in orders.items() if k in members) or "none"
    unknown = [t for t in orders if k in _unknown_orders(detail, t)]
    return right + ("; not known (a run failed): " + ", ".join(f"T{t}" for t in unknown) if unknown else "")


def _member_facts(v: Validation) -> tuple[list[int], dict[int, list[int]], list[dict[str, int]]]:
    """Per ensemble member, from its runs on seeds 0-4: the measured RMSE cells within tolerance
    (:func:`member_cells_within`), per Chapter 5 trajectory the members whose order is right
    (:func:`member_orders`; {} without the experiments' rows) and its T3 leads (:func:`member_leads`)."""
    experiment = [r for r in v.rows if r["source"] == "chapter 5 experiment"]
    orders = member_orders(v.prediction_detail, controller_order(experiment, "measured")) if experiment else {}
    return member_cells_within(v), orders, member_leads(v.prediction, v.prediction_detail)


def member_rows(v: Validation) -> list[dict]:
    """``members.csv``'s rows (:data:`MEMBER_COLUMNS`), one per ensemble member; a value the run does not have
    (a cost the file does not record, cells the members did not run) is None."""
    d = v.prediction_detail
    costs = d.get("costs") or []
    within, orders, leads = _member_facts(v)
    return [{"member": k, "committed": k == d.get("committed"), **{f.name: m.get(f.name) for f in FITTED},
             "fit_cost": costs[k] if k < len(costs) else None,
             "measured_rmse_cells_within": within[k] if within else None,
             "chapter5_orders_right": " ".join(str(t) for t, right in orders.items() if k in right) if orders else None,
             "t3_cells_ffpva_ahead": leads[k].get("ffpva", 0), "t3_cells_smc_ahead": leads[k].get("smc", 0)}
            for k, m in enumerate(d["members"])]


def _members_table(v: Validation) -> list[str]:
    """The ensemble's members, one row each: the values they differ in, the cost the fit recorded, and what
    each does with the measured cells, the Chapter 5 orders and the T3 lead (the other sections name members
    by these numbers)."""
    d = v.prediction_detail
    members = d["members"]
    names = _profiled(members)
    costs = d.get("costs")
    costs = costs if costs and len(costs) == len(members) and all(c is not None for c in costs) else None
    within, orders, leads = _member_facts(v)
    cells = len({(r["payload_g"], r["orientation"]) for r in v.prediction})
    header = ["member"] + [_with_unit(PARAMETER_TEXT[n][0], f"({PARAMETER_TEXT[n][2]})" if PARAMETER_TEXT[n][2] else "")
                           for n in names]
    header += ["fit cost"] if costs else []
    header += [f"measured RMSE cells within {RMSE_TOLERANCE * 100:.0f} % (of {len(_measured_rmse_rows(v))})"] \
        if within else []
    header += ["Chapter 5 order right on"] if orders else []
    header += ["T3 lead (lower RMSE)"]
    lines = ["### The ensemble's members", "",
             "Numbered from 0 as in `prediction_members.csv` and `misses.csv`; the other sections name members "
             "by these numbers, and `members.csv` has this table with the values in SI. " + _cost_line_text(d, costs)
             + "Within, order and lead are on seeds 0-4, as the verdicts above.", "",
             "| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    for k, m in enumerate(members):
        row = [f"{k} (committed)" if k == d.get("committed") else str(k)]
        row += [PARAMETER_TEXT[n][1](m[n]) for n in names]
        row += [f"{costs[k]:.3f}"] if costs else []
        row += [str(within[k])] if within else []
        row += [_orders_right_text(d, orders, k)] if orders else []
        row += [_leads_text(leads[k], cells)]
        lines.append("| " + " | ".join(row) + " |")
    return lines + [""]
