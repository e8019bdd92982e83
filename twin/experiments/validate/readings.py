"""Every miss and its reading (``misses.csv`` and the report's table): which other check a miss goes with."""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence

from twin.batch.tables import signed
from twin.experiments import calibrate
from twin.experiments.reference import THESIS_EXPERIMENT_RMSE_DEG
from twin.experiments.validate.common import EFFECT_SIGNIFICANCE, RMSE_TOLERANCE, SEEDS
from twin.experiments.validate.ensemble import _member_within, _unknown_orders, controller_order, member_orders
from twin.experiments.validate.motion import SLOW_TRAJECTORIES
from twin.experiments.validate.run import Validation
from twin.experiments.validate.text import _cell_name, _fmt, _loaded, _times, _which_members
from twin.physics.trajectories import trajectory
from twin.plants import plant
from twin.sim.metrics import delay_for_rmse, lagging_metrics
from twin.sim.scenario import CONTROLLER_LABELS


def _measured_text(controller: str, trajectory: int) -> str:
    mean, std = THESIS_EXPERIMENT_RMSE_DEG[controller][trajectory]
    return f"{mean:.2f} ± {std:.2f}"


def _members_within_text(detail: dict, r: dict) -> str:
    """On how many ensemble members the measured cell ``r`` (a validation row) is within tolerance, and
    the span of their ratios; "" when ``prediction``'s detail has no member means for it."""
    key = (r["controller"], r["trajectory"], r["payload_g"], r["orientation"])
    ran = [m for m in detail.get("fitted_means") or [] if key in m]
    if not ran:
        return ""
    within = sum(_member_within(m, r) is True for m in ran)  # a member whose runs failed has no mean: not counted
    ratios = [m[key] / r["measured"] for m in ran if math.isfinite(m[key])]
    span = f"; x{min(ratios):.2f}-x{max(ratios):.2f}" if ratios else ""
    return f"; within on {within} of the ensemble's {len(ran)} members (seeds 0-4{span})"


def _members_right_text(detail: dict, t: int, right: Sequence[int]) -> str:
    """How many members put trajectory ``t``'s order right, and which (by number: the members' table gives
    their values), named by the shorter list: those right, or all but those not."""
    members = detail["members"]
    text = f"right on {len(right)} of the ensemble's {len(members)} members" + _unknown_text(detail, t)
    return text + _which_members(len(members), right)


def _unknown_text(detail: dict, t: int) -> str:
    """" (2 without an order: a run failed)" for trajectory ``t``, or "" when every member's order is known."""
    unknown = len(_unknown_orders(detail, t))
    return f" ({unknown} without an order: a run failed)" if unknown else ""


@functools.cache
def implied_t1(controller: str) -> tuple[tuple[float, float], ...] | None:
    """What the rig's measured T2 and T3 RMSE of ``controller`` (§8) imply for its T1, by a joint that lags its
    reference a fixed time (:func:`twin.sim.metrics.lagging_metrics` on the twin's references): (delay s, T1 RMSE
    deg) read from T2, then from T3; None for a law not measured on both. The references and the tick are every
    preset's; the `thesis` preset's are read (it needs no calibration file)."""
    cells = THESIS_EXPERIMENT_RMSE_DEG.get(controller, {})
    if 2 not in cells or 3 not in cells:
        return None
    base = plant("thesis")
    r, h = base.params.gears.spur_radius, base.timestep
    read = []
    for number in (2, 3):
        delay = delay_for_rmse(trajectory(number, spur_radius=r), math.radians(cells[number][0]), spur_radius=r,
                               timestep=h)
        t1 = lagging_metrics(trajectory(1, spur_radius=r), delay, spur_radius=r, timestep=h).rmse
        read.append((delay, math.degrees(t1)))
    return tuple(read)


def departs(measured: float, implied: Sequence[float], twin: float) -> bool:
    """Whether a measured T1 is out of tolerance of each value its own T2 and T3 imply while the twin's is within
    tolerance of each. (For a twin that misses the measured value, that puts the measured value on the other side
    of them from the twin's: within 20 % of t1 and over 20 % above a measured value over 20 % above t1 cannot both
    hold, nor the same below.)"""
    return (len(implied) > 0 and all(math.isfinite(t1) for t1 in implied)
            and all(abs(measured / t1 - 1) > RMSE_TOLERANCE for t1 in implied)
            and all(abs(twin / t1 - 1) <= RMSE_TOLERANCE for t1 in implied))


