"""``twin demo``: the thesis's simulated controller comparison, reproduced."""

from __future__ import annotations

import argparse
import pathlib

from twin.cli.common import check_out_folder, output_folder
from twin.experiments import arguments


def _cmd_demo(args: argparse.Namespace) -> int:
    from twin.experiments.demo import file_names, run_demo

    check_out_folder(args.out, "demo", file_names(args.seeds, args.plots))  # now, not once the runs are done
    with output_folder(args.out):  # one writer; a folder made here goes again if the demo is stopped
        return run_demo(out=args.out, seeds=args.seeds, plots=args.plots)


def add_parser(sub) -> None:
    demo = sub.add_parser("demo", help="reproduce the thesis's simulated controller comparison")
    demo.add_argument("--out", type=arguments.out_dir, default=pathlib.Path("twin-demo"),
                      help="output folder (created; default ./twin-demo)")
    demo.add_argument("--seeds", type=arguments.seed_count, default=5, help="noise seeds per case (default 5)")
    demo.add_argument("--plots", action=argparse.BooleanOptionalAction, default=True)
    demo.set_defaults(func=_cmd_demo)
