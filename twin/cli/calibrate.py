"""``twin calibrate``: fit the as-built plant to the thesis's measurements (SPEC §8, §9's T1 cells)."""

from __future__ import annotations

import argparse
import os
import pathlib
import sys

from twin.batch.tables import counted
from twin.cli.common import output_folder
from twin.exceptions import InvalidScenario
from twin.experiments import arguments
from twin.experiments.base import refuse_folders_in_the_way, staged, tell_undrawn

FIGURE = "calibration.png"


def _cmd_calibrate(args: argparse.Namespace) -> int:
    """Exit 0; 1 when the fit's figure could not be drawn (its file is written, and installed if asked)."""
    from twin.experiments import calibrate
    from twin.plants.as_built import CALIBRATION_FILE
    from viz.calibration_plots import plot_calibration

    preset = pathlib.Path(str(CALIBRATION_FILE))
    if args.install and not arguments.can_create_in(preset.parent):  # found out now, not after the fit
        raise InvalidScenario(f"--install: cannot write the as-built preset's folder {preset.parent}")

    def progress(done: int, total: int, stage: str, cost: float, values: dict) -> None:
        shown = ", ".join(f"{k} {v:.4g}" for k, v in values.items())
        print(f"[{done}/{total}] {stage:7} cost {cost:.4f}  {shown}", file=sys.stderr, flush=True)

    refuse_folders_in_the_way(args.out, [calibrate.FILE_NAME, FIGURE])  # now, not after the fit
    with output_folder(args.out) as folder:
        print(f"calibrate: {counted(calibrate.planned_evaluations(), 'evaluation')} at most, on "
              f"{counted(args.workers, 'worker')}; a line for each once the workers have started",
              file=sys.stderr, flush=True)  # the first line comes some seconds later: say it has begun
        result = calibrate.calibrate(workers=args.workers, progress=progress)
        data = calibrate.record(result)
        path = calibrate.write(data, args.out)
        folder.keep = True  # a finished fit stays, whatever happens after
        print(calibrate.format_residuals(data))
        print(f"wrote {path} ({result.evaluations} evaluations, {result.wall_time:.0f} s)")
        if args.install:
            calibrate.write(data, preset.parent, name=preset.name)  # whole or not at all (a rename)
            print(f"installed as the as-built preset: {preset}")
        with staged(args.out, "calibrate") as stage:  # drawn beside the folder's files, then renamed in
            stage.figure(FIGURE, lambda png: plot_calibration(data, png))
    for name in stage.names:
        print(f"wrote {args.out / name}")
    tell_undrawn(stage.undrawn)
    return 1 if stage.undrawn else 0


def add_parser(sub) -> None:
    cal = sub.add_parser("calibrate", help="fit the as-built plant to the thesis's measurements (SPEC §8, §9 T1)")
    cal.add_argument("--out", type=arguments.out_dir, required=True, metavar="DIR", help="results folder (created)")
    cal.add_argument("--workers", type=arguments.workers, default=max(1, min(os.cpu_count() or 1, 4)),
                     help="processes (default: the cores, at most 4)")
    cal.add_argument("--install", action="store_true",
                     help="also make the result the as-built preset (twin/plants/data/as_built.json)")
    cal.set_defaults(func=_cmd_calibrate)
