"""Trial (not installed): the calibration refitted with T1, T2 and T4 started elsewhere, and the T3 prediction on it.

The thesis does not say where T1, T2 and T4 start. The twin starts them at 30 deg (``twin/physics/trajectories.py``:
inside the Coulomb fit's 24-174 deg, SPEC §4), and the calibration fits the measured cells run from there. On a
joint turned on its side the start decides where the payload's weight acts during the move and the hold, so the
vertical T1 cells, which pin how much margin the joint has to lift 13.5 g, read differently from another start.
Run without ``--start``, this script shows how much, on the committed preset with nothing refitted (the tenth
refit's, committed when it ran: ``twin/plants/data/tenth_refit.json``, digest 1c2dcd8c9f7f, so a later refit does
not move what it prints): the six vertical T1 cells (FF + PVA and sliding mode, 0, 6.5 and 13.5 g) from each start
of UNFITTED_STARTS_DEG, seeds 0-4, against the measured means (about 20 s). T3 does not read this start (it starts
at 80 deg), so the T3 cells do not depend on it directly; they may through the fit. This script measured that on
2026-11-27: it set the start (``trajectories.START``, before the fit's workers fork, so they inherit it) and ran the
calibration exactly as ``twin calibrate`` did then (file version 8: the same box, seeds, budgets, profiles and
second start), then the T3 prediction's twelve cells on every member of the refitted ensemble, seeds 0-4, as
``twin validate`` runs them. Starts tried: 20 deg (T3's own lowest angle: the rig may have run T1 over T3's 20-140
deg, where the thesis's Hall sensor is linear, §5; for the twin it is below the Coulomb fit, which is clamped there,
and where its model of the sensor's calibration errs most), 25 deg and 40 deg, then 22 deg (after seeing the others).
Those files are ``examples/trial_start_refit/start_*.json``.

On 2026-11-28 (stop 44) it fitted again from the same four starts with ``twin calibrate`` as the eleventh refit made
it (file version 9: the chambers' start pressure fitted too, six earlier fits as further starts; ``--out``), to see
whether the start still moves the prediction once the start pressure is fitted:
``examples/trial_start_refit/eleventh_start_*.json``, each fit 306-330 s on 2 cores, alone. ``--from-committed``
prints its best's cost on the further seed sets (10-39) from its own start, then runs each member of such a file
from the committed start (30 deg) against the eleventh refit's cut (its cost
plus its noise; the twelfth's is the same) and, for a member under it, prints its cost on the further seed sets and its 13.5 g vertical T3
cells: whether the eleventh refit's ensemble left out a set that fits as well from the committed start (one did; the
twelfth refit takes the ten sets under the cut as further starts: ``twin/plants/data/start_angle_refits.json``).

It prints the fitted values, the cost and its noise, the members, the measured cells within 20 % on seeds 0-4,
and each T3 cell's value on the best, its band and the members' range, the stalled runs, and per member which
law leads in each cell. ``--out DIR`` fits now (``twin calibrate``'s code as it is) and writes the calibration file
there as ``versionN_start_DEG.json`` (N: that code's file version; the kept ``eleventh_start_*`` files are version 9),
refusing a file of that name already there; ``--calibration FILE`` reports a file written before without fitting again (under a minute), with the start it
was fitted at (checked by its ``code_version``, which hashes the trajectories as they ran), and first runs the
measured cells again on its best values to show they give the file's table from that start. Nothing is installed,
and the T3 cells' measurements were not seen. The results are recorded in docs/prediction.md and
docs/investigations.md; a slow test in tests/experiments/test_trials_refits.py holds the printed numbers of the kept
files (CI runs the eleventh code's file from 25 deg again, all four with pytest's ``--every-kept-row``:
docs/testing.md).

    python examples/trial_start_refit.py
    python examples/trial_start_refit.py --start DEG --calibration FILE [--from-committed] [--workers N]
    python examples/trial_start_refit.py --start DEG --out DIR [--from-committed] [--workers N]
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import pathlib
import sys

import numpy as np

from twin.batch.sweep import code_version
from twin.envs.runner import run_many
from twin.experiments import calibrate
from twin.experiments.reference import THESIS_ROBUSTNESS_T1_DEG
from twin.experiments.validate import (
    PREDICTION_CELLS,
    SEEDS,
    lead_counts,
    member_means,
    prediction_rows,
    rmse_within,
)
from twin.physics import trajectories
from twin.physics.model import Orientation
from twin.plants.as_built import (
    ELEVENTH_REFIT_FILE,
    TENTH_REFIT_FILE,
    as_built_plant,
    calibrated_values,
    calibration_cost_line,
    preset_digest,
)
from twin.sim.scenario import Scenario

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))  # the sibling modules, however this one is loaded
import kept_profiles  # noqa: E402

COMMITTED_START_DEG = 30.0
UNFITTED_STARTS_DEG = (20.0, 24.0, 30.0, 40.0, 50.0, 54.0)  # 54 + 120 = 174 deg, the Coulomb fit's top


@contextlib.contextmanager
def started_at(degrees: float):
    """T1, T2 and T4 start at ``degrees`` inside the block (and in every process forked in it); after it, where
    they did."""
    committed = trajectories.START
    trajectories.START = math.radians(degrees)
    try:
        yield
    finally:
        trajectories.START = committed


def params_hash(version: str) -> str:
    """The presets', trajectories' and model's hash in a ``code_version`` string (not the package versions,
    which a fresh install may move)."""
    return version.rsplit("params ", 1)[-1]


def unfitted() -> None:
    """The committed (tenth refit's) preset's six vertical T1 cells from each start of :data:`UNFITTED_STARTS_DEG`,
    seeds 0-4."""
    plant = as_built_plant(calibrated_values(TENTH_REFIT_FILE))  # named "as-built", as the preset it ran on
    cells = [(law, grams) for law in ("ffpva", "smc") for grams in (0.0, 6.5, 13.5)]
    rig = " / ".join(f"{THESIS_ROBUSTNESS_T1_DEG[law, 'vertical'][g][0]:.2f}" for law, g in cells)
    print(f"T1 vertical, committed preset, nothing refitted, seeds 0-4: mean RMSE (deg) FF + PVA 0 / 6.5 / 13.5 g, "
          f"then sliding mode; the rig {rig}")
    for start in UNFITTED_STARTS_DEG:
        with started_at(start):
            runs = run_many([Scenario(law, 1, payload=g * 1e-3, orientation=Orientation.VERTICAL, plant=plant,
                                      seed=s) for law, g in cells for s in SEEDS])
        means = [np.mean([math.degrees(r.metrics.rmse) for r in runs[i:i + len(SEEDS)]])
                 for i in range(0, len(runs), len(SEEDS))]
        print(f"from {start:g} deg: " + " / ".join(f"{m:.2f}" for m in means), flush=True)


def recomputed(data: dict, workers: int) -> None:
    """Run the measured cells again on ``data``'s best values and check seeds, at the start in force, and print
    whether they give the file's residual table: the check that the start reaches the evaluator's forked workers
    (the T3 cells do not read it)."""
    with calibrate.Evaluator(seeds=data["check_seeds"], workers=workers) as evaluator:
        rows = calibrate.cell_rows(evaluator.cells(data["fitted"]))
    within = sum(bool(rmse_within(r["twin_rmse_deg"], r["experiment_rmse_deg"])) for r in rows)
    same = [r["twin_rmse_deg"] for r in rows] == [r["twin_rmse_deg"] for r in data["residuals_check_seeds"]]
    print(f"the measured cells run again from this start: {within} of {len(rows)} within 20 %, each mean as the file's: "
          f"{same}")


def report(data: dict, workers: int) -> None:
    """Print the calibration file ``data``'s fit and members, then run and print the T3 cells on every member."""
    print("fitted: " + ", ".join(f"{k} {v:.4g}" for k, v in data["fitted"].items()))
    noise = data["noise"]
    print(f"cost {data['cost']:.4f}, noise {noise['std']:.4f}; {data['evaluations']} evaluations; "
          f"{len(data['ensemble'])} members")
    checked = data["residuals_check_seeds"]
    within = sum(rmse_within(r["twin_rmse_deg"], r["experiment_rmse_deg"]) for r in checked)
    print(f"measured cells within 20 % on seeds {data['check_seeds'][0]}-{data['check_seeds'][-1]} (best): "
          f"{within} of {len(checked)}")
    with calibrate.Evaluator(seeds=SEEDS, workers=workers) as evaluator:
        per_member = [evaluator.cells(m["values"], keys=PREDICTION_CELLS) for m in data["ensemble"]]
    rows = prediction_rows(per_member, per_member[0])  # the best is the first member
    means = member_means({"per_member": [[c.mean_rmse for c in m] for m in per_member]})  # (cells, members)
    print("T3 (mean RMSE deg, seeds 0-4): cell, best, band p10-p90, members lowest-highest, stalled runs")
    for r, cell in zip(rows, means, strict=True):
        print(f"  {r['controller']:6} {r['payload_g']:4g} g {r['orientation']:10} {r['twin_mean']:.2f}  "
              f"{r['band_p10']:.2f}-{r['band_p90']:.2f}  {cell.min():.2f}-{cell.max():.2f}  {r['stalled_runs']}")
    cells = [(g, o) for c, _, g, o in PREDICTION_CELLS if c == "ffpva"]
    leads = []
    for m in per_member:
        mean = {(c.controller, c.payload_g, c.orientation): c.mean_rmse for c in m}
        leads.append("".join("S" if mean["smc", g, o] < mean["ffpva", g, o] else "F" for g, o in cells))
    print("which law leads, per member (H 0 / 6.5 / 13.5 g, V 0 / 6.5 / 13.5 g; S sliding mode, F FF + PVA): "
          + " ".join(leads))


def further_costs(evaluator: calibrate.Evaluator, values: dict[str, float]) -> list[float]:
    """The cost of ``values`` on each further seed set (calibrate's NOISE_SEED_SETS), at the start in force."""
    return [calibrate.cost(evaluator.cells(values, seeds=s)) for s in calibrate.NOISE_SEED_SETS]


def own_further(data: dict, workers: int) -> None:
    """The calibration ``data``'s best values on the further seed sets, at the start in force (its own): the costs
    to set beside the committed preset's on the same seeds, which no fit's search saw."""
    with calibrate.Evaluator(seeds=calibrate.FIT_SEEDS, workers=workers) as evaluator:
        costs = further_costs(evaluator, data["fitted"])
    print("its best on seeds 10-19 / 20-29 / 30-39, from this start: " + " / ".join(f"{c:.3f}" for c in costs))


def from_committed(data: dict, workers: int) -> None:
    """Run every member of the calibration ``data`` (fitted from another start) from the committed start, on the fit
    seeds, against the eleventh refit's cut (its cost plus its noise: the rule that admits a member). For each
    member under the cut: its cost on the further seed sets beside the eleventh refit's best, and its 13.5 g
    vertical T3 cells (seeds 0-4; T3 starts at 80 deg whatever T1's start) and which law leads in how many cells.
    Call it with T1, T2 and T4 at the committed start. It reads the eleventh refit's kept file (digest 78c00bbdf7e4,
    printed), the committed preset when it first ran; the twelfth refit has the same best, noise and cut."""
    best, noise = calibration_cost_line(ELEVENTH_REFIT_FILE)
    committed = calibrated_values(ELEVENTH_REFIT_FILE)
    print(f"its members from {COMMITTED_START_DEG:g} deg, fit seeds, against the eleventh refit's cut {best + noise:.4f} "
          f"(cost {best:.4f} + noise {noise:.4f}; preset {preset_digest(ELEVENTH_REFIT_FILE)}):")
    rows = kept_profiles.t3_rows()
    with calibrate.Evaluator(seeds=calibrate.FIT_SEEDS, workers=workers) as evaluator:
        further = None
        for index, member in enumerate(data["ensemble"]):
            cost = calibrate.cost(evaluator.cells(member["values"]))
            if cost > best + noise:
                print(f"  member {index}: cost {cost:.4f}")
                continue
            if further is None:  # the eleventh refit's best on the further seed sets, once
                further = further_costs(evaluator, committed)
            own = further_costs(evaluator, member["values"])
            means = [c.mean_rmse for c in evaluator.cells(member["values"], keys=PREDICTION_CELLS, seeds=SEEDS)]
            t3 = {(r["controller"], r["payload_g"], r["orientation"]): m for r, m in zip(rows, means, strict=True)}
            ahead = lead_counts(rows, means)[0].get("smc", 0)  # validate's rule: a tie counts for neither
            print(f"  member {index}: cost {cost:.4f}, under the cut; seeds 10-19 / 20-29 / 30-39 "
                  + " / ".join(f"{c:.3f}" for c in own) + " (the eleventh refit's best " + " / ".join(f"{c:.3f}" for c in further)
                  + f"); T3 13.5 g vertical {t3['ffpva', 13.5, 'vertical']:.2f} / {t3['smc', 13.5, 'vertical']:.2f} "
                  f"(FF + PVA / sliding mode), sliding mode ahead in {ahead} of 6 cells; "
                  + ", ".join(f"{k} {v:.4g}" for k, v in member["values"].items()), flush=True)


def checked_file(parser: argparse.ArgumentParser, path: pathlib.Path, setting: str) -> dict:
    """The calibration file ``path``, refused (a parser error) unless its ``code_version`` shows it was fitted with
    the presets, trajectories and MJCF in force (inside the block that sets the trial's condition, ``setting``)."""
    data = json.loads(path.read_text())
    if params_hash(data["code_version"]) != params_hash(code_version(plants=calibrate.fit_presets(data["fitted"]))):
        parser.error(f"{path} was not fitted {setting} with these presets, trajectories and MJCF "
                     "(they hash to another value)")
    return data


def read(parser: argparse.ArgumentParser, path: pathlib.Path, setting: str, workers: int) -> dict:
    """Inside the block that sets a trial's condition (``setting``, as "from 20 deg"): the kept file ``path``, once its
    ``code_version`` shows it was fitted so and its measured cells run again (:func:`recomputed`)."""
    data = checked_file(parser, path, setting)
    recomputed(data, workers)
    return data


def refit_arguments(doc: str, flag: str, help: str, folder: str, argv: list[str] | None,
                    extra=None, fits: bool = False) -> tuple[argparse.ArgumentParser, argparse.Namespace]:
    """A refit trial's command line: ``--FLAG`` (a number: the trial's condition; none: its unrefitted table),
    ``--calibration`` (a file written before in ``folder``, at the same condition), ``--out`` when the trial
    ``fits`` (a fit now, on ``twin calibrate`` as it is) and ``--workers``; ``extra(parser)`` adds a trial's own."""
    parser = argparse.ArgumentParser(description=doc.splitlines()[0])
    parser.add_argument(f"--{flag}", type=float, help=help)
    parser.add_argument("--calibration", type=pathlib.Path, help="report a trial calibration file written before at "
                        f"the same {flag} ({folder})" + ("" if fits else f"; needed with --{flag}: the trial no "
                                                         "longer fits"))
    if fits:
        parser.add_argument("--out", type=pathlib.Path, metavar="DIR", help=f"fit at --{flag} on twin calibrate as "
                            "it is now, write the file into DIR (created), then report it")
    parser.add_argument("--workers", type=int, default=2)
    if extra is not None:
        extra(parser)
    args = parser.parse_args(argv)
    out = getattr(args, "out", None)
    if getattr(args, flag) is None and (args.calibration or out):
        parser.error(f"--{'calibration' if args.calibration else 'out'} needs --{flag}")
    if args.calibration and out:
        parser.error("--calibration reports a file written before and --out fits a new one: give one of them")
    if getattr(args, flag) is not None and not (args.calibration or out):
        if fits:
            parser.error(f"--{flag} needs --out DIR (a fit now, about 6 min on 2 cores) or --calibration FILE")
        parser.error("the trial's fits ran on twin calibrate as it was before the start pressure was fitted (commit "
                     "3e13ceb); a fit now would be another trial: report a kept file with --calibration")
    return parser, args


def fitted_here(out: pathlib.Path, name: str, workers: int) -> dict:
    """A fit now, with ``twin calibrate``'s code as it is, written to ``out/name`` (whole or not at all) and
    returned; progress on stderr as ``twin calibrate`` prints it."""
    def progress(done: int, total: int, stage: str, cost: float, values: dict) -> None:
        print(f"[{done}/{total}] {stage:7} cost {cost:.4f}", file=sys.stderr, flush=True)

    out.mkdir(parents=True, exist_ok=True)
    data = calibrate.record(calibrate.calibrate(workers=workers, progress=progress))
    print(f"wrote {calibrate.write(data, out, name)} (file version {data['version']}, {data['wall_time_s']:.0f} s)")
    return data


def main(argv: list[str] | None = None) -> None:
    def committed_flag(parser: argparse.ArgumentParser) -> None:
        parser.add_argument("--from-committed", action="store_true", help="then run the file's members from the "
                            f"committed start ({COMMITTED_START_DEG:g} deg) against the eleventh refit's cut")

    parser, args = refit_arguments(__doc__, "start", "where T1, T2 and T4 start, deg (none: the unrefitted table)",
                                   "examples/trial_start_refit/", argv, extra=committed_flag, fits=True)
    if args.from_committed and args.start is None:
        parser.error("--from-committed needs --start and a fit (--out or --calibration)")
    if args.start is not None and not 0.0 <= args.start <= UNFITTED_STARTS_DEG[-1]:
        parser.error(f"--start {args.start:g}: T1, T2 and T4 must start within 0-{UNFITTED_STARTS_DEG[-1]:g} deg (their "
                     "+120 deg must end inside the Coulomb fit, 174 deg at most)")
    if args.start is None:
        unfitted()
        return
    name = f"version{calibrate.FILE_VERSION}_start_{args.start:g}.json"  # the kept files, version 9: eleventh_start_*
    if args.out and (args.out / name).exists():
        parser.error(f"{args.out / name} is there already: a fit would replace it; give another --out")
    print(f"T1, T2 and T4 from {args.start:g} deg (committed: {COMMITTED_START_DEG:g})")
    with started_at(args.start):
        if args.out:
            data = fitted_here(args.out, name, args.workers)
        else:
            data = read(parser, args.calibration, f"from {args.start:g} deg", args.workers)
        report(data, args.workers)
        if args.from_committed:
            own_further(data, args.workers)
    if args.from_committed:  # T1, T2 and T4 back at the committed start: the Evaluator's workers fork with it
        from_committed(data, args.workers)


if __name__ == "__main__":
    main()
