"""``twin whatif air``: the blind T3 prediction against the free air in the chambers.

``twin calibrate`` holds the chambers' free air (``air_fraction``) in a box (0-8 % of the chamber volume since the
tenth refit; 0-3 % before, a judgement of visibly bubbly water), and since the tenth refit profiles it about the
best, so the ensemble's members span some air (docs/as-built.md). A profile moves one parameter about the best
on a few points; this what-if runs the committed preset with the air moved to any values, nothing else
refitted, and gives for each value:

* the fit's cost on its own seeds (:data:`twin.experiments.calibrate.FIT_SEEDS`) beside the line the
  calibration drew its ensemble with (the best cost plus its seed-to-seed noise, read from the calibration
  file): under the line, the value fits the measurements about as well as the fitted one by the calibration's
  own rule, inside the box or not;
* the twelve T3 cells (FF + PVA and sliding mode; 0, 6.5 and 13.5 g; horizontal and vertical), mean RMSE over
  seeds 0..N-1 (``twin validate``'s prediction runs 0-4), and which law leads in each.

It answers a question; it changes nothing: every other command runs the committed preset.
"""

from __future__ import annotations

import argparse
import math
import pathlib
from collections.abc import Sequence

from twin.exceptions import InvalidScenario
from twin.experiments import calibrate
from twin.experiments.arguments import seed_count
from twin.experiments.base import Experiment, Outcome
from twin.experiments.whatifs.common import number_list, progress_bar, refuse_oversized
from twin.physics.params import AIR_FRACTION_MAX
from twin.sim.metrics import spread
from viz.figures import finish_panels, plt

COLUMNS = ("air_pct", "committed", "inside_box", "fit_cost", "cost_line", "under_line", "controller", "trajectory",
           "payload_g", "orientation", "rmse_mean_deg", "rmse_std_deg")
DEFAULT_AIR_PCT = (1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 8.0)
AIR_LIMIT_PCT = AIR_FRACTION_MAX * 100  # what the chamber model takes, in %
MAX_VALUES = 50  # air values given in one run, the committed one added besides (each costs the fit's 210 runs)
LAWS = ("ffpva", "smc")


def parse_air(text: str) -> tuple[float, ...]:
    """``--air``: free air in % of the chamber volume, comma-separated, each from 0 to the chamber model's
    limit; the committed value is always run besides."""
    values = number_list(text, "--air", "percentages")
    if not all(math.isfinite(v) and 0 <= v <= AIR_LIMIT_PCT for v in values):
        raise InvalidScenario(f"--air: each value must be 0-{AIR_LIMIT_PCT:g} % of the chamber volume, got {text!r}")
    if len(values) > MAX_VALUES:
        raise InvalidScenario(f"--air: at most {MAX_VALUES} values in one run (the committed one is added besides), "
                              f"got {len(values)}")
    return tuple(values)  # number_list sorts them


def _cell(r: dict) -> tuple:
    return r["payload_g"], r["orientation"]


def _pct(air: float) -> str:
    """An air value as the answer writes it: four significant digits, so the committed 2.826 % and a given 2.83
    read apart."""
    return f"{air:.4g}"


def _cell_label(cell: tuple) -> str:
    return f"{cell[0]:g} g {cell[1][0].upper()}"


def runs_per_value(seeds: int) -> int:
    """The runs of one air value: the fit's cells on its seeds, and the T3 cells on ``seeds`` seeds."""
    from twin.experiments.validate import PREDICTION_CELLS

    return len(calibrate.CELLS) * len(calibrate.FIT_SEEDS) + len(PREDICTION_CELLS) * seeds


def air_study(*, air_pct: Sequence[float], seeds: int = 5, workers: int = 2, bar=None) -> Outcome:
    """The committed preset with the air at each of ``air_pct`` (and at its own value): the fit's cost on
    its seeds and the T3 cells over seeds 0..``seeds``-1 (see the module docstring)."""
    from twin.experiments.validate import PREDICTION_CELLS
    from twin.plants.as_built import FITTED, calibrated_values, calibration_cost_line

    committed = calibrated_values()
    best, noise = calibration_cost_line()
    box = FITTED[calibrate.FITTED_INDEX["air_fraction"]]
    points = {x / 100: x for x in air_pct}  # fraction -> % as given
    points.setdefault(committed["air_fraction"], committed["air_fraction"] * 100)
    t3_seeds = tuple(range(seeds))
    per_value = runs_per_value(seeds)
    if bar is not None:
        bar.reset(total=len(points) * per_value)
    rows, failed = [], 0
    with calibrate.Evaluator(seeds=calibrate.FIT_SEEDS, workers=workers) as evaluator:
        for fraction in sorted(points):
            values = {**committed, "air_fraction": fraction}
            fit = evaluator.cells(values)
            fit_cost = calibrate.cost(fit)
            t3 = evaluator.cells(values, keys=PREDICTION_CELLS, seeds=t3_seeds)
            failed += sum(cell.failed for cell in (*fit, *t3))
            for cell in t3:
                s = spread(cell.rmse_deg)
                rows.append(dict(zip(COLUMNS, (points[fraction], fraction == committed["air_fraction"],
                                               box.low <= fraction <= box.high, fit_cost, best + noise,
                                               fit_cost <= best + noise, *cell.key, s.mean, s.std), strict=True)))
            if bar is not None:
                bar.update(per_value)
    detail = {"seeds": seeds, "best": best, "noise": noise, "box_pct": (box.low * 100, box.high * 100)}
    return Outcome(rows, answer(rows, **detail), failed=failed, detail=detail)