def own_trajectories(r: dict, twin: float) -> tuple[tuple[float, float], ...] | None:
    """What the rig's own T2 and T3 imply for RMSE row ``r`` (:func:`implied_t1`) when ``r`` is a flat T1 cell
    that :func:`departs` from them with the twin at ``twin`` deg; else None."""
    if _loaded(r) or r["trajectory"] != 1:
        return None
    own = implied_t1(r["controller"])
    return own if own and departs(r["measured"], [t1 for _, t1 in own], twin) else None


def _own_trajectories_text(r: dict, own: Sequence[tuple[float, float]], twin: float) -> str:
    implied = sorted(t1 for _, t1 in own)
    delays = sorted(delay * 1e3 for delay, _ in own)
    ratios = sorted(r["measured"] / t1 for t1 in implied)
    others = [THESIS_EXPERIMENT_RMSE_DEG[law][1][0] / t1 for law, read in
              ((law, implied_t1(law)) for law in THESIS_EXPERIMENT_RMSE_DEG if law != r["controller"]) if read
              for _, t1 in read]
    return (f"a joint that lags its reference a fixed time (a ruler, not a plant), read from the rig's own T2 and T3 "
            f"of this law ({delays[0]:.1f}-{delays[1]:.1f} ms; exact on the twin's references at their ticks, over "
            f"the twin's run lengths), gives T1 {implied[0]:.2f}-{implied[1]:.2f} deg: the rig measured "
            f"{r['measured']:.2f} (x{ratios[0]:.2f}-x{ratios[1]:.2f} of that), the twin {twin:.2f}"
            + (f". The rig's other laws' T1 are x{min(others):.2f}-x{max(others):.2f} of what their own T2 and T3 "
               "imply. So by this ruler the rig's cell is the one that does not follow from its law's T2 and T3; "
               "whether something disturbed those runs or this law meets something on T1 that the twin lacks, the "
               "thesis's data do not tell apart" if others else ""))


MISS_COLUMNS = ("comparison", "missed_on", "controller", "trajectory", "payload_g", "orientation", "measured", "twin",
                "off_by", "fresh", "fresh_within", "groups_within", "groups", "reading", "what_the_twin_shows")
# How misses() reads a miss, in the order it tries the rules (the first that applies): the rule, then its name.
READINGS = {
    "draw": "the draw of five runs",  # out (or wrong) on seeds 0-4, in (or right) on the fresh seeds' runs
    "own trajectories": "the rig's cell departs from its own T2 and T3",  # a flat T1 cell: see implied_t1
    "largest error": "§8's largest error is off the same way",  # a flat cell whose largest error is off by > 20 %
    "opening lag": "sliding mode's opening lag",  # sliding mode too high on a slow trajectory, opening no earlier
    "base level": "its 0 g flat level",  # a Chapter 6 cell: the payload's cost matches, its flat cell is out alike
    "payload cost": "its payload's cost",  # a Chapter 6 cell: the payload costs the twin more (less) than the rig
    "scatter": "where the runs end scatters",  # an SSE range out on the fresh seeds too, their ends centred near 0
    "offset": "where the runs end is off zero",  # the same, their ends centred away from 0
    "follows": "follows from the cells that miss",  # an order that the measured values of its out cells restore
    "rig noise": "the rig's runs do not settle it",  # each pair the twin swaps: under 2 s.e. apart on the rig, and
    # the twin's gap under 2 s.e. from the rig's
    "failed": "runs that failed",  # a mean that is not a number: some run failed
    "open": "not shown by the twin",
}


