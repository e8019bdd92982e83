"""``twin demo``: the thesis's simulated controller comparison, reproduced.

Runs PVA + DZC, FF + PVA and sliding mode on T1 - T4 on the ``thesis`` plant,
over several noise seeds, in one batch; prints RMSE, SSE and max error (mean
and std over seeds) beside the thesis's simulated values (SPEC §8), and writes
into the output folder: ``results.csv`` (one row per run), ``summary.md`` (the
table) and one PNG per run. They are written beside the folder's files first and
renamed into place one after another once all are written (so a stop or a full disk
while they are written leaves the folder as it was). In a folder an earlier demo
wrote (its ``summary.md`` says so), that run's PNGs that this run did not draw (fewer
seeds, ``--no-plots``) are removed: the folder shows one run. Elsewhere nothing but
this run's files is touched.
"""

from __future__ import annotations

import pathlib
import re
import sys

import numpy as np
from tqdm import tqdm

from twin.batch.tables import counted, signed, write_csv
from twin.envs.runner import run_many
from twin.experiments.base import staged, tell_undrawn
from twin.experiments.reference import (
    THESIS_SIMULATED_RMSE_DEG,
    THESIS_SIMULATED_SSE_T1_DEG,
    THESIS_SIMULATED_T4_REST_ERRORS_DEG,
)
from twin.sim import report
from twin.sim.metrics import spread
from twin.sim.scenario import CONTROLLER_LABELS, CONTROLLER_NAMES, TRAJECTORY_NUMBERS, Scenario
from twin.sim.simulation import Result


def demo_scenarios(seeds: int) -> list[Scenario]:
    return [Scenario(controller=c, trajectory=t, plant="thesis", seed=s)
            for c in CONTROLLER_NAMES for t in TRAJECTORY_NUMBERS for s in range(seeds)]


def summary_rows(results: list[Result]) -> list[dict]:
    """One row per controller x trajectory: mean and std over seeds, thesis value beside."""
    rows = []
    for c in CONTROLLER_NAMES:
        for t in TRAJECTORY_NUMBERS:
            records = [report.summary(r) for r in results
                       if r.scenario.controller == c and r.scenario.trajectory == t]
            rmse = spread([r["rmse_deg"] for r in records])
            sse = spread([np.nan if r["sse_deg"] is None else r["sse_deg"] for r in records])
            peak = spread([r["max_error_deg"] for r in records])
            thesis = THESIS_SIMULATED_RMSE_DEG.get(c, {}).get(t)
            rows.append({
                "controller": c, "trajectory": t, "runs": len(records),
                "rmse_mean": rmse.mean, "rmse_std": rmse.std,
                "sse_mean": sse.mean, "sse_min": sse.min, "sse_max": sse.max,
                "max_error_mean": peak.mean, "thesis_rmse": thesis,
                "thesis_sse": THESIS_SIMULATED_SSE_T1_DEG.get(c) if t == 1 else None,
                "warnings": sum(len(r["warnings"]) for r in records),
            })
    return rows


def _fmt(value, spec: str = ".2f") -> str:
    return "–" if value is None else format(value, spec)


def _sse(row: dict) -> str:
    if np.isnan(row["sse_mean"]):
        return "– (ends moving)"
    return f"{signed(row['sse_mean'])} [{signed(row['sse_min'])}, {signed(row['sse_max'])}]"


def rest_error_table(results: list[Result]) -> str:
    """T4's errors at the end of its four rests, seed mean, beside the thesis's simulated ones."""
    lines = ["| controller | T4 rest errors (deg), twin mean over seeds | thesis sim |", "|---|---|---|"]
    for c in CONTROLLER_NAMES:
        runs = [r for r in results if r.scenario.controller == c and r.scenario.trajectory == 4]
        if not runs:
            continue
        mean = np.degrees(np.mean([r.metrics.rest_errors for r in runs], axis=0))
        thesis = THESIS_SIMULATED_T4_REST_ERRORS_DEG.get(c)
        lines.append(f"| {CONTROLLER_LABELS[c]} | {', '.join(signed(e) for e in mean)} | "
                     f"{', '.join(f'{e:+.2f}' for e in thesis) if thesis else '–'} |")
    return "\n".join(lines)


