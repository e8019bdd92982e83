"""``twin calibrate``: fit the as-built plant to the thesis's measurements (SPEC §8, §9's T1 cells)."""

from __future__ import annotations

import argparse
import os
import sys

from twin.experiments import arguments


def _cmd_calibrate(args: argparse.Namespace) -> int:
    from twin.experiments import calibrate
    from twin.plants.as_built import CALIBRATION_FILE
    from viz.calibration_plots import plot_calibration

    args.out.mkdir(exist_ok=True)

    def progress(done: int, total: int, stage: str, cost: float, values: dict) -> None:
        shown = ", ".join(f"{k} {v:.4g}" for k, v in values.items())
        print(f"[{done}/{total}] {stage:7} cost {cost:.4f}  {shown}", file=sys.stderr, flush=True)

    result = calibrate.calibrate(workers=args.workers, progress=progress)
    data = calibrate.record(result)
    path = calibrate.write(data, args.out)
    plot_calibration(data, args.out / "calibration.png")
    print(calibrate.format_residuals(data))
    print(f"wrote {path} and {args.out / 'calibration.png'} ({result.evaluations} evaluations, "
          f"{result.wall_time:.0f} s)")
    if args.install:
        CALIBRATION_FILE.write_text(path.read_text())
        print(f"installed as the as-built preset: {CALIBRATION_FILE}")
    return 0


def add_parser(sub) -> None:
    cal = sub.add_parser("calibrate", help="fit the as-built plant to the thesis's measurements (SPEC §8, §9 T1)")
    cal.add_argument("--out", type=arguments.out_dir, required=True, metavar="DIR", help="results folder (created)")
    cal.add_argument("--workers", type=arguments.workers, default=max(1, min(os.cpu_count() or 1, 4)),
                     help="processes (default: the cores, at most 4)")
    cal.add_argument("--install", action="store_true",
                     help="also make the result the as-built preset (twin/data/as_built.json)")
    cal.set_defaults(func=_cmd_calibrate)