def _rmse_reading(r: dict, f: dict | None, v: Validation, experiment: Sequence[dict]) -> tuple[str, str]:
    """:data:`READINGS`' first rule that reads RMSE row ``r`` of ``v.rows`` (its fresh row ``f``, if
    any), and its text."""
    fresh_only = r["within_tolerance"]  # in on seeds 0-4, so out on the fresh seeds
    miss = f if fresh_only else r  # the result that misses, and which way

    def high(x: dict) -> bool:
        return x["ratio"] > 1

    big = None if _loaded(r) else next((x for x in v.max_errors or [] if (x["controller"], x["trajectory"])
                                        == (r["controller"], r["trajectory"])), None)
    peak = None if big is None else big["fresh_mean"] if fresh_only else big["twin_mean"]
    cost = _cell_row(v.effects, r["controller"], r["payload_g"], r["orientation"])
    flat = next((x for x in v.seeds or [] if (x["controller"], x["trajectory"], x["payload_g"], x["orientation"])
                 == (r["controller"], 1, 0.0, "horizontal")), None)
    lag = (v.pulses or {}).get("lag_deg", {})
    ffpva = next((x for x in experiment if (x["controller"], x["trajectory"]) == ("ffpva", r["trajectory"])), None)
    if not math.isfinite(miss["ratio"]):
        return "failed", "some of its runs failed, so its mean is not a number"
    if not fresh_only and f and f["within_tolerance"]:
        below = sum(m > f["five_run_mean"] for m in f["group_means"]) if f["five_run_mean"] is not None else None
        return "draw", (f"x{f['ratio']:.2f} on the {f['runs']}-run mean, within; {f['groups_within']} of "
                        f"{f['groups']} five-run groups within" + (
                            f"; seeds 0-4 ({f['five_run_mean']:.2f}) lie below {below} of the {f['groups']} groups' "
                            "means" if below is not None else ""))
    same = [x for x in experiment if x["controller"] == r["controller"] and x is not r and x["within_tolerance"]]
    also = ((". The same law is within on " + ", ".join(f"T{x['trajectory']}" for x in same) if same else "")
            + (f". The rig's runs also scattered more (std {f['measured_std']:.2f} against the twin's "
               f"{f['twin_std']:.2f})" if f and f["twin_std"] < f["measured_std_low"] else ""))
    twin_largest = None if peak is None else (
        f"{peak:.1f} (mean over its runs on seeds {f['seeds']})" if fresh_only else
        f"{peak:.1f} (mean over its runs; {big['twin_high']:.1f} at most)")
    twin = miss["ratio"] * r["measured"]
    own = own_trajectories(r, twin)
    if own:
        return "own trajectories", _own_trajectories_text(r, own, twin) + also + (
            f". Its largest error was {big['measured']:g} deg, the twin's {twin_largest}"
            if peak is not None else "")
    if (peak is not None and abs(peak / big["measured"] - 1) > RMSE_TOLERANCE
            and (peak > big["measured"]) == high(miss)):
        return "largest error", (
            f"the rig's largest error was {big['measured']:g} deg, the twin's {twin_largest}: the "
            + ("twin" if peak > big["measured"] else "rig") + " reached a larger error; when in the run, and why, "
            "the thesis's data do not show" + also)
    if (r["controller"] == "smc" and r["trajectory"] in SLOW_TRAJECTORIES and high(miss) and "smc" in lag
            and "ffpva" in lag and lag["smc"] >= 0.9 * lag["ffpva"] and ffpva):
        return "opening lag", (
            f"at the thesis's phi sliding mode opens its valve at {lag['smc']:.2f} deg of error and FF + PVA at "
            f"{lag['ffpva']:.2f} (closed form on T2's ramp, the slow trajectories' measure): no lead on slow "
            f"motion, where the rig's sliding mode tracked at {r['measured'] / ffpva['measured']:.2f} of its FF + "
            "PVA. phi is the thesis's, not fitted; `twin whatif smc-phi` runs others")
    if (cost and flat and f and _loaded(r) and abs(cost["difference_in_se"]) <= EFFECT_SIGNIFICANCE
            and not flat["within_tolerance"] and not f["within_tolerance"] and high(flat) == high(f) == high(miss)):
        return "base level", (
            f"on seeds {flat['seeds']}, where this cell is x{f['ratio']:.2f}, the payload's cost matches the "
            f"rig's (x{cost['twin_effect']:.2f} against x{cost['measured_effect']:.2f}) and its controller's 0 g "
            f"flat cell is out the same way (x{flat['ratio']:.2f})"
            + ("" if flat["five_run_mean"] is None else
               f"; on seeds 0-4 that flat cell is x{flat['five_run_mean'] / flat['measured']:.2f}"))
    if (cost and flat and f and _loaded(r) and abs(cost["difference_in_se"]) > EFFECT_SIGNIFICANCE
            and (cost["difference_in_se"] > 0) == high(f) == high(miss)):
        here = _cell_row(v.phases, r["controller"], r["payload_g"], r["orientation"])
        base = _cell_row(v.phases, r["controller"], 0.0, "horizontal")
        return "payload cost", (
            f"on seeds {flat['seeds']}, where this cell is x{f['ratio']:.2f}, the payload costs the twin "
            + ("more" if high(miss) else "less") + f" than it cost the rig: x{cost['twin_effect']:.2f} over its "
            f"controller's 0 g flat cell against x{cost['measured_effect']:.2f} ({cost['difference_in_se']:+.1f} "
            f"combined standard errors); that flat cell is x{flat['ratio']:.2f}"
            + (", within" if flat["within_tolerance"] else ", out")
            + (_phase_cost(here, base) if here and base else "")
            + "; why the payload costs the twin's law differently, the twin does not show")
    if cost and flat and f and _loaded(r):  # what the two payload checks do show, though neither reads the miss
        return "open", (
            f"none of the other checks explains it alone: on seeds {flat['seeds']}, where this cell is "
            f"x{f['ratio']:.2f}, the payload's cost "
            + ("matches" if abs(cost["difference_in_se"]) <= EFFECT_SIGNIFICANCE else "differs from")
            + f" the rig's (x{cost['twin_effect']:.2f} against x{cost['measured_effect']:.2f}, "
            f"{cost['difference_in_se']:+.1f} combined standard errors) and its controller's 0 g flat cell is "
            f"x{flat['ratio']:.2f}, " + ("within" if flat["within_tolerance"] else "out"))
    return "open", "none of the other checks explains it"