def leads(rows: Sequence[dict], seeds: int) -> dict[float, dict[tuple, tuple[float, float]]]:
    """{air %: {(payload g, orientation): (FF + PVA's RMSE minus sliding mode's, its standard error over
    ``seeds`` runs each)}}: above zero, sliding mode leads."""
    by = {(r["air_pct"], r["controller"], *_cell(r)): r for r in rows}
    out: dict[float, dict[tuple, tuple[float, float]]] = {}
    for r in rows:
        if r["controller"] == LAWS[0]:
            other = by[(r["air_pct"], LAWS[1], *_cell(r))]
            se = math.sqrt((r["rmse_std_deg"] ** 2 + other["rmse_std_deg"] ** 2) / seeds)
            out.setdefault(r["air_pct"], {})[_cell(r)] = (r["rmse_mean_deg"] - other["rmse_mean_deg"], se)
    return out


def _span(values: Sequence[float]) -> str:
    low, high = f"{min(values):.2f}", f"{max(values):.2f}"
    return low if low == high else f"{low}-{high}"


def _lead_text(margins: dict[tuple, tuple[float, float]]) -> str:
    parts = []
    for law, name in zip(LAWS, ("FF + PVA", "sliding mode"), strict=True):
        ahead = [(abs(m), se) for m, se in margins.values() if m != 0 and (m < 0) == (law == LAWS[0])]
        if ahead:
            clear = sum(m > 2 * se for m, se in ahead)
            parts.append(f"{name} leads in {len(ahead)} of {len(margins)} (by {_span([m for m, _ in ahead])} deg"
                         + (f", {clear} by more than two standard errors)" if any(se for _, se in ahead) else ")"))
    return "; ".join(parts) or f"the laws tie in all {len(margins)}"


def _majority(margins: dict[tuple, tuple[float, float]]) -> str | None:
    """The law ahead in more than half the cells, or None."""
    smc = sum(m > 0 for m, _ in margins.values())
    ffpva = sum(m < 0 for m, _ in margins.values())
    half = len(margins) / 2
    return LAWS[1] if smc > half else LAWS[0] if ffpva > half else None


def answer(rows: Sequence[dict], *, seeds: int, best: float, noise: float, box_pct: tuple[float, float]) -> str:
    """The short answer: per air value its cost against the line and which law leads on T3; then whether
    the lead turns on the air among the values under the line."""
    margins = leads(rows, seeds)
    first = {r["air_pct"]: r for r in rows}  # each value's shared fields
    runs = "seed 0" if seeds == 1 else f"seeds 0-{seeds - 1}"
    lines = [f"The committed as-built preset with the chambers' free air moved, nothing else refitted. The fit's box "
             f"is {box_pct[0]:g}-{box_pct[1]:g} % (a judgement, not a measurement). The fit's cost on its own seeds "
             f"against the calibration's ensemble line {best + noise:.3f} (best {best:.3f} + seed-to-seed noise "
             f"{noise:.3f}); T3 RMSE in deg over {runs}, FF + PVA / sliding mode."]
    for air, margin in margins.items():
        r = first[air]
        where = ("the committed value" if r["committed"] else "inside the box" if r["inside_box"]
                 else "outside the box")
        cells = {(c["controller"], *_cell(c)): c["rmse_mean_deg"] for c in rows if c["air_pct"] == air}
        lines.append(f"air {_pct(air)} % ({where}): cost {r['fit_cost']:.3f}, "
                     f"{'under' if r['under_line'] else 'over'} the line; {_lead_text(margin)}. "
                     + ", ".join(f"{_cell_label(k)} {cells[(LAWS[0], *k)]:.2f} / {cells[(LAWS[1], *k)]:.2f}"
                                 for k in margin))
    under = [air for air in margins if first[air]["under_line"]]
    majorities = {air: _majority(margins[air]) for air in under}
    named = {LAWS[0]: "FF + PVA", LAWS[1]: "sliding mode", None: "neither law"}
    groups = {law: [air for air in under if majorities[air] == law] for law in dict.fromkeys(majorities.values())}
    said = "; ".join(f"{named[law]} at {', '.join(_pct(a) for a in airs)} %" for law, airs in groups.items())
    leaders = [law for law in groups if law is not None]
    if not under:
        verdict = "No air value run is under the line, the committed one included: the line cannot be read here."
    elif len(leaders) == 2:
        verdict = (f"Under the line, ahead in most T3 cells: {said}. Which law leads on T3 turns on the air, which "
                   "the measurements do not pin down.")
    elif leaders:
        verdict = (f"Under the line, ahead in most T3 cells: {said}. The other law leads at none of these values: "
                   "which law leads does not turn on the air, as far as they show.")
    else:
        verdict = "Under the line, neither law leads in most T3 cells at any value run."
    lines.append(f"{verdict} The line is the calibration's rule on its own {len(calibrate.FIT_SEEDS)} seeds; on other "
                 f"seed sets a cost moves by about the noise ({noise:.3f}), so a value near the line may fall on "
                 "either side of it. A what-if, not a fit: every other command runs the committed preset.")
    return "\n".join(lines)