def markdown_table(rows: list[dict]) -> str:
    lines = ["| controller | traj | RMSE (deg) mean ± std | thesis sim RMSE | diff | SSE mean [min, max] | thesis SSE | max \\|e\\| mean |",
             "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        diff = None if r["thesis_rmse"] is None else r["rmse_mean"] - r["thesis_rmse"]
        lines.append(
            f"| {CONTROLLER_LABELS[r['controller']]} | T{r['trajectory']} | {r['rmse_mean']:.2f} ± {r['rmse_std']:.2f} | "
            f"{_fmt(r['thesis_rmse'])} | {'–' if diff is None else signed(diff)} | {_sse(r)} | "
            f"{_fmt(r['thesis_sse'])} | {r['max_error_mean']:.2f} |")
    return "\n".join(lines)


RUN_FIGURE = re.compile(rf"({'|'.join(CONTROLLER_NAMES)})_T[1-4]_seed\d+\.png")  # the name of a run's PNG


SUMMARY_TITLE = "# Thesis controller comparison on the twin"  # summary.md's first words: a demo wrote the folder
OUTPUTS = ("results.csv", "summary.md")  # besides the figures


def figure_name(scenario: Scenario) -> str:
    """A run's PNG (:data:`RUN_FIGURE`)."""
    return f"{scenario.controller}_T{scenario.trajectory}_seed{scenario.seed}.png"


def file_names(seeds: int, plots: bool) -> list[str]:
    """Every file a demo of ``seeds`` seeds writes in its folder."""
    return [*OUTPUTS, *(figure_name(s) for s in demo_scenarios(seeds) if plots)]


def wrote_folder(out: pathlib.Path) -> bool:
    """A demo wrote ``out``: its ``summary.md`` begins with :data:`SUMMARY_TITLE` (an unreadable one is not
    taken for a demo's)."""
    try:
        with open(out / "summary.md", errors="replace") as handle:
            return handle.read(len(SUMMARY_TITLE)) == SUMMARY_TITLE
    except OSError:
        return False


def run_demo(*, out: pathlib.Path, seeds: int = 5, plots: bool = True) -> int:
    out.mkdir(parents=True, exist_ok=True)
    demo_folder = wrote_folder(out)
    scenarios = demo_scenarios(seeds)
    print(f"Simulating {len(scenarios)} runs on the 'thesis' plant; output in {out.resolve()}", file=sys.stderr)
    with tqdm(total=1, desc="simulating", unit="tick", file=sys.stderr, dynamic_ncols=True) as bar:
        def progress(done: int, total: int) -> None:
            bar.total = total
            bar.n = done
            bar.refresh()

        results = run_many(scenarios, progress=progress)

    rows = summary_rows(results)
    table = markdown_table(rows) + "\n\n" + rest_error_table(results)
    with staged(out, "demo") as stage:
        records = []  # the CSV rules of every table (true / false, 12 significant digits): write_csv's
        for result in results:
            record = report.summary(result)
            record["rest_errors_deg"] = ";".join(f"{e:.4f}" for e in record["rest_errors_deg"])
            records.append(record)
        write_csv(records, list(records[0]), stage.folder / "results.csv")
        (stage.folder / "summary.md").write_text(f"{SUMMARY_TITLE} ('thesis' plant, {counted(seeds, 'seed')})\n\n{table}\n")
        stage.names += list(OUTPUTS)
        if plots:
            from viz.plots import plot_run

            for result in tqdm(results, desc="plotting", unit="png", file=sys.stderr, dynamic_ncols=True):
                stage.figure(figure_name(result.scenario), lambda path, r=result: plot_run(r, path))
    for stale in out.iterdir() if demo_folder else ():  # an earlier demo's figures that this run did not draw
        if RUN_FIGURE.fullmatch(stale.name) and stale.name not in stage.names:
            stale.unlink(missing_ok=True)
    print(table)
    failed = [r for r in results if r.warnings]
    for r in failed:
        print(f"warning: {r.scenario}: {', '.join(r.warnings)}", file=sys.stderr)
    tell_undrawn(stage.undrawn)
    print(f"\nWrote {out / 'results.csv'}, {out / 'summary.md'}"
          + (f" and {len(stage.names) - 2} PNGs" if plots else ""))
    return 1 if failed or stage.undrawn else 0