def _cell_row(rows: Sequence[dict] | None, controller: str, payload_g: float, orientation: str) -> dict | None:
    """The row of ``rows`` (a T1 table: :func:`payload_effects`, :func:`payload_phases`) for that cell, if any."""
    return next((x for x in rows or [] if (x["controller"], x["payload_g"], x["orientation"])
                 == (controller, payload_g, orientation)), None)


def _phase_cost(here: dict, base: dict) -> str:
    """A cell's RMS error over T1's move and over its hold, each over its flat cell's (:func:`payload_phases`'
    rows ``here`` and ``base``), or nothing where a ratio cannot be formed."""
    ratios = [here[k] / base[k] if math.isfinite(here[k]) and base[k] > 0 else math.nan
              for k in ("move_deg", "hold_deg")]
    if not all(math.isfinite(x) for x in ratios):
        return ""
    return (f". On seeds 0-4 its RMS error is x{ratios[0]:.2f} the flat cell's over T1's move and x{ratios[1]:.2f} "
            "over its hold")


def _sse_reading(r: dict, f: dict | None, v: Validation) -> tuple[str, str]:
    """:data:`READINGS`' first rule that reads T1 SSE range row ``r`` (its fresh row ``f``), and its text."""
    judged = f is not None and f["sse_twin"] is not None
    if not r["within_tolerance"] and judged and f["sse_within_tolerance"]:
        return "draw", (f"±{f['sse_twin']:.2f} on the mean of the {f['groups']} groups' ranges, within; "
                        f"{f['sse_groups_within']} of {f['groups']} groups within")
    if not judged or f.get("sse_std") is None:
        return "open", "none of the other checks explains it"
    cost = _cell_row(v.effects, r["controller"], r["payload_g"], r["orientation"])
    centred = abs(f["sse_mean"]) < f["sse_std"] / 2
    return ("scatter" if centred else "offset"), (
        f"out on seeds {f['seeds']}" + (" too" if not r["within_tolerance"] else "") + ", "
        + ("narrower" if f["sse_twin"] < r["measured"] else "wider") + " than the rig's (groups' ranges "
        f"±{f['sse_group_low']:.2f}-{f['sse_group_high']:.2f}, mean ±{f['sse_twin']:.2f}, against "
        f"±{r['measured']:.2f}). The twin's runs end at {signed(f['sse_mean'])} ± {f['sse_std']:.2f} deg "
        "(mean ± std), so its range is " + ("their scatter" if centred else "their offset as much as their scatter")
        + "; whether the rig's was scatter or an offset, its range does not tell"
        + (f". The same cell's payload cost on RMSE is short of the rig's (x{cost['twin_effect']:.2f} "
           f"against x{cost['measured_effect']:.2f})" if cost and cost["difference_in_se"] < -EFFECT_SIGNIFICANCE
           else ""))


