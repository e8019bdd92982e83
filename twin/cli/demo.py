"""``twin demo``: the thesis's simulated controller comparison, reproduced."""

from __future__ import annotations

import argparse
import pathlib

from twin.cli.common import output_folder, refuse_another_commands_folder
from twin.experiments import arguments
from twin.experiments.base import refuse_folders_in_the_way


def _cmd_demo(args: argparse.Namespace) -> int:
    from twin.experiments.demo import OUTPUTS, run_demo

    refuse_folders_in_the_way(args.out, OUTPUTS)  # now, not once the runs are done
    refuse_another_commands_folder(args.out, "demo")
    with output_folder(args.out):  # one writer; a folder made here goes again if the demo is stopped
        return run_demo(out=args.out, seeds=args.seeds, plots=args.plots)


def add_parser(sub) -> None:
    demo = sub.add_parser("demo", help="reproduce the thesis's simulated controller comparison")
    demo.add_argument("--out", type=arguments.out_dir, default=pathlib.Path("twin-demo"),
                      help="output folder (created; default ./twin-demo)")
    demo.add_argument("--seeds", type=arguments.seed_count, default=5, help="noise seeds per case (default 5)")
    demo.add_argument("--plots", action=argparse.BooleanOptionalAction, default=True)
    demo.set_defaults(func=_cmd_demo)
