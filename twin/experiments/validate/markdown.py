"""``validation.md``: the report, readable on its own."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence

import numpy as np

from twin.batch.tables import counted
from twin.experiments import calibrate
from twin.experiments.reference import THESIS_FULL_DUTY_SPEEDS
from twin.experiments.studies import valve as valve_study
from twin.experiments.validate.common import (
    DELAY_TOLERANCE,
    EFFECT_SIGNIFICANCE,
    FRESH_SEEDS,
    PARAMETER_TEXT,
    RMSE_TOLERANCE,
    SEEDS,
    SIMULATION_TOLERANCE_DEG,
    SPREAD_CONFIDENCE,
    SSE_TOLERANCE_DEG,
    STALL_ERROR_DEG,
)
from twin.experiments.validate.comparisons import BROKE_AWAY, FULL_DUTY_PLANTS, FULL_DUTY_TURN, _judged
from twin.experiments.validate.ensemble import controller_order, lead_counts, member_means, member_orders
from twin.experiments.validate.members import _members_lead_text, _members_table, _why_members
from twin.experiments.validate.motion import SLOW_TRAJECTORIES
from twin.experiments.validate.readings import READINGS, _miss_row, _unknown_text, misses
from twin.experiments.validate.run import Validation
from twin.experiments.validate.text import (
    _and_list,
    _band_ends_text,
    _cell_name,
    _effect_name,
    _fmt,
    _member_text,
    _numbers_text,
    _percent_span,
    _profiled,
    _times,
    _which_members,
    _with_unit,
)
from twin.plants.as_built import CCW_SCALE_BOUND, FULL_DUTY_SPEED_DIGIT, FULL_DUTY_WINDOW, fits_start_pressure
from twin.sim.scenario import CONTROLLER_LABELS


def _t3_as_run_text() -> str:
    """Sentences on the T3 cells as the twin runs them: T3 (``twin.physics.trajectories``; its middle, amplitude
    and length, which SPEC §7 does not fix all of), the supply pressure (the as-built plant's, which §9 does not
    restate for Chapter 6) and where the fitted cells' T1, T2 and T4 start, and where to read how much they
    matter. The start is ``trajectories.START`` as the report runs: the committed calibration was fitted with it,
    since its ``code_version`` (which hashes the trajectories) is the sweep store's. The trial's numbers are the
    tenth refit's and said as such. Added 2026-11-27 (stop 38), after the trials it points to; the chambers' start
    pressure (the as-built plant's, an assumption) and its trial added 2026-11-28 (stop 42), after that trial; the
    start pressure fitted, and said so, since 2026-11-28 (stop 43)."""
    from twin.physics.params import NOMINAL_PARAMS
    from twin.physics.trajectories import trajectory
    from twin.plants import plant
    from twin.plants.as_built import ensemble_plants

    params = plant("as-built").params
    fitted = fits_start_pressure()  # the file the report runs on (a trial's in the committed one's place counts)
    starts = [p.params.chambers.initial_pressure_fraction * 100 for p in ensemble_plants()] if fitted else []
    chambers = (f"and with what both chambers held when a run began fitted with the rest: "
                f"{params.chambers.initial_pressure_fraction * 100:.0f} % of the supply on the committed preset, "
                f"{min(starts):.0f}-{max(starts):.0f} % over the ensemble" if fitted else
                f"and with both chambers starting at {params.chambers.initial_pressure_fraction * 100:.0f} % of the "
                "supply, not fitted")
    t3 = trajectory(3, spur_radius=params.gears.spur_radius)
    (sine,) = t3.segments
    chapter5 = ", Chapter 5's" if params.supply.pressure == NOMINAL_PARAMS.supply.pressure else ""
    t1 = trajectory(1, spur_radius=params.gears.spur_radius)
    return (f"T3 as the twin runs it: {math.degrees(t3.start):g} ± {math.degrees(sine.delta):g} deg at 0.5 Hz for "
            f"{t3.duration:g} s, starting mid-stroke at full speed (the thesis simulated its largest error at T3's start), "
            f"at a supply of {params.supply.pressure / 1e3:g} kPa{chapter5}; the committed preset was fitted on the "
            f"measured cells with T1, T2 and T4 run from {math.degrees(t1.start):g} deg, {chambers}. The thesis "
            "states neither T3's length nor its start nor where T1, T2 and T4 started nor what the chambers held when a "
            "run began, nor restates the supply for Chapter 6. "
            + ("Of these only the chambers' start pressure is fitted, so only its spread, as far as the measured "
               "cells leave it open, is in the prediction: in the members' range, and less of it in the 10-90 % band, "
               "which leaves the extreme members out. The prediction does not include the uncertainty of the others, "
               "which it holds as said." if fitted else
               "The band does not include the uncertainty of any of them: it is the spread over the fitted parameters "
               "with these held.")
            + " docs/prediction.md in the repository records a trial of each "
            "(`examples/trial_t2_t3_choices.py`, `examples/trial_start_refit.py`, "
            "`examples/trial_start_pressure_refit.py`, `examples/trial_chapter6_supply.py`); the 13.5 g vertical "
            "cells depend on them most. On the tenth refit (committed 2026-11-27), refitted about as well with T1, T2 "
            "and T4 from 20 deg, those two cells came out 4.84 and 4.28 deg (FF + PVA, sliding mode), above that "
            "preset's band (whose tops were 3.81 and 3.48); refitted about as well with the chambers starting at the "
            "supply's pressure, 3.37 and 2.97 deg, below it (whose bottoms were 3.62 and 3.38): the trial that led to "
            "fitting the start pressure.")


def _fixed_text(members: Sequence[dict]) -> str:
    """A sentence on the fitted parameters every member of ``members`` shares and the fit never profiled
    (:func:`_profiled` leaves them out), or "" if there are none."""
    shown = _profiled(members)
    fixed = [n for n in PARAMETER_TEXT if all(n in m for m in members) and n not in shown]
    if not fixed:
        return ""
    text = ("Every member has the same " + " and ".join(_member_text(members[0], [n]) for n in fixed)
            + ": the fit does not profile " + ("it" if len(fixed) == 1 else "them")
            + ", so the band does not show what " + ("it does" if len(fixed) == 1 else "they do") + ".")
    if "air_fraction" in fixed:
        text += (" `twin whatif air` runs these cells with the air moved and the fit's cost beside each value "
                 "(nothing else refitted).")
    return text


def _spans_text(members: Sequence[dict]) -> str:
    """The span of each profiled parameter over the ensemble's ``members`` (one value said as such)."""
    parts = []
    for name in _profiled(members):
        label, fmt, unit = PARAMETER_TEXT[name]
        low, high = fmt(min(m[name] for m in members)), fmt(max(m[name] for m in members))
        parts.append(f"{label} {_with_unit(f'{low}-{high}', unit)}" if low != high else
                     f"{label} {_with_unit(low, unit)} (one value)")
    return ", ".join(parts)


def _why_pulses(pulses: dict | None, experiment: Sequence[dict]) -> list[str]:
    """The slow trajectories' pulse cycle and each law's opening lag (:func:`pulse_cycle`), against the
    measured order."""
    if not pulses or not pulses["runs"]:
        return []
    names = list(pulses["lag_deg"])
    ts = SLOW_TRAJECTORIES
    runs = pulses["runs"]
    lag = pulses["lag_deg"]
    low, high = pulses["feedforward_pct"]
    gaps = [1e3 / runs[key]["openings_per_s"] for key in runs]
    advances = [runs[key]["advance_deg"] for key in runs]
    errors = [runs[key]["error_at_opening_deg"] for key in runs]
    where = ("inside the dead zone (a held command opens the valve from "
             f"{pulses['opening_pct']:.1f} %)" if high < pulses["opening_pct"] else
             f"partly above the {pulses['opening_pct']:.1f} % that opens the valve")
    line = (f"- **Slow motion in pulses** (T{ts[0]} and T{ts[-1]}, Chapter 5, as-built): on T2 the feed-forward asks "
            f"for {low:.0f}-{high:.0f} % of duty, {where}. In the twin the controllers move the joint in pulses "
            f"there: an opening every {min(gaps):.0f}-{max(gaps):.0f} ms, {min(advances):.1f}-{max(advances):.1f} "
            f"deg of advance per opening, {min(errors):.1f}-{max(errors):.1f} deg of error when the valve opens "
            "(medians, table below). A law opens the valve once its error reaches a lag that its gains and the "
            "valve fix (closed form, T2, the joint at rest behind the reference): "
            + ", ".join(f"{CONTROLLER_LABELS[n]} {lag[n]:.2f} deg" for n in sorted(names, key=lag.get)) + ".")
    if "smc" in lag and "ffpva" in lag:
        measured = {(r["controller"], r["trajectory"]): r["measured"] for r in experiment}
        rig = [measured[("smc", t)] / measured[("ffpva", t)] for t in ts
               if ("smc", t) in measured and ("ffpva", t) in measured]
        twin = "; ".join(f"T{t}: {runs[(n, t)]['rmse_deg']:.2f} ± {runs[(n, t)]['rmse_std_deg']:.2f} and "
                         f"{runs[(m, t)]['rmse_deg']:.2f} ± {runs[(m, t)]['rmse_std_deg']:.2f}"
                         for t in ts for n, m in [("ffpva", "smc")])
        if lag["smc"] >= 0.9 * lag["ffpva"]:
            line += (f" Sliding mode's lag is {lag['smc'] / lag['ffpva']:.2f} of FF + PVA's: at the thesis's gains and "
                     f"phi = {pulses.get('phi', math.nan):g} m/s it gains no lead on slow motion, and the twin tracks "
                     f"with the two about alike (FF + PVA and sliding mode, {twin} deg). ")
            if rig:
                line += ("The rig's sliding mode tracked at " + " and ".join(f"{r:.2f}" for r in rig)
                         + " of its FF + PVA there. If the rig moved in the same pulses, its sliding mode opened its "
                         "valve at a smaller error, or advanced less per opening, than this law on this valve can. "
                         "The thesis does not say which; phi is not fitted.")
        else:
            line += f" FF + PVA and sliding mode on the twin: {twin} deg."
    return [line]


def _why_seeds(v: Validation) -> list[str]:
    """How much of each verdict on seeds 0-4 is the twin's draw of five runs (:func:`seed_rows`)."""
    rows = [r for r in v.seeds or [] if r["groups"]]
    if not rows:
        return []
    runs = max(r["runs"] for r in rows)
    key = ("controller", "trajectory", "payload_g", "orientation")
    verdict = {tuple(r[k] for k in key): r["within_tolerance"] for r in v.rows
               if r["source"] in ("chapter 5 experiment", "chapter 6 T1")}
    sse_verdict = {tuple(r[k] for k in key): r["within_tolerance"] for r in v.rows if r["source"].endswith("T1 SSE range")}
    never = [r for r in rows if r["groups_within"] == 0]
    split = [r for r in rows if 0 < r["groups_within"] < r["groups"]]
    line = (f"- **Five runs or {runs}** (seeds {rows[0]['seeds']}, which no step of the calibration ran; "
            f"{rows[0]['groups']} groups of five; a check, the verdicts stay on seeds 0-4): on the {runs}-run mean, "
            f"{sum(r['within_tolerance'] for r in rows)} of {len(rows)} RMSE cells are within "
            f"{RMSE_TOLERANCE * 100:.0f} % (on seeds 0-4: {sum(verdict.values())} of {len(verdict)}).")
    if never:
        line += (" Out on every five-run group, so not the twin's draw of five runs (in brackets, how far the "
                 "twin is from the measured mean in the measured mean's standard errors): "
                 + ", ".join(f"{_cell_name(r)} (x{r['ratio']:.2f}; {(r['twin_mean'] - r['measured']) / r['measured_se']:+.1f})"
                             for r in never) + ".")
    if split:
        line += (" In on some five-run groups and out on others: "
                 + ", ".join(f"{_cell_name(r)} (seeds 0-4 x{_fmt(r['five_run_mean'] and r['five_run_mean'] / r['measured'])}, "
                             f"{r['runs']} runs x{r['ratio']:.2f}, {r['groups_within']} of {r['groups']} groups within)"
                             for r in split) + ".")
    flat = [r for r in rows if r["payload_g"] == 0.0 and r["orientation"] == "horizontal"]
    measured, twin = controller_order(flat, "measured"), controller_order(flat, "twin_mean")
    if measured:
        same = [t for t in measured if measured[t] == twin[t]]
        line += (f" Controller order on the {runs}-run means (Chapter 5): right on {len(same)} of {len(measured)} "
                 "trajectories" + "".join(f"; T{t}: twin {twin[t]} (" + ", ".join(
                     f"{r['twin_mean']:.2f}" for r in sorted((r for r in flat if r["trajectory"] == t),
                                                             key=lambda r: r["twin_mean"])) + ")"
                     for t in measured if t not in same) + ".")
    sse = [r for r in rows if r["sse_twin"] is not None]
    if sse:
        widths = [r["sse_group_high"] - r["sse_group_low"] for r in sse]
        line += (f" T1 steady-error ranges: {sum(r['sse_within_tolerance'] for r in sse)} of {len(sse)} within "
                 f"±{SSE_TOLERANCE_DEG:g} deg on the mean of the groups' ranges (on seeds 0-4: "
                 f"{sum(sse_verdict.values())} of {len(sse_verdict)}). The largest |SSE| of five runs is a rough "
                 f"measure: across one cell's groups it spreads over {float(np.median(widths)):.2f} deg (median over "
                 f"the cells; up to {max(widths):.2f}), against a tolerance band {2 * SSE_TOLERANCE_DEG:g} deg wide.")
    narrow = [r for r in rows if r["twin_std"] < r["measured_std_low"]]
    wide = [r for r in rows if r["twin_std"] > r["measured_std_high"]]

    def stds(r: dict) -> str:
        return (f"{_cell_name(r)} ({r['twin_std']:.2f} against {r['measured_std']:.2f}; "
                f"{r['measured_std_low']:.2f}-{r['measured_std_high']:.2f})")

    line += (f" Run-to-run spread: the twin's std over its {runs} runs lies in the {SPREAD_CONFIDENCE * 100:.0f} % "
             f"interval of the rig's std that its five runs allow on {sum(r['spread_within'] for r in rows)} of "
             f"{len(rows)} cells" + ("; below it (the twin steadier than the rig) on " + ", ".join(map(stds, narrow))
                                     if narrow else "")
             + ("; above it on " + ", ".join(map(stds, wide)) if wide else "") + ".")
    line += (" The measured means carry their own five-run error: the thesis's std / sqrt 5 is "
             f"{_percent_span([r['measured_se'] / r['measured'] for r in rows])} of them.")
    stalled = sum(r["stalled_runs"] for r in rows)
    if stalled:
        line += f" {stalled} of these runs stalled (an error past {STALL_ERROR_DEG:g} deg), counted in their means."
    return [line]


def _why_effects(v: Validation) -> list[str]:
    """Whether the twin shows what a payload and turning the joint on its side cost (:func:`payload_effects`)."""
    effects = v.effects
    if not effects:
        return []
    line = (f"- **What a payload and the side cost** (Chapter 6 T1, each cell's RMSE over the same controller's 0 g "
            f"flat; the twin on seeds {v.seeds[0]['seeds']}): ")
    parts = []
    for c in dict.fromkeys(r["controller"] for r in effects):
        mine = [r for r in effects if r["controller"] == c]
        parts.append(f"{CONTROLLER_LABELS[c]} measured " + " / ".join(f"x{r['measured_effect']:.2f}" for r in mine)
                     + ", twin " + " / ".join(f"x{r['twin_effect']:.2f}" for r in mine)
                     + " (" + ", ".join(_effect_name(r) for r in mine) + ")")
    line += "; ".join(parts) + ". "
    low = [r for r in effects if r["difference_in_se"] < -EFFECT_SIGNIFICANCE]
    high = [r for r in effects if r["difference_in_se"] > EFFECT_SIGNIFICANCE]
    judged = sum(math.isfinite(r["difference_in_se"]) for r in effects)
    line += (f"The twin's effect is smaller than the measured one by more than {EFFECT_SIGNIFICANCE:g} combined "
             f"standard errors (normal approximation) on {len(low)} of {judged} cells, larger on {len(high)}")
    level = {(r["controller"], r["payload_g"], r["orientation"]): r["within_tolerance"] for r in v.seeds
             if r["trajectory"] == 1}
    hidden = [r for r in low + high if level.get((r["controller"], r["payload_g"], r["orientation"]))]
    if hidden:
        line += ("; of these, the RMSE check passes all the same (the cell's mean is within "
                 f"{RMSE_TOLERANCE * 100:.0f} % on the same runs) on " + ", ".join(
                     f"{CONTROLLER_LABELS[r['controller']]} {_effect_name(r)}" for r in hidden))
    line += "."
    return [line]


def _why_phases(v: Validation) -> list[str]:
    """Where in T1 the twin's payload costs fall, per controller (:func:`payload_phases`), each phase's RMS error
    over the same controller's 0 g flat one."""
    rows = v.phases or []
    flat = {r["controller"]: r for r in rows if r["payload_g"] == 0.0 and r["orientation"] == "horizontal"}
    parts = []
    for c, base in flat.items():
        loaded = [r for r in rows if r["controller"] == c and r is not base]
        if loaded:
            parts.append(f"{CONTROLLER_LABELS[c]} move " + " / ".join(f"x{r['move_deg'] / base['move_deg']:.2f}"
                                                                       for r in loaded)
                         + ", hold " + " / ".join(f"x{r['hold_deg'] / base['hold_deg']:.2f}" for r in loaded)
                         + ", RMSE " + " / ".join(f"x{r['rmse_deg'] / base['rmse_deg']:.2f}" for r in loaded)
                         + " (" + ", ".join(_effect_name(r) for r in loaded) + ")")
    if not parts:
        return []
    move_end = rows[0]["move_end_s"]
    return [f"- **Where in T1 the twin's payload costs fall** (the committed preset, seeds {SEEDS[0]}-{SEEDS[-1]}; the "
            f"RMS error over T1's move, its first {move_end:g} s, and over its hold, the rest, each over the same "
            "controller's 0 g flat cell; the table below has the degrees): " + "; ".join(parts) + ". The thesis "
            "gives each run's RMSE over the whole of it, so how the rig's costs split between move and hold is not "
            "known."]


def _way_text(run: dict, way: int) -> str:
    """One way of a full-duty run: its speed in mm/s, or why there is none."""
    if run["warnings"]:
        return "failed"
    if math.isfinite(run["speeds"][way]):
        return f"{run['speeds'][way] * 1e3:.0f}"
    if run["travel"][way] < BROKE_AWAY:
        return "did not break away"
    return f"did not cross the window (went {run['travel'][way] * 1e3:.1f} mm)"


def _why_full_duty(rows: Sequence[dict] | None) -> list[str]:
    """What §4.5.1's full-duty runs show: each end of the measured range against the twin's way that sets it,
    set against the interval the printed digit allows (no tolerance of its own: a check)."""
    if not rows:
        return []
    parts = []
    for r in rows:
        run = r["runs"]["as-built"]
        low, high = (x * 1e3 for x in r["interval"])
        measured = f"the {low:g}-{high:g} mm/s that the printed {r['end']} speed, {r['measured']:g} m/s, stands for"
        k = r["way"]
        if k is None:
            parts.append(f"at {r['pressure'] / 1e3:g} kPa the as-built rack CW / CCW: {_way_text(run, 0)} / "
                         f"{_way_text(run, 1)}, against {measured}")
            continue
        twin = run["speeds"][k] * 1e3
        where = "inside" if low <= twin <= high else ("under" if twin < low else "over")
        parts.append(f"at {r['pressure'] / 1e3:g} kPa the as-built rack's {r['end']} way ({('CW', 'CCW')[k]}) runs "
                     f"at {twin:.0f} mm/s, {where} {measured} (x{r['ratio']:.2f} of it); {('CCW', 'CW')[k]} at "
                     f"{_way_text(run, 1 - k)}; the thesis's model CW / CCW "
                     + " / ".join(_way_text(r["runs"]["thesis"], w) for w in (0, 1)))
    built = [r["runs"]["as-built"] for r in rows]
    moved = all(not run["warnings"] and min(run["travel"]) >= BROKE_AWAY for run in built)
    ccw_slower = all(r["way"] is not None and run["speeds"][1] < run["speeds"][0]
                     for r, run in zip(rows, built, strict=True))
    return ["- **Full-duty speed** (§4.5.1's force-loss runs; a check: which pressure each end of the measured "
            "range came at is inferred, and the speed's window is the twin's choice): " + "; ".join(parts) + "."
            + (" The as-built joint breaks away from rest both ways at each pressure, as the rig did." if moved else
               " The as-built joint does **not** break away from rest both ways at each pressure (or its run "
               "failed); the rig did.")
            + (" Its CCW way (towards 0 deg) is the slower, by its fitted CCW Coulomb scale (fitted because the "
               "thesis tracked worse moving CCW); with that scale reset to 1 it runs CW / CCW at " + "; ".join(
                   " / ".join(_way_text(r["runs"]["as-built, no CCW scale"], w) for w in (0, 1))
                   + f" mm/s at {r['pressure'] / 1e3:g} kPa" for r in rows) + "." if ccw_slower else "")]


def _why(v: Validation) -> list[str]:
    """What the runs themselves show about the misses: computed, not written in advance."""
    rows = v.rows
    lines = []
    experiment = [r for r in rows if r["source"] == "chapter 5 experiment"]
    measured, twin = controller_order(experiment, "measured"), controller_order(experiment, "twin_mean")
    same = [t for t in measured if measured[t] == twin[t]]
    lines.append(f"- **Controller order** (Chapter 5 experiments, best first): right on "
                 f"{len(same)} of {len(measured)} trajectories. "
                 + "; ".join(f"T{t}: measured {measured[t]}, twin {twin[t]}" for t in measured if t not in same)
                 + ("." if len(same) < len(measured) else ""))
    lines += _why_members(v)
    by_member = member_orders(v.prediction_detail, measured)
    if by_member:
        count = len(v.prediction_detail["members"])
        split = [t for t, right in by_member.items() if 0 < len(right) < count]
        lines.append(
            f"- **Controller order across the ensemble** (Chapter 5 experiments, seeds 0-4, each of the {count} "
            "members that fit the measurements about equally well): "
            + "; ".join(f"T{t} right on {len(right)}" + _which_members(count, right)
                        + _unknown_text(v.prediction_detail, t)
                        for t, right in by_member.items()) + ". "
            + ("So within what the data allow the twin does not settle the order of "
               + _and_list([f"T{t}" for t in split])
               + ": it comes out right on some members and wrong on others, and the committed preset's "
               "order there is one of them, not a finding." if split else
               "Each order is right on every member or on none: within the ensemble, the parameters the data "
               "do not pin do not turn it."))
    parts = v.sliding_mode
    if parts and parts["trajectories"]:
        ts = sorted(parts["trajectories"])
        ffpva = {r["trajectory"]: r["twin_mean"] for r in experiment if r["controller"] == "ffpva"}

        def listed(values) -> str:
            return " / ".join(_fmt(x) for x in values)

        lines.append(
            "- **Sliding mode's switching term** (Chapter 5, " + "-".join(f"T{t}" for t in (ts[0], ts[-1]))
            + ", as-built): sliding mode tracks at "
            + listed(parts["trajectories"][t]["as_run_deg"] for t in ts) + " deg, and without its switching term at "
            + listed(parts["trajectories"][t]["without_switching_deg"] for t in ts) + " deg (FF + PVA: "
            + listed(ffpva.get(t) for t in ts) + "). With no dead-zone compensation, that term is what lifts its "
            f"small commands past the valve's dead zone (no flow below {parts['dead_zone_pct']:.0f} % here), and at "
            "the thesis's phi it adds " + listed(parts["trajectories"][t]["switching_rms_pct"] for t in ts)
            + " % of duty RMS. How it compares with FF + PVA turns on that term's strength against the dead zone.")
    lines += _why_pulses(v.pulses, experiment)
    lines += _why_seeds(v)
    lines += _why_effects(v)
    lines += _why_phases(v)
    by = {(r["source"], r["controller"], r["trajectory"], r["payload_g"], r["orientation"]): r for r in rows}
    for c in ("ffpva", "smc"):
        heavy = by.get(("chapter 6 T1", c, 1, 13.5, "vertical"))
        stalled = v.stalled.get((c, 1, 13.5, "vertical"), 0)
        if heavy:
            lines.append(f"- **{CONTROLLER_LABELS[c]}, 13.5 g vertical, T1**: measured {heavy['measured']:.2f}, twin "
                         f"{heavy['twin_mean']:.2f} deg, {stalled} of {len(SEEDS)} twin runs stalled. " + (
                             "The twin lifts the payload but tracks it better than the real joint did: the real "
                             "joint lost more to the payload than the twin does (its lift was nearer its edge)."
                             if heavy["ratio"] < 1 - RMSE_TOLERANCE and not stalled else
                             "Within tolerance." if heavy["within_tolerance"] else
                             "The twin tracks it worse than the real joint did."))
    sim_smc = [r for r in rows if r["source"] == "chapter 5 simulation" and r["controller"] == "smc"]
    if sim_smc and all(r["ratio"] < 0.5 for r in sim_smc):
        better = sorted(1 / r["ratio"] for r in sim_smc)
        lines.append(f"- **Sliding mode on `thesis`** tracks {better[0]:.1f}-{better[-1]:.1f} times better than the "
                     "thesis simulated: the `thesis` plant's averaged valve lets the 1 ms switching act at once, which "
                     "a valve that needs 5 ms to open cannot.")
    lag = [r for r in rows if r["source"].startswith("4.6")]
    if lag and not lag[0]["within_tolerance"]:
        lines.append(f"- **Open-loop lag**: the as-built twin reverses sooner ({lag[0]['twin_mean']:.0f} ms) than the "
                     f"thesis's model ({lag[0]['measured']:.0f} ms); the real joint reversed later than the model. "
                     "The twin's chambers build pressure faster than the real ones did.")
    lines += _why_full_duty(v.full_duty)
    members = v.prediction_detail["members"]
    # Judged on every member's mean, not on the 10-90 % band alone: with a few members the band's ends are
    # interpolated between the two lowest and the two highest, so one member set apart by a parameter that
    # the data do not pin would fall mostly outside it.
    means = member_means(v.prediction_detail)
    span = means.max(axis=1) - means.min(axis=1)
    k = int(np.argmax(span / np.array([r["band_p50"] for r in v.prediction])))
    widest, relative = v.prediction[k], span[k] / v.prediction[k]["band_p50"]
    lowest, highest = members[int(np.argmin(means[k]))], members[int(np.argmax(means[k]))]
    differ = [n for n in _profiled(members) if lowest[n] != highest[n]]
    lines.append(f"- **The parameters the data do not pin**: the ensemble's {len(members)} members span "
                 f"{_spans_text(members)}, fitting the measurements about equally well. The T3 cell that depends "
                 f"on them most is {CONTROLLER_LABELS[widest['controller']]} {widest['payload_g']:g} g "
                 f"{widest['orientation']}: its members' means span {means[k].min():.2f}-{means[k].max():.2f} deg "
                 f"({relative:.0%} of the median; 10-90 % band {widest['band_p10']:.2f}-{widest['band_p90']:.2f})"
                 + (f", from member {int(np.argmin(means[k]))} ({_member_text(lowest, differ)}) to member "
                    f"{int(np.argmax(means[k]))} ({_member_text(highest, differ)})" if differ else "")
                 + ". So within the ensemble the T3 cells' size "
                 + ("does not turn on them" if relative < RMSE_TOLERANCE else "**turns on them** there: read the "
                    "members' range, not the committed value")
                 + " (the ensemble holds the sets the fit's search evaluated; a set it did not reach may fit as well "
                    "and lie outside the members' range"
                 + ("; no run of any member stalls)." if not any(r["stalled_runs"] for r in v.prediction) else
                    "); some members' runs stall, counted per cell above."))
    text, apart = _members_lead_text(v)
    if apart:
        lines.append(f"- **Which law leads on T3 turns on which of the equally good fits holds** (the ensemble's "
                     f"{len(members)} members): {text}. Set apart: "
                     + _numbers_text(apart) + " (the members' table at the end gives the values). Read the members' "
                     "means there, not the committed preset's lead; the 10-90 % band leaves a "
                     "lone member out.")
    known = {r["controller"]: r for r in rows if r["source"] == "chapter 5 experiment" and r["trajectory"] == 3
             and r["controller"] in ("ffpva", "smc")}
    if known:
        lines.append("- **What the band does not hold**: it is the spread over parameter sets that fit equally well, "
                     "not the model's own error. The one T3 cell that was measured and fitted (0 g, horizontal, "
                     "Chapter 5) is off by " + ", ".join(f"{CONTROLLER_LABELS[c]} x{r['ratio']:.2f}" for c, r in known.items())
                     + "; a T3 prediction is as far off as that, at least, before its band.")
    return lines


def _in_short(v: Validation, missed: Sequence[dict]) -> list[str]:
    """The report's opening: what is within tolerance, what is not (each miss's size and reading), and what the
    blind prediction says, in three lines computed from the same rows as the tables below. Added 2026-11-27,
    after every result it reads: it says again what the tables say, in short. ``missed``: :func:`misses` of ``v``."""
    measured = [r for r in v.rows if r["source"] in ("chapter 5 experiment", "chapter 6 T1")]
    within = [r for r in measured if r["within_tolerance"]]
    parts = ", ".join(f"{label} {sum(r['within_tolerance'] for r in rs)} of {len(rs)}"
                      for source, label in (("chapter 5 experiment", "Chapter 5 experiments"),
                                            ("chapter 6 T1", "Chapter 6 T1"))
                      if (rs := [r for r in measured if r["source"] == source]))
    heavy = [r for r in measured if r["payload_g"] and r["orientation"] == "vertical"]
    stalled = sum(v.stalled.values())
    first = f"- **Within tolerance**: {len(within)} of {len(measured)} measured RMSE means ({parts})"
    if heavy:
        first += (f"; of the vertical cells with a payload, {sum(r['within_tolerance'] for r in heavy)} of "
                  f"{len(heavy)} RMSE means")
    first += (", and no run of the measured cells stalls." if not stalled else
              f"; {counted(stalled, 'run')} of the measured cells stall{'s' if stalled == 1 else ''}.")
    checked = [r for r in v.rows if r["source"].startswith("4.4.3 valve test") and _judged(r)]
    delays = [r for r in v.rows if r["source"].startswith("4.4.3 valve") and "delay" in r["source"]]
    if checked or delays:
        first += (f" The valve: R(d) within {valve_study.TOLERANCE * 100:.0f} % of eq. 4.4.2 at "
                  f"{sum(r['within_tolerance'] for r in checked)} of {len(checked)} duties from "
                  f"{valve_study.CHECKED_FROM:g} %, delays within {DELAY_TOLERANCE * 1e3:g} ms on "
                  f"{sum(r['within_tolerance'] for r in delays)} of {len(delays)}.")
    rmse = [m for m in missed if m["comparison"] == "RMSE" and m["missed_on"] == "seeds 0-4"]
    orders = [m for m in missed if m["comparison"] == "controller order" and m["missed_on"] == "seeds 0-4"]
    sse = [r for r in v.rows if r["source"].endswith("T1 SSE range")]
    out = []
    if rmse:
        out.append("RMSE means: " + "; ".join(f"{_cell_name(m)} {_times(m['off_by'])} ({READINGS[m['reading']]})"
                                              for m in rmse))
    if orders:
        trajectories = {r["trajectory"] for r in v.rows if r["source"] == "chapter 5 experiment"}
        out.append(f"the controller order, wrong on {len(orders)} of {len(trajectories)} Chapter 5 trajectories ("
                   + "; ".join(f"T{m['trajectory']}: {READINGS[m['reading']]}" for m in orders) + ")")
    if sse and not all(r["within_tolerance"] for r in sse):
        readings: dict[str, int] = {}
        for m in missed:
            if m["comparison"] == "T1 SSE range" and m["missed_on"] == "seeds 0-4":
                readings[m["reading"]] = readings.get(m["reading"], 0) + 1
        out.append(f"T1 steady-error ranges, out on {sum(not r['within_tolerance'] for r in sse)} of {len(sse)} ("
                   + ", ".join(f"{READINGS[k]}: {n}" for k, n in readings.items()) + ")")
    for source, what in (("chapter 5 simulation", "the `thesis` plant's Chapter 5 simulations"),
                         ("4.6", "the open-loop lag at reversals")):
        rs = [r for r in v.rows if r["source"].startswith(source)]
        if rs and not all(r["within_tolerance"] for r in rs):
            out.append(f"{what}, out on {sum(not r['within_tolerance'] for r in rs)} of {len(rs)}")
    lines = [first]
    if out:
        lines.append("- **Outside it** (seeds 0-4; a reading links a miss to another check, it does not prove its "
                     "cause; the sections below say more): " + ". ".join(x[0].upper() + x[1:] for x in out) + ".")
    if v.prediction:
        leads, both = lead_counts(v.prediction, [r["twin_mean"] for r in v.prediction])  # a failed run ranks none
        stalls = sum(r["stalled_runs"] for r in v.prediction)
        members_text = _members_lead_text(v)[0] if both and v.prediction_detail.get("per_member") else ""
        lines.append(f"- **Blind T3 prediction** ({counted(len(v.prediction), 'cell')}): "
                     + (", ".join(f"{CONTROLLER_LABELS[c]} tracks best on {n} of {both} payload and orientation "
                                  "cells" for c, n in sorted(leads.items())) + " (the committed preset)"
                        + (f". Across the ensemble: {members_text}" if members_text else "") + ". " if both else "")
                     + ("No run of any ensemble member stalls." if not stalls else
                        f"{counted(stalls, 'run')} of the ensemble's members stall{'s' if stalls == 1 else ''}.")
                     + (" The band and the members' range are the spread over the fitted parameters only (among them "
                        "what the chambers held when a run began, which the members' range holds more of), not over "
                        "the other choices the thesis leaves open (T3's length and start, the supply, where T1, T2 and "
                        "T4 started), which the prediction section names."
                        if fits_start_pressure() else
                        " The band is the spread over the fitted parameters only, not over the choices the thesis "
                        "leaves open (T3's length and start, the supply, where T1, T2 and T4 started, what the "
                        "chambers held when a run began), which the prediction section names."))
    return lines


def _tolerances_text() -> str:
    """Each comparison's tolerance, as the report's opening paragraph says it, from the constants that judge."""
    return (f"±{SIMULATION_TOLERANCE_DEG:g} deg for the thesis's simulations, {RMSE_TOLERANCE * 100:.0f} % for measured "
            f"RMSE means, ±{SSE_TOLERANCE_DEG:g} deg for T1 steady-error ranges, {valve_study.TOLERANCE * 100:.0f} % for the "
            f"valve's R(d) from {valve_study.CHECKED_FROM:g} % duty, {DELAY_TOLERANCE * 1e3:g} ms for the valve's delays")


def _terms() -> str:
    """The words the report uses, said once at its head."""
    from controllers.smc import SlidingModeGains

    phi = next(f.default for f in dataclasses.fields(SlidingModeGains) if f.name == "boundary_layer")
    return (
        "Terms: **within** means within the comparison's tolerance above; **x0.44** is the twin's value over the "
        "measured one. **SSE** is a T1 run's steady error at its end, and an **SSE range** is ± the largest |SSE| "
        "of five runs. **Horizontal** (also *flat*): gravity along the joint's shaft; **vertical** (on its *side*): "
        "gravity in the plane of rotation, 0 deg hanging down (inferred). Plants: **`thesis`** is what the thesis "
        "simulated, its Chapter 4 model with the simulation gains (the valve as eq. 4.4.2 averaged over the PWM "
        "period, with its opening and closing delays; eq. 4.5.7's friction; `thesis-deadzone` adds the valve's dead "
        "zone); **`as-built`** is that plant plus, as physics, the effects the thesis blames for its experiments' "
        "larger errors (among them the physical solenoid valve, the supply line, the chambers' free air, a leak and "
        "stiction), with the experiment gains and scored on the Hall sensor; the few parameters the thesis does not "
        "give are fitted to the measurements (`twin calibrate`). The **ensemble** is the parameter sets that fit "
        "the measurements about equally well (within the fit's seed-to-seed noise); each is a **member**, numbered "
        "from 0 in the members' table at the end. The **committed preset** is the fit's best values, which every "
        "verdict uses (the table marks the member that has them). The **fresh seeds** are "
        f"{FRESH_SEEDS[0]}-{FRESH_SEEDS[-1]}: noise seeds no step of the calibration ran. **phi** is sliding "
        f"mode's boundary layer, {phi:g} m/s as the thesis ran it (not fitted).")


def report(v: Validation) -> str:
    """``validation.md``: what matches, what does not, and why as far as the twin shows."""
    rows = v.rows
    groups: dict[str, list[dict]] = {}
    for r in rows:
        head = "4.4.3 valve test" if r["source"].startswith("4.4.3") else r["source"].split(" (")[0]
        groups.setdefault(head, []).append(r)
    missed = misses(v)
    lines = ["# How far to trust the twin", "",
             "Written by `twin validate`. Every published comparison the twin can be held to, run from this "
             "code and the committed as-built calibration, and the blind prediction of the Chapter 6 T3 cells. "
             "Closed-loop verdicts are on means over the thesis's five runs (seeds 0-4); the rows marked as a check "
             "run more seeds, and their section says how. Degrees unless named. "
             f"`within` is each comparison's tolerance: {_tolerances_text()}.", "",
             _terms(), "",
             "## In short", "", *_in_short(v, missed), "",
             "## Summary", "", "| comparison | plant | within tolerance |", "|---|---|---|"]
    for head, members in groups.items():
        judged = [r for r in members if _judged(r)]
        shown = len(members) - len(judged)
        lines.append(f"| {head} | {members[0]['plant']} | {sum(r['within_tolerance'] for r in judged)} of "
                     f"{len(judged)}" + (f" (and {counted(shown, 'row')} below the duties checked: shown, not judged)"
                                         if shown else "") + " |")
    if v.seeds and any(r["groups"] for r in v.seeds):
        more = f"mean of {max(r['runs'] for r in v.seeds)} runs on seeds {v.seeds[0]['seeds']} (a check, not the verdict)"
        sse = [r for r in v.seeds if r["sse_twin"] is not None]
        lines.append(f"| chapter 5 experiment and chapter 6 T1, {more} | as-built | "
                     f"{sum(r['within_tolerance'] for r in v.seeds)} of {len(v.seeds)} |")
        if sse:
            lines.append(f"| T1 SSE range, mean of the five-run ranges on seeds {v.seeds[0]['seeds']} (a check) | "
                         f"as-built | {sum(r['sse_within_tolerance'] for r in sse)} of {len(sse)} |")
    lines += ["", "![twin against measurement](validation.png)", ""]
    if missed:
        lines += ["## Every miss, and what the other checks show about it", "",
                  f"Each comparison judged against its tolerance (an RMSE mean within {RMSE_TOLERANCE * 100:.0f} %, a "
                  f"T1 SSE range within ±{SSE_TOLERANCE_DEG:g} deg, each Chapter 5 trajectory's controller order) "
                  "that misses on seeds 0-4 (the verdict's), or only on the fresh seeds 40-79. `off by` is the twin "
                  "over the measured (an RMSE) or the twin less the measured (an SSE range, deg). `fresh seeds` is the "
                  "same measure on seeds 40-79: the RMSE ratio on the mean of their runs, the mean of their five-run "
                  "groups' SSE ranges, or their order; then whether within (or right), and how many of the eight "
                  "five-run groups are within. A reading links a miss to another check; it is not a proof of its "
                  "cause. It is the first of these rules that applies (`misses.csv` has the table):", "",
                  "- **runs that failed**: a mean that is not a number;",
                  "- **the draw**: a miss on seeds 0-4 that is within (an order: right) on the fresh seeds;",
                  "- **the rig's cell departs from its own T2 and T3**: a 0 g horizontal T1 cell whose measured "
                  "RMSE is more than "
                  f"{RMSE_TOLERANCE * 100:.0f} % off, the other way from the twin's, what the same law's measured T2 "
                  "and T3 each imply for it by a joint that lags its reference a fixed time, while the twin's is "
                  f"within {RMSE_TOLERANCE * 100:.0f} % of both;",
                  "- **§8's largest error is off the same way**: a 0 g horizontal cell whose largest error and the "
                  f"thesis's differ by more than {RMSE_TOLERANCE * 100:.0f} % in the direction of the miss (on the "
                  "seeds it misses on);",
                  "- **sliding mode's opening lag**: sliding mode tracks a slow trajectory too badly while its "
                  "closed-form lag (the error at which a law's command opens its valve on T2's ramp, from its gains"
                  + ("; \"Slow motion in pulses\" below" if v.pulses else "") + ") is no more than 10 % shorter "
                  "than FF + PVA's;",
                  "- **its 0 g flat level**: a Chapter 6 cell out on the fresh seeds whose payload cost there "
                  f"matches the rig's within {EFFECT_SIGNIFICANCE:g} standard errors while its controller's 0 g "
                  "horizontal cell is out the same way;",
                  "- **its payload's cost**: a Chapter 6 cell out on the fresh seeds whose payload costs the twin "
                  f"more (or less) than the rig by more than {EFFECT_SIGNIFICANCE:g} standard errors, the way it "
                  "misses;",
                  "- **where the runs end scatters** (or **is off zero**): an SSE range out on the fresh seeds too, "
                  "by whether the twin's signed steady errors centre within half a std of zero;",
                  "- **follows**: an order that the measured values of its out cells would put right;",
                  "- **the rig's runs do not settle it**: an order whose every pair the twin ranks the other way is "
                  f"less than {EFFECT_SIGNIFICANCE:g} combined standard errors apart in the thesis's five-run means, "
                  "with the twin's gap less than as far from the rig's;",
                  "- else **not shown by the twin**.", "",
                  "The table and its rules were added on 2026-11-25, after every result they read; **its payload's "
                  "cost** on 2026-11-26, after the one miss it reads; **the rig's runs do not settle it** on "
                  "2026-11-27, after the one order it reads; **the rig's cell departs from its own T2 and T3** on "
                  "2026-12-08, after the one miss it reads.", "",
                  "| comparison | missed on | cell | measured | twin, seeds 0-4 | off by | fresh seeds | reading | "
                  "what the other checks show |", "|---|---|---|---|---|---|---|---|---|"]
        lines += [_miss_row(m) for m in missed]
        lines.append("")
    lines += ["## Why, as far as the twin shows", ""]
    lines += _why(v) + [""]
    if v.pulses and v.pulses["runs"]:
        lines += [f"### Slow motion in pulses (Chapter 5 experiments' T2 and T3, as-built, seeds {SEEDS[0]}-{SEEDS[-1]})",
                  "",
                  "Per opening of a discharge valve: the advance of the scored angle until the next opening, and "
                  f"the error when it opened (medians over the runs). The lag is the closed form on T2 (median "
                  f"over the ramp), for T3's rows too; the error at opening exceeds it by the wait for the next "
                  f"period's start (on T2 the reference moves {v.pulses['period_advance_deg']:.1f} deg a period) and "
                  f"the {v.pulses['opening_delay_ms']:g} ms the valve takes to open.", "",
                  "| controller | T | RMSE (deg) | openings per s | advance per opening (deg) | error at opening (deg) "
                  "| lag on T2 (deg) |", "|---|---|---|---|---|---|---|"]
        for (name, t), run in v.pulses["runs"].items():
            lines.append(f"| {CONTROLLER_LABELS[name]} | {t} | {run['rmse_deg']:.2f} | {run['openings_per_s']:.1f} | "
                         f"{run['advance_deg']:.2f} | {run['error_at_opening_deg']:.2f} | "
                         f"{v.pulses['lag_deg'][name]:.2f} |")
        lines += ["", "![T2's first run: the error, each opening of a discharge valve and the law's lag](pulses.png)", ""]
    if v.phases:
        lines += [f"### Where in T1 a payload costs (Chapter 6 T1 cells, as-built, seeds {SEEDS[0]}-{SEEDS[-1]})", "",
                  f"RMS error (deg, mean over the runs) over T1's move (its first {v.phases[0]['move_end_s']:g} s) and "
                  "over its hold (the rest), beside the run's RMSE and the measured mean.", "",
                  "| controller | payload | orientation | measured RMSE | twin RMSE | move | hold |",
                  "|---|---|---|---|---|---|---|"]
        measured = {(r["controller"], r["payload_g"], r["orientation"]): r["measured"] for r in v.rows
                    if r["source"] in ("chapter 5 experiment", "chapter 6 T1") and r["trajectory"] == 1}
        for r in v.phases:
            lines.append(f"| {CONTROLLER_LABELS[r['controller']]} | {r['payload_g']:g} g | {r['orientation']} | "
                         f"{_fmt(measured.get((r['controller'], r['payload_g'], r['orientation'])))} | "
                         f"{_fmt(r['rmse_deg'])} | {_fmt(r['move_deg'])} | {_fmt(r['hold_deg'])} |")
        lines.append("")

    def table(title: str, members: list[dict], note: str) -> None:
        if not members:
            return
        lines.extend([f"## {title}", "", note, "",
                      "| controller | T | payload | orientation | measured | twin (mean ± std) | twin / measured | within |",
                      "|---|---|---|---|---|---|---|---|"])
        for r in members:
            lines.append(f"| {CONTROLLER_LABELS.get(r['controller'], r['controller'] or '')} | {r['trajectory'] or ''} | "
                         f"{'' if r['payload_g'] is None else format(r['payload_g'], 'g') + ' g'} | "
                         f"{r['orientation'] or ''} | {_fmt(r['measured'])} | {_fmt(r['twin_mean'])}"
                         f"{'' if r['twin_std'] is None else ' ± ' + _fmt(r['twin_std'])} | {_fmt(r['ratio'])} | "
                         f"{'yes' if r['within_tolerance'] else '**no**'} |")
        lines.append("")

    table("Chapter 5 simulations, `thesis` plant (RMSE)", groups.get("chapter 5 simulation", []),
          f"The thesis simulated its own model; tolerance ±{SIMULATION_TOLERANCE_DEG} deg.")
    table("Chapter 5 experiments, `as-built` plant (RMSE)", groups.get("chapter 5 experiment", []),
          f"Horizontal, no payload; tolerance {RMSE_TOLERANCE:.0%}. These cells were fitted (`twin calibrate`).")
    table("Chapter 6 T1 cells, `as-built` plant (RMSE)", groups.get("chapter 6 T1", []),
          "Payload at the link tip. Also fitted: they show how well the fit could do, not a prediction.")
    table("T1 steady-error ranges, `as-built` plant (± max |SSE| of five runs)",
          groups.get("chapter 5 experiment, T1 SSE range", []) + groups.get("chapter 6 T1, T1 SSE range", []),
          f"Tolerance ±{SSE_TOLERANCE_DEG} deg.")
    if v.max_errors:
        lines += ["## Largest error (§8's max-error column; a check)", "",
                  "The largest |error| of a run, in degrees: the thesis gives one rounded number per cell (PVA + DZC "
                  "on T1 only); the twin's is the mean of its runs' and the largest of them, on seeds 0-4, and the "
                  "mean on the fresh seeds. No tolerance is set, so it is no verdict; `twin / measured` uses the "
                  "mean. It is a size, not a time: the thesis does not say when in the run it fell. Added 2026-11-25, "
                  "after the RMSE verdicts.", "",
                  "| controller | T | measured | twin, seeds 0-4: mean (largest) | twin / measured | fresh seeds, mean |",
                  "|---|---|---|---|---|---|"]
        for r in v.max_errors:
            lines.append(f"| {CONTROLLER_LABELS[r['controller']]} | {r['trajectory']} | {r['measured']:g} | "
                         f"{r['twin_mean']:.1f} ({r['twin_high']:.1f}) | {r['ratio']:.2f} | {_fmt(r['fresh_mean'], '.1f')} |")
        lines.append("")
    if v.seeds:
        n = max(r["runs"] for r in v.seeds)
        lines += [f"## Five runs or {n}: the measured cells on seeds {v.seeds[0]['seeds']}", "",
                  f"Every measured cell again on {n} noise seeds that no step of the calibration ran, in "
                  f"{v.seeds[0]['groups']} groups of five. `groups within` counts the five-run groups within tolerance "
                  f"({RMSE_TOLERANCE * 100:.0f} % of the RMSE mean, ±{SSE_TOLERANCE_DEG:g} deg of the SSE range). The measured "
                  "mean's ± is its standard error (the thesis's std / sqrt 5). The measured std's interval is the "
                  f"{SPREAD_CONFIDENCE * 100:.0f} % range of the rig's run-to-run std that five runs allow (chi-square, "
                  f"{calibrate.THESIS_RUNS - 1} degrees of freedom); **out** marks a twin std outside it. The SSE range on these runs is the "
                  "mean of the groups' ranges. The verdicts in the summary's other rows judge seeds 0-4, the "
                  "thesis's five runs.", "",
                  f"| controller | T | payload | orientation | measured | seeds 0-4 | {n} runs (mean ± std) | "
                  f"measured std ({SPREAD_CONFIDENCE * 100:.0f} % interval) | "
                  f"twin / measured | within | groups within (low-high) | SSE range: measured | seeds 0-4 | groups' "
                  "mean (low-high) | groups within |", "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
        for r in v.seeds:
            sse = (f"{_fmt(r['sse_measured'])} | {_fmt(r['sse_five_run'])} | {_fmt(r['sse_twin'])} "
                   f"({_fmt(r['sse_group_low'])}-{_fmt(r['sse_group_high'])}) | {r['sse_groups_within']} of {r['groups']}"
                   if r["sse_twin"] is not None else "| | |")
            lines.append(f"| {CONTROLLER_LABELS[r['controller']]} | {r['trajectory']} | {r['payload_g']:g} g | "
                         f"{r['orientation']} | {r['measured']:.2f} ± {r['measured_se']:.2f} | "
                         f"{_fmt(r['five_run_mean'])} | {r['twin_mean']:.2f} ± {r['twin_std']:.2f} | "
                         f"{r['measured_std']:.2f} ({r['measured_std_low']:.2f}-{r['measured_std_high']:.2f})"
                         f"{'' if r['spread_within'] else ' **out**'} | {r['ratio']:.2f} | "
                         f"{'yes' if r['within_tolerance'] else '**no**'} | {r['groups_within']} of {r['groups']} "
                         f"({_fmt(r['group_low'])}-{_fmt(r['group_high'])}) | {sse} |")
        lines += ["", "![each measured cell's five-run groups against the measurement](seeds.png)", ""]
    effects = v.effects
    if effects:
        lines += ["## What a payload and the side cost (Chapter 6 T1, against 0 g flat)", "",
                  "Each cell's RMSE over the same controller's 0 g horizontal RMSE, measured and on the twin's runs "
                  f"of seeds {v.seeds[0]['seeds']}, ± standard errors (the thesis's std / sqrt 5 for each measured "
                  "mean, the twin's std / sqrt of its runs; the two means of a ratio taken as independent, which "
                  "the twin's are not quite: its cells share their noise seeds). `difference` is twin minus measured "
                  "in combined standard errors (a normal approximation; the measured errors rest on five runs, and "
                  "a controller's cells share its 0 g flat cell, so they are not independent findings). "
                  f"A cell within {RMSE_TOLERANCE * 100:.0f} % of its "
                  "level need not show the payload's cost the rig showed; this table asks that.", "",
                  "| controller | payload | orientation | measured | twin | difference |", "|---|---|---|---|---|---|"]
        for r in effects:
            lines.append(f"| {CONTROLLER_LABELS[r['controller']]} | {r['payload_g']:g} g | {r['orientation']} | "
                         f"x{r['measured_effect']:.2f} ± {r['measured_se']:.2f} | x{r['twin_effect']:.2f} ± "
                         f"{r['twin_se']:.2f} | {r['difference_in_se']:+.1f} |")
        lines += ["", "![what a payload and the side cost, measured and on the twin](effects.png)", ""]
    valve = groups.get("4.4.3 valve test", [])
    lines += ["## The valve test (§4.4.3) and the delays", "",
              "The physical solenoid valve, alone, in the replica of the thesis's rig. Its parameters were fitted "
              "to the rows from 35 % and to the two delays, with no lift from a 25 % pulse (`python -m "
              "twin.experiments.valve_fit`): within here says that the fit reached what it aimed at, not that the "
              "valve predicts it. The 30 % row is the one duty the fit did not aim at.", "",
              "| what | eq. 4.4.2 / thesis | twin | ratio | within |", "|---|---|---|---|---|"]
    for r in valve:
        lines.append(f"| {r['source'].replace('4.4.3 valve test, ', '')} | {_fmt(r['measured'], '.4g')} | "
                     f"{_fmt(r['twin_mean'], '.4g')} | {_fmt(r['ratio'])} | {'yes' if r['within_tolerance'] else '**no**'} |")
    lag = groups.get("4.6 open-loop mean lag at reversals", [])
    if lag:
        r = lag[0]
        lines += ["", "## Open-loop lag (§4.6)", "",
                  "The thesis found the real joint lagging its model at each reversal of the open-loop sine, "
                  "because the chamber pressures take time to build; it gives no number. The twin's mean lag at the "
                  f"reversals: thesis model (`thesis-deadzone`) {_fmt(r['measured'], '.0f')} ms, as-built "
                  f"{_fmt(r['twin_mean'], '.0f')} ms: the as-built twin "
                  + ("lags the model, as the real joint did." if r["within_tolerance"] else
                     "does **not** lag the model, unlike the real joint."), ""]
    if v.full_duty:
        low, high = (f"{x * 1e3:g}" for x in FULL_DUTY_WINDOW)
        (p_low, s_low, _), (p_high, s_high, _) = THESIS_FULL_DUTY_SPEEDS
        low_end = (s_low - FULL_DUTY_SPEED_DIGIT / 2) * 1e3
        lines += ["## Full-duty rack speed (§4.5.1; a check)", "",
                  "The force-loss runs started the joint from rest with both valves of the pair at 100 % duty, both "
                  f"ways, at supply pressures from {p_low / 1e3:g} to {p_high / 1e3:g} kPa; the rack ran at "
                  f"{s_low:g} to {s_high:g} m/s. The thesis gives only the range, each end to "
                  f"{FULL_DUTY_SPEED_DIGIT:g} m/s (so each stands for an interval that wide); that its slowest "
                  "end came at the lowest pressure and its fastest at the highest is inferred, and how the rig took "
                  "its speeds it does not say. So this is a check, not a verdict. The twin's run, sensor noise off: "
                  f"from T1's start, 100 % out for {FULL_DUTY_TURN:g} s, then 100 % back; the speed is the mean over "
                  f"the rack's travel from {low} to {high} mm each way (the twin's choice; CCW is towards 0 deg). "
                  "`as-built / measured` takes its slowest way at the low end, its fastest at the high end. Added "
                  "2026-11-26, after every other result of this report. Since the ninth refit (the same day) the slow "
                  "end also bounds the fit: the CCW Coulomb scale's top, "
                  f"{CCW_SCALE_BOUND:.3f}, is where the thesis's own model (eq. 4.3.6's steady state over the same "
                  f"window) runs CCW at {low_end:g} mm/s at {p_low / 1e3:g} kPa. The as-built joint, with its own "
                  "losses besides, is set against the measured range below.",
                  "",
                  "| supply (kPa) | measured (mm/s) | thesis model, CW / CCW | as-built, CW / CCW | "
                  "as-built / measured |", "|---|---|---|---|---|"]
        for r in v.full_duty:
            low_mm, high_mm = (x * 1e3 for x in r["interval"])
            lines.append(f"| {r['pressure'] / 1e3:g} | {r['measured'] * 1e3:g} ({r['end']}; {low_mm:g}-{high_mm:g}) | "
                         + " | ".join(" / ".join(_way_text(r["runs"][name], w) for w in (0, 1))
                                      for name in FULL_DUTY_PLANTS)
                         + f" | {_fmt(r['ratio'])} |")
        lines.append("")
    d = v.prediction_detail
    fixed = _fixed_text(d["members"])
    lines += ["## Prediction: Chapter 6 T3 (blind)", "",
              f"The held-back T3 cells, predicted on the committed preset (five runs) and on each of the "
              f"{len(d['members'])} members of the calibration ensemble (five runs each). The band is the 10-90 % "
              f"range of the members' five-run means ({_band_ends_text(len(d['members']))}, so "
              "the lowest and the highest member are listed beside it); `stalled` counts the members' runs whose "
              f"error passed {STALL_ERROR_DEG:g} deg (out of {d['runs']} per cell); "
              + "the members' table below gives each member's values." + (f" {fixed}" if fixed else "")
              + f" {_t3_as_run_text()}", "",
              "| controller | payload | orientation | committed | p10 | p50 | p90 | members (lowest-highest) | stalled |",
              "|---|---|---|---|---|---|---|---|---|"]
    for r, means in zip(v.prediction, member_means(d), strict=True):
        lines.append(f"| {CONTROLLER_LABELS[r['controller']]} | {r['payload_g']:g} g | {r['orientation']} | "
                     f"{_fmt(r['twin_mean'])} | {_fmt(r['band_p10'])} | {_fmt(r['band_p50'])} | {_fmt(r['band_p90'])} | "
                     f"{_fmt(float(means.min()))}-{_fmt(float(means.max()))} | {r['stalled_runs']} |")
    lines += ["", "![prediction](prediction.png)", ""] + _members_table(v)
    return "\n".join(lines)