def misses(v: Validation) -> list[dict]:
    """Every comparison the issue's bar judges that misses (an RMSE mean out of 20 %, a T1 SSE range out
    of ±0.5 deg, a Chapter 5 trajectory's controller order wrong) on seeds 0-4, the verdict's seeds, or
    on the mean of the fresh seeds' runs only; its size, its fresh result, and what the other checks
    (:func:`seed_rows`, :func:`max_error_rows`, :func:`pulse_cycle`, :func:`payload_effects`) show about
    it, read by :data:`READINGS`' rules (:func:`_rmse_reading`, :func:`_sse_reading`, and here for the
    orders). Added 2026-11-25 and its rules written after seeing every result they read: a reading links
    a miss to another check, it does not prove a cause, and a miss no rule reads says so."""
    key = ("controller", "trajectory", "payload_g", "orientation")
    fresh = {tuple(r[k] for k in key): r for r in v.seeds or []}
    experiment = [r for r in v.rows if r["source"] == "chapter 5 experiment"]
    fresh_only = f"seeds {v.seeds[0]['seeds']} only" if v.seeds else ""
    out = []

    def add(comparison, r, f, measured, twin, off_by, fresh_value, within, groups_within, reading, text) -> None:
        out.append({"comparison": comparison, "missed_on": fresh_only if r.get("within_tolerance") else "seeds 0-4",
                    **{k: r.get(k) for k in key}, "measured": measured, "twin": twin, "off_by": off_by,
                    "fresh": fresh_value, "fresh_within": within, "groups_within": groups_within,
                    "groups": (f or {}).get("groups"), "reading": reading, "what_the_twin_shows": text})

    for r in v.rows:
        f = fresh.get(tuple(r[k] for k in key))
        if r["source"] in ("chapter 5 experiment", "chapter 6 T1"):
            if not r["within_tolerance"] or (f and not f["within_tolerance"]):
                reading, text = _rmse_reading(r, f, v, experiment)
                add("RMSE", r, f, r["measured"], r["twin_mean"], r["ratio"], f and f["ratio"],
                    f and f["within_tolerance"], f and f["groups_within"], reading,
                    text + _members_within_text(v.prediction_detail, r))
    for r in v.rows:
        f = fresh.get(tuple(r[k] for k in key))
        judged = f is not None and f["sse_twin"] is not None
        if r["source"].endswith("T1 SSE range") and (not r["within_tolerance"]
                                                       or (judged and not f["sse_within_tolerance"])):
            add("T1 SSE range", r, f, r["measured"], r["twin_mean"],
                None if r["twin_mean"] is None else r["twin_mean"] - r["measured"], f and f["sse_twin"],
                f and f["sse_within_tolerance"], f and f["sse_groups_within"], *_sse_reading(r, f, v))
    finite = [r for r in experiment if r["twin_mean"] is not None and math.isfinite(r["twin_mean"])]
    rig, twin = controller_order(finite, "measured"), controller_order(finite, "twin_mean")
    fresh_flat = [r for r in v.seeds or [] if r["payload_g"] == 0.0 and r["orientation"] == "horizontal"
                  and math.isfinite(r["twin_mean"])]
    fresh_order = controller_order(fresh_flat, "twin_mean")
    for t in rig:
        ran = {r["controller"] for r in fresh_flat if r["trajectory"] == t}
        complete = t in fresh_order and ran == {r["controller"] for r in finite if r["trajectory"] == t}
        right = fresh_order[t] == rig[t] if complete else None
        if rig[t] == twin[t] and right is not False:
            continue
        on = [r for r in (finite if rig[t] != twin[t] else fresh_flat) if r["trajectory"] == t]
        out_cells = [r for r in on if not r["within_tolerance"]]
        pairs = _swapped_pairs(on)
        restored = controller_order(
            [dict(r, twin_mean=r["measured"] if r in out_cells else r["twin_mean"]) for r in on], "twin_mean").get(t)
        if rig[t] != twin[t] and right:
            reading, text = "draw", f"right on the {fresh_flat[0]['runs']}-run means"
        elif out_cells and restored == rig[t]:
            reading = "follows"
            text = (", ".join(f"{_cell_name(r)} is out (x{r['ratio']:.2f})" for r in out_cells)
                    + "; with the measured values in their place the order is right")
        elif pairs and all(max(p["rig_z"], p["gap_z"]) < EFFECT_SIGNIFICANCE for p in pairs):
            reading = "rig noise"
            text = (_pairs_text(pairs) + f", each under {EFFECT_SIGNIFICANCE:g}: the measurements do not settle the "
                    "order, and the twin's is as far from theirs as their own noise")
        elif out_cells:
            reading, text = "open", ("with the measured values in place of the cells that are out the order is "
                                     "still wrong")
        else:
            reading = "open"
            text = f"every cell of T{t} is within {RMSE_TOLERANCE * 100:.0f} %: the order turns on differences inside it"
        if reading == "open" and pairs:
            text += "; " + _pairs_text(pairs)
        right_members = member_orders(v.prediction_detail, rig).get(t)
        if right_members is not None:
            text += "; seeds 0-4 put it " + _members_right_text(v.prediction_detail, t, right_members)
        order_row = {"controller": None, "trajectory": t, "payload_g": 0.0, "orientation": "horizontal",
                     "within_tolerance": rig[t] == twin[t]}
        add("controller order", order_row, None, rig[t], twin[t], None,
            fresh_order[t] if complete else None, right, None, reading, text)
    return out