def plot_air(rows: Sequence[dict], path: pathlib.Path, *, seeds: int, best: float, noise: float,
             box_pct: tuple[float, float]) -> None:
    """Left: the fit's cost against the air, with the ensemble's line and the box. Right: each T3 cell's FF +
    PVA minus sliding mode against the air (above zero, sliding mode leads); open marks over the line."""
    first = {r["air_pct"]: r for r in rows}
    air = sorted(first)
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.5), constrained_layout=True)
    left.plot(air, [first[a]["fit_cost"] for a in air], "o-", color="tab:blue", label="fit's cost, its seeds")
    committed = [a for a in air if first[a]["committed"]]
    left.plot(committed, [first[a]["fit_cost"] for a in committed], "*", ms=14, color="tab:blue",
              label="committed preset")
    left.axhline(best + noise, color="tab:green", ls="--", label="ensemble line (best + noise)")
    top = max(air[-1], box_pct[1]) * 1.05
    left.axvspan(box_pct[1], top, color="0.5", alpha=0.15, lw=0, label="outside the fit's box")
    left.set_xlim(min(air[0], box_pct[0]) - 0.2, top)
    left.set_xlabel("free air (% of chamber volume at 1 atm)")
    left.set_ylabel("cost")
    left.set_title("what the measurements allow (nothing else refitted)", fontsize=9)
    margins = leads(rows, seeds)
    cells = list(next(iter(margins.values())))
    for k, cell in enumerate(cells):
        colour = f"C{k}"
        ys = [margins[a][cell][0] for a in air]
        right.plot(air, ys, "-", color=colour, lw=1.0, label=_cell_label(cell))
        for a, y in zip(air, ys, strict=True):
            right.plot([a], [y], "o", color=colour, mfc=colour if first[a]["under_line"] else "none")
    right.axhline(0.0, color="0.3", lw=1.0)
    right.axvspan(box_pct[1], top, color="0.5", alpha=0.15, lw=0)
    right.set_xlim(left.get_xlim())
    right.set_xlabel("free air (% of chamber volume at 1 atm)")
    right.set_ylabel("FF + PVA minus sliding mode, T3 RMSE (deg)")
    right.set_title("above 0: sliding mode leads (open marks: over the line)", fontsize=9)
    finish_panels(fig, (left, right), path, legend_size=7)


class AirWhatIf(Experiment):
    name = "air"
    help = "the T3 prediction against the chambers' free air, with the fit's cost beside it (as-built)"

    def add_arguments(self, parser: argparse.ArgumentParser) -> None:
        parser.add_argument("--air", default=",".join(f"{a:g}" for a in DEFAULT_AIR_PCT), metavar="LIST",
                            help="free air in %% of the chamber volume (default 1,2,3,4,5,6,8; the committed "
                                 "value always runs)")
        parser.add_argument("--seeds", type=seed_count, default=5, help="noise seeds per T3 cell (default 5, as "
                                                                         "twin validate)")

    def check(self, args: argparse.Namespace) -> None:
        from twin.plants.as_built import calibrated_values, calibration_cost_line

        args.air_values = parse_air(args.air)
        calibration_cost_line()  # a calibration file with a cost and its noise, before anything is written
        committed = calibrated_values()["air_fraction"]
        if all(v / 100 == committed for v in args.air_values):  # as air_study tells values apart: nothing to compare
            raise InvalidScenario(f"--air: give a value other than the committed {_pct(committed * 100)} %, which is "
                                  f"always run, got {args.air!r}")
        refuse_oversized((len(args.air_values) + 1) * runs_per_value(args.seeds), "--air x --seeds")

    def run(self, args: argparse.Namespace, out: pathlib.Path) -> Outcome:
        with progress_bar(self.name) as bar:
            return air_study(air_pct=args.air_values, seeds=args.seeds, bar=bar)

    def plot(self, outcome: Outcome, path: pathlib.Path) -> None:
        plot_air(outcome.rows, path, **outcome.detail)


EXPERIMENT = AirWhatIf()
