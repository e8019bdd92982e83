"""``twin run``: one scenario; its metrics, and optionally its trace, figure and 3D recording."""

from __future__ import annotations

import argparse
import json

from twin.cli.common import (
    add_scenario_arguments,
    all_or_nothing,
    compare_of,
    compare_settings,
    say_written,
    scenario_from,
)
from twin.exceptions import InvalidScenario
from twin.experiments import arguments
from twin.experiments.base import naming


def _cmd_run(args: argparse.Namespace) -> int:
    from twin.envs.runner import run, run_many
    from twin.sim import report

    if args.compare and not args.html:
        raise InvalidScenario("--compare records a second joint beside the first: use it with --html")
    if args.compare:  # the second joint only for the recording; the metrics and outputs are the first's
        compare = compare_of(args, args.compare)
        first = scenario_from(args)
        result, compared = run_many([first, compare.applied(first)])
    else:
        result, compared = run(scenario_from(args)), None
    outputs = [path for path in (args.trace, args.plot, args.html) if path is not None]
    with all_or_nothing(outputs) as temporary:  # every output, or none (a failed one leaves no other)
        staged = dict(zip(outputs, temporary, strict=True))
        if args.trace:
            with naming(staged[args.trace]):
                report.write_trace(result, staged[args.trace])
        if args.plot:
            from viz.plots import plot_run

            with naming(staged[args.plot]):
                plot_run(result, staged[args.plot])
        if args.html:
            from viz.recording import write_recording

            with naming(staged[args.html]):
                write_recording(result, staged[args.html], compare=compared,
                                compare_text=None if compared is None else args.compare)
    say_written(outputs)
    record = report.summary(result)
    if args.json:
        print(json.dumps(record))
    else:
        sse = "none (ends moving)" if record["sse_deg"] is None else f"{record['sse_deg']:.3f} deg"
        print(f"RMSE {record['rmse_deg']:.3f} deg  SSE {sse}  "
              f"max |e| {record['max_error_deg']:.3f} deg  ({record['duration_s']:.2f} s simulated)")
        for warning in record["warnings"]:
            print(f"warning: {warning}")
    return 1 if result.warnings else 0


def add_parser(sub) -> None:
    run = sub.add_parser("run", help="simulate one scenario")
    add_scenario_arguments(run)
    run.add_argument("--trace", type=arguments.writable_file(".csv"), metavar="FILE.csv", help="write the time series")
    run.add_argument("--plot", type=arguments.writable_file(".png"), metavar="FILE.png", help="write a figure")
    run.add_argument("--json", action="store_true", help="print exactly one JSON object")
    run.add_argument("--html", type=arguments.writable_file(".html"), metavar="FILE.html",
                     help="write a self-contained 3D recording with its traces")
    run.add_argument("--compare", type=compare_settings, default=None, metavar="KEY=VALUE[,KEY=VALUE]",
                     help="with --html: record a second joint beside the first, these scenario flags changed "
                          "(as twin view --compare); the metrics printed are the first's")
    run.set_defaults(func=_cmd_run)