def _swapped_pairs(rows: Sequence[dict]) -> list[dict]:
    """Each pair of controllers that the twin's means (``rows``, one trajectory's Chapter 5 cells, on seeds 0-4
    or on the fresh seeds) rank the other way from the rig's: ``ahead`` and ``behind`` on the rig, ``rig_z`` the
    rig's gap in combined standard errors of the thesis's five-run means, ``twin_gap`` the twin's (deg, the
    other way) and ``gap_z`` how far the twin's gap lies from the rig's, in the two gaps' combined standard
    errors (the twin's from its runs' std). Added 2026-11-27, after the T4 order it reads."""
    pairs = []
    for a in rows:
        for b in rows:
            if a["measured"] < b["measured"] and a["twin_mean"] > b["twin_mean"]:
                (ma, sa), (mb, sb) = (THESIS_EXPERIMENT_RMSE_DEG[r["controller"]][r["trajectory"]] for r in (a, b))
                rig_se = math.sqrt((sa**2 + sb**2) / calibrate.THESIS_RUNS)
                twin_se = math.sqrt((a["twin_std"] ** 2 + b["twin_std"] ** 2) / a.get("runs", len(SEEDS)))
                twin_gap = a["twin_mean"] - b["twin_mean"]
                pairs.append({"ahead": a["controller"], "behind": b["controller"], "trajectory": a["trajectory"],
                              "rig_z": (mb - ma) / rig_se, "twin_gap": twin_gap,
                              "gap_z": (mb - ma + twin_gap) / math.hypot(rig_se, twin_se)})
    return pairs


def _pairs_text(pairs: Sequence[dict]) -> str:
    return "; ".join(
        f"the rig's five runs put {CONTROLLER_LABELS[p['ahead']]} ({_measured_text(p['ahead'], p['trajectory'])}) "
        f"ahead of {CONTROLLER_LABELS[p['behind']]} ({_measured_text(p['behind'], p['trajectory'])}) by "
        f"{p['rig_z']:.1f} combined standard errors, and the twin's gap the other way ({p['twin_gap']:.2f} deg) lies "
        f"{p['gap_z']:.1f} of the two gaps' combined standard errors from the rig's" for p in pairs)


def _miss_value(x, comparison: str) -> str:
    """A :func:`misses` row's value as the report shows it: an RMSE, a ± range, or an order's string."""
    if comparison == "RMSE":
        return _fmt(x)
    return x if isinstance(x, str) else "–" if x is None else f"±{x:.2f}"


def _miss_row(m: dict) -> str:
    """One :func:`misses` row as a line of the report's table."""
    kind = m["comparison"]
    cell = f"T{m['trajectory']}" if m["controller"] is None else _cell_name(m)
    off = ("" if m["off_by"] is None else _times(m["off_by"]) if kind == "RMSE" else f"{m['off_by']:+.3f} deg")
    fresh = ""
    if m["fresh"] is not None:
        verdict = (("right" if m["fresh_within"] else "wrong") if kind == "controller order" else
                   "within" if m["fresh_within"] else "out")
        fresh = ((f"x{m['fresh']:.2f}" if kind == "RMSE" else _miss_value(m["fresh"], kind)) + f", {verdict}"
                 + (f", {m['groups_within']} of {m['groups']} groups" if m["groups_within"] is not None else ""))
    return (f"| {kind} | {m['missed_on']} | {cell} | {_miss_value(m['measured'], kind)} | "
            f"{_miss_value(m['twin'], kind)} | {off} | {fresh} | {READINGS[m['reading']]} | "
            f"{m['what_the_twin_shows']} |")
