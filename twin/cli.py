"""Command line of the hydraulic joint twin.

    twin demo                      reproduce the thesis's controller comparison
    twin run --controller ffpva --trajectory 1 --json      one scenario
    twin bench                     cost per simulated second
    twin view --controller smc --trajectory 4              the joint live in a browser
    twin study robustness --out DIR                        the thesis's Chapter 6 protocol
    twin study ablation --out DIR                          each as-built effect off in turn, against SPEC §8

Degrees, grams and kPa here; SI inside. Bad input gets a one-line error and
exit code 2, and nothing is written.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import pathlib
import signal
import sys
import time

from twin.exceptions import InvalidScenario, TwinError
from twin.physics.model import Orientation
from twin.plants import PLANTS, Plant
from twin.plants.as_built import EFFECTS, as_built_plant
from twin.sim.scenario import CONTROLLER_NAMES, Scenario

EXIT_USAGE = 2


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> None:  # one line, no usage dump
        self.exit(EXIT_USAGE, f"{self.prog}: error: {message}\n")


def _writable_file(suffix: str):
    """An argparse type for an output file with ``suffix`` in an existing, writable folder."""
    def check(text: str) -> pathlib.Path:
        path = pathlib.Path(text)
        if path.suffix.lower() != suffix:
            raise argparse.ArgumentTypeError(f"{text!r} must end in {suffix}")
        if not path.parent.is_dir():
            raise argparse.ArgumentTypeError(f"folder {str(path.parent)!r} of {text!r} does not exist")
        if path.is_dir():
            raise argparse.ArgumentTypeError(f"{text!r} is a folder, not a file")
        if not os.access(path.parent, os.W_OK) or (path.exists() and not os.access(path, os.W_OK)):
            raise argparse.ArgumentTypeError(f"cannot write {text!r}")
        return path

    return check


def _checked(kind: type, accept, requirement: str):
    """An argparse type: parse with ``kind``, keep it if ``accept(value)``, else name the bad text."""
    def parse(text: str):
        try:
            value = kind(text)
        except ValueError:
            value = None
        if value is None or not math.isfinite(value) or not accept(value):
            raise argparse.ArgumentTypeError(f"{requirement}, got {text!r}")
        return value

    return parse


_grams = _checked(float, lambda v: v >= 0, "payload must be a non-negative number of grams")
_kpa = _checked(float, lambda v: 0 < v <= 700, "supply pressure must be in (0, 700] kPa (cylinder rating)")
_seed = _checked(int, lambda v: v >= 0, "seed must be a non-negative integer")
_positive_int = _checked(int, lambda v: v >= 1, "expected a positive integer")
_port = _checked(int, lambda v: 0 <= v <= 65535, "port must be an integer in [0, 65535]")
_speed = _checked(float, lambda v: 0 < v <= 10, "speed must be in (0, 10] times real time")
_seconds = _checked(float, lambda v: v > 0, "duration must be a positive number of seconds")


def add_scenario_arguments(parser: argparse.ArgumentParser) -> None:
    """The scenario flags shared by ``run`` and later commands."""
    parser.add_argument("--controller", choices=CONTROLLER_NAMES, required=True)
    parser.add_argument("--trajectory", type=int, choices=(1, 2, 3, 4), required=True)
    parser.add_argument("--payload", type=_grams, default=0.0, metavar="GRAMS", help="mass at the link tip (g)")
    parser.add_argument("--orientation", choices=[o.value for o in Orientation], default="horizontal")
    parser.add_argument("--plant", choices=sorted(PLANTS), default="thesis")
    parser.add_argument("--seed", type=_seed, default=0)
    parser.add_argument("--noise", action=argparse.BooleanOptionalAction, default=True,
                        help="the thesis's sensor noise, seeded (default on)")
    parser.add_argument("--supply-kpa", type=_kpa, default=None, help="supply pressure (kPa gauge)")
    parser.add_argument("--without", type=_effects, default=(), metavar="EFFECT[,EFFECT]",
                        help=f"as-built effects to switch off ({', '.join(EFFECTS)}); only with --plant as-built")


def _effects(text: str) -> tuple[str, ...]:
    names = tuple(sorted({name.strip() for name in text.split(",") if name.strip()}))
    unknown = [name for name in names if name not in EFFECTS]
    if not names or unknown:
        raise argparse.ArgumentTypeError(f"unknown as-built effect {', '.join(unknown) or repr(text)}: "
                                         f"choose from {', '.join(EFFECTS)}")
    return names


def _plant_of(args: argparse.Namespace) -> str | Plant:
    """``--plant``, or the as-built plant with the ``--without`` effects switched off."""
    if not args.without:
        return args.plant
    if args.plant != "as-built":
        raise InvalidScenario(f"--without switches off as-built effects, but the plant is {args.plant!r}: "
                              f"use --plant as-built")
    return as_built_plant(without=args.without, name="as-built-without-" + "+".join(args.without))


def scenario_from(args: argparse.Namespace) -> Scenario:
    return Scenario(
        controller=args.controller, trajectory=args.trajectory, payload=args.payload / 1e3,
        orientation=Orientation(args.orientation), plant=_plant_of(args), seed=args.seed, noise=args.noise,
        supply_pressure=None if args.supply_kpa is None else args.supply_kpa * 1e3,
    )


def _cmd_run(args: argparse.Namespace) -> int:
    from twin.envs.runner import run
    from twin.sim import report

    result = run(scenario_from(args))
    if args.trace:
        report.write_trace(result, args.trace)
    if args.plot:
        from viz.plots import plot_run

        plot_run(result, args.plot)
    if args.html:
        from viz.recording import write_recording

        write_recording(result, args.html)
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


def _cmd_view(args: argparse.Namespace) -> int:
    from viz.live_server import LiveSession, LiveViewer

    session = LiveSession(scenario_from(args), record=args.html is not None)
    viewer = LiveViewer(session, host=args.host, port=args.port, speed=args.speed)
    if args.host not in ("127.0.0.1", "localhost", "::1"):
        print(f"warning: serving on {args.host}: anyone who can reach it can drive the twin", file=sys.stderr)
    print(f"twin view: open {viewer.url}  (Ctrl-C to stop)", flush=True)
    if args.duration is not None:
        stop_at = time.monotonic() + args.duration
        viewer.on_frame = lambda: viewer.stop() if time.monotonic() >= stop_at else None
    signal.signal(signal.SIGTERM, signal.default_int_handler)  # stop (and write --html) on SIGTERM too
    try:
        viewer.start()
    except KeyboardInterrupt:
        viewer.stop()
    print("twin view: stopped", flush=True)
    if args.html is not None:
        print(f"writing {args.html} ...", flush=True)
        try:
            session.write_html(args.html)
        except KeyboardInterrupt:
            print("twin view: interrupted; no recording written", file=sys.stderr)
            return 130
        print(f"wrote {args.html}", flush=True)
    return 1 if viewer.failure else 0


def _cmd_calibrate(args: argparse.Namespace) -> int:
    from twin.experiments import calibrate
    from twin.plants.as_built import CALIBRATION_FILE
    from viz.calibration_plots import plot_calibration

    args.out.mkdir(exist_ok=True)

    def progress(done: int, cost: float, values: dict) -> None:
        shown = ", ".join(f"{k} {v:.4g}" for k, v in values.items())
        print(f"[{done}/{args.max_evaluations}] cost {cost:.4f}  {shown}", file=sys.stderr, flush=True)

    if args.max_evaluations is None:
        args.max_evaluations = calibrate.MAX_EVALUATIONS
    result = calibrate.calibrate(workers=args.workers, max_evaluations=args.max_evaluations, progress=progress)
    data = calibrate.record(result)
    path = calibrate.write(data, args.out)
    plot_calibration(data["residuals_check_seeds"], data["history"], args.out / "calibration.png",
                     data["residuals_ensemble_seeds"], len(data["ensemble_seeds"]), len(data["check_seeds"]))
    print(calibrate.format_residuals(data))
    print(f"wrote {path} and {args.out / 'calibration.png'} ({result.evaluations} evaluations, "
          f"{result.wall_time:.0f} s)")
    if args.install:
        CALIBRATION_FILE.write_text(path.read_text())
        print(f"installed as the as-built preset: {CALIBRATION_FILE}")
    return 0


def _cmd_demo(args: argparse.Namespace) -> int:
    from twin.experiments.demo import run_demo

    return run_demo(out=args.out, seeds=args.seeds, plots=args.plots)


def _cmd_bench(args: argparse.Namespace) -> int:
    from twin.experiments.bench import measure

    for line in measure(batch_size=args.batch, workers=args.workers).lines():
        print(line)
    return 0


def _out_dir(text: str) -> pathlib.Path:
    path = pathlib.Path(text)
    if not path.parent.exists():
        raise argparse.ArgumentTypeError(f"folder {str(path.parent)!r} does not exist")
    if path.exists() and not path.is_dir():
        raise argparse.ArgumentTypeError(f"{text!r} is a file, not a folder")
    return path


def _cmd_sweep(args: argparse.Namespace) -> int:
    from tqdm import tqdm

    from twin.batch import grid, tables
    from twin.batch.sweep import open_store, run_sweep

    axes = grid.read_toml(args.config) if args.config else {}
    for name in grid.AXES:
        value = getattr(args, name)
        if value is not None:
            axes[name] = grid.parse_axis(name, value)
    points = grid.expand(axes)
    args.out.mkdir(exist_ok=True)
    open_store(args.out).close()  # refuses a store of another code version before any output
    print(f"{len(points)} scenarios -> {args.out.resolve()}", file=sys.stderr)
    bar = tqdm(total=len(points), unit="scenario", file=sys.stderr, dynamic_ncols=True, smoothing=0.1)
    try:
        outcome = run_sweep(points, out=args.out, workers=args.workers, backend=args.backend,
                            address=args.ray_address, progress=bar.update)
    except KeyboardInterrupt:
        bar.close()
        print(f"interrupted: finished scenarios are kept in {args.out / 'results.sqlite'}; "
              "run the same command again to finish the rest", file=sys.stderr)
        return 130
    finally:
        bar.close()
    tables.write_results(outcome.records, args.out)
    summary = tables.summarise(outcome.records)
    tables.write_summary(summary, args.out)
    from viz.sweep_plots import plot_summary

    plot_summary(summary, args.out / "rmse.png")
    print(tables.format_summary(summary))
    failed = [r for r in outcome.records if r["status"] != "ok"]
    for r in failed[:20]:
        print(f"failed: {r['key']}: {r['reason']}", file=sys.stderr)
    print(f"{outcome.ran} run, {outcome.skipped} already done, {len(failed)} failed; "
          f"wrote results.csv, results.parquet, summary.csv, rmse.png in {args.out}")
    return 1 if failed else 0


_WHATIF_LISTS = {"payload": ("--payloads", "payloads", "payload"), "lift": ("--pressures", "pressures", "supply_kpa"),
                 "pwm": ("--periods", "periods", "pwm_period_ms")}  # study: (flag, attribute, sweep axis)


def _whatif_values(args: argparse.Namespace, plant_name: str) -> list | None:
    """The study's list flag, parsed and every scenario it implies built (so bad input fails before
    anything is written), in edge units; errors name the flag. None for a study without a list."""
    from twin.batch import grid
    from twin.exceptions import InvalidScenario

    if args.study not in _WHATIF_LISTS:
        return None
    flag, attribute, axis = _WHATIF_LISTS[args.study]
    try:
        values = grid.parse_axis(axis, getattr(args, attribute))
        grid.expand({axis: values, "plant": [plant_name]})
    except InvalidScenario as error:
        message = str(error).replace(f"--{axis.replace('_', '-')}", flag)  # grid names its own flag (--payload)
        raise InvalidScenario(message if flag in message else f"{flag}: {message}") from None
    return values


def _cmd_whatif(args: argparse.Namespace) -> int:
    from tqdm import tqdm

    from twin.batch import tables
    from twin.experiments import whatif
    from viz.whatif_plots import PLOTS

    plant_name = args.plant or whatif.DEFAULT_PLANTS[args.study]
    values = _whatif_values(args, plant_name)
    if args.study == "supply":  # a plant whose supply cannot sag is refused before anything is written
        from twin.plants import plant

        whatif.supply_variants(plant(plant_name))
    args.out.mkdir(exist_ok=True)
    with tqdm(unit="scenario", file=sys.stderr, dynamic_ncols=True, desc=args.study) as bar:
        if args.study == "payload":
            store = args.out / "payload-runs"
            store.mkdir(exist_ok=True)
            study = whatif.payload_study(out=store, payloads_g=values, trajectory=args.trajectory, seeds=args.seeds,
                                         plant_name=plant_name, workers=args.workers, progress=bar.update)
        elif args.study == "pwm":
            study = whatif.pwm_study(periods_ms=values, seeds=args.seeds, plant_name=plant_name)
        elif args.study == "lift":
            study = whatif.lift_study(pressures_kpa=values, plant_name=plant_name)
        elif args.study == "supply":
            study = whatif.supply_study(seeds=args.seeds, plant_name=plant_name)
        else:
            study = whatif.gear_load_study(plant_name=plant_name)
    stem = args.out / args.study
    tables.write_csv(study.rows, list(study.rows[0]), stem.with_suffix(".csv"))
    PLOTS[args.study](study.rows, stem.with_suffix(".png"))
    stem.with_suffix(".txt").write_text(study.answer + "\n")
    print(study.answer)
    print(f"wrote {stem.with_suffix('.csv')}, {stem.with_suffix('.png')}, {stem.with_suffix('.txt')}")
    return 0


def _cmd_ablation(args: argparse.Namespace) -> int:
    from twin.batch import tables
    from twin.experiments import ablation
    from twin.plants.as_built import calibrated_values
    from viz.study_plots import plot_ablation

    calibrated_values()  # no committed preset: a one-line error before anything is written
    args.out.mkdir(exist_ok=True)
    print(f"{len(ablation.variants())} variants x 11 cells x {args.seeds} seeds on the as-built plant -> "
          f"{args.out.resolve()}", file=sys.stderr)
    study = ablation.ablation_study(seeds=range(args.seeds), workers=args.workers,
                                    progress=lambda done, total, label: print(f"[{done}/{total}] {label}",
                                                                              file=sys.stderr))
    csv, png = args.out / "ablation.csv", args.out / "ablation.png"
    tables.write_csv(study.rows, list(study.rows[0]), csv)
    plot_ablation(study.rows, png)
    print(ablation.format_ablation(study))
    print(f"wrote {csv}, {png}")
    return 1 if any(r["failed_runs"] for r in study.rows) else 0


def _cmd_study(args: argparse.Namespace) -> int:
    from twin.experiments import studies
    from twin.plants import plant

    plant_name = args.plant or studies.default_plant("thesis" if args.study == "robustness" else "thesis-pwm")
    plant(plant_name)  # an unknown name is a one-line error before anything is written
    args.out.mkdir(exist_ok=True)
    if args.study == "robustness":
        from tqdm import tqdm

        from viz.study_plots import plot_robustness

        points = studies.robustness_grid(plant_name=plant_name, seeds=args.seeds)
        print(f"{len(points)} runs on the {plant_name} plant -> {args.out.resolve()}", file=sys.stderr)
        try:
            with tqdm(total=len(points), unit="run", file=sys.stderr, dynamic_ncols=True, desc="robustness") as bar:
                study = studies.robustness_study(out=args.out, plant_name=plant_name, seeds=args.seeds,
                                                 workers=args.workers, progress=bar.update)
        except KeyboardInterrupt:
            print(f"interrupted: finished runs are kept in {args.out / 'results.sqlite'}; "
                  "run the same command again to finish the rest", file=sys.stderr)
            return 130
        paths = studies.write_robustness(study, args.out) + [args.out / "robustness.png"]
        plot_robustness(study.runs, paths[-1])
        print(studies.format_robustness(study))
        failed = bool(study.failed)
    else:
        from viz.study_plots import plot_openloop

        study = studies.openloop_study(plant_name=plant_name)
        paths = [studies.write_openloop(study, args.out), args.out / "openloop.png"]
        plot_openloop(study, paths[-1])
        print(study.answer)
        failed = any(run.warnings for run in study.runs)
    print(f"wrote {', '.join(str(p) for p in paths)}")
    return 1 if failed else 0


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="twin", description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)

    demo = sub.add_parser("demo", help="reproduce the thesis's simulated controller comparison")
    demo.add_argument("--out", type=_out_dir, default=pathlib.Path("twin-demo"),
                      help="output folder (created; default ./twin-demo)")
    demo.add_argument("--seeds", type=_positive_int, default=5, help="noise seeds per case (default 5)")
    demo.add_argument("--plots", action=argparse.BooleanOptionalAction, default=True)
    demo.set_defaults(func=_cmd_demo)

    bench = sub.add_parser("bench", help="cost per simulated second, as ratios to bare mj_step")
    bench.add_argument("--batch", type=_positive_int, default=100, help="runs in the batched case (default 100)")
    bench.add_argument("--workers", type=_positive_int, default=None, help="sweep workers (default: all cores)")
    bench.set_defaults(func=_cmd_bench)

    sweep = sub.add_parser("sweep", help="a grid of scenarios on all cores (or Ray), resumable")
    for name in ("controller", "trajectory", "payload", "orientation", "plant", "seed", "supply_kpa", "pwm_period_ms"):
        sweep.add_argument("--" + name.replace("_", "-"), dest=name, metavar="LIST",
                           help="comma list; numbers also start:stop:step; seeds also a-b")
    sweep.add_argument("--config", type=pathlib.Path, metavar="GRID.toml", help="axes from a TOML file")
    sweep.add_argument("--out", type=_out_dir, required=True, metavar="DIR", help="results folder (created)")
    sweep.add_argument("--workers", type=_positive_int, default=None,
                       help="processes (default: all cores); with Ray, CPUs to size chunks for (default: the cluster's)")
    sweep.add_argument("--backend", choices=("local", "ray"), default="local")
    sweep.add_argument("--ray-address", default=None, help="Ray cluster address (default: RAY_ADDRESS or local)")
    sweep.set_defaults(func=_cmd_sweep)

    whatif = sub.add_parser("whatif", help="payload, lift, PWM, gear-load and supply studies")
    whatif.add_argument("study", choices=("payload", "lift", "pwm", "gear-load", "supply"))
    whatif.add_argument("--out", type=_out_dir, required=True, metavar="DIR")
    whatif.add_argument("--plant", choices=sorted(PLANTS), default=None,
                        help="default: thesis-pwm for pwm (switching valves), thesis otherwise")
    whatif.add_argument("--payloads", default="0:30:2.5", metavar="LIST", help="grams (payload study)")
    whatif.add_argument("--trajectory", type=int, choices=(1, 2, 3, 4), default=1, help="payload study")
    whatif.add_argument("--pressures", default="100:700:50", metavar="LIST", help="kPa (lift study)")
    whatif.add_argument("--periods", default="8:32:4", metavar="LIST", help="valve PWM periods in ms (pwm study)")
    whatif.add_argument("--seeds", type=_positive_int, default=3)
    whatif.add_argument("--workers", type=_positive_int, default=None)
    whatif.set_defaults(func=_cmd_whatif)

    study = sub.add_parser("study", help="the thesis's robustness protocol (ch. 6) and open-loop validation (4.6)")
    studies = study.add_subparsers(dest="study", required=True, parser_class=_Parser)
    robustness = studies.add_parser("robustness", help="FF + PVA and sliding mode, T1 and T3, 0/6.5/13.5 g, "
                                    "horizontal and vertical, 5 seeds (SPEC §9)")
    robustness.add_argument("--seeds", type=_positive_int, default=5, help="noise seeds per case (default 5)")
    robustness.add_argument("--workers", type=_positive_int, default=None, help="processes (default: all cores)")
    openloop = studies.add_parser("openloop", help="sine duty with soft limits, thesis model against a plant (SPEC §4)")
    for parser_ in (robustness, openloop):
        parser_.add_argument("--plant", default=None, metavar="NAME",
                             help="default: as-built if present, else thesis (robustness) or thesis-pwm (openloop)")
        parser_.add_argument("--out", type=_out_dir, required=True, metavar="DIR", help="output folder (created)")
        parser_.set_defaults(func=_cmd_study)
    ablation = studies.add_parser("ablation", help="the as-built preset on SPEC §8's cells with each effect "
                                  "switched off in turn")
    ablation.add_argument("--seeds", type=_positive_int, default=5, help="noise seeds per cell (default 5)")
    ablation.add_argument("--workers", type=_positive_int, default=2, help="processes (default 2)")
    ablation.add_argument("--out", type=_out_dir, required=True, metavar="DIR", help="output folder (created)")
    ablation.set_defaults(func=_cmd_ablation)

    run = sub.add_parser("run", help="simulate one scenario")
    add_scenario_arguments(run)
    run.add_argument("--trace", type=_writable_file(".csv"), metavar="FILE.csv", help="write the time series")
    run.add_argument("--plot", type=_writable_file(".png"), metavar="FILE.png", help="write a figure")
    run.add_argument("--json", action="store_true", help="print exactly one JSON object")
    run.add_argument("--html", type=_writable_file(".html"), metavar="FILE.html",
                     help="write a self-contained 3D recording with its traces")
    run.set_defaults(func=_cmd_run)

    cal = sub.add_parser("calibrate", help="fit the as-built plant to the thesis's experiments (SPEC §8)")
    cal.add_argument("--out", type=_out_dir, required=True, metavar="DIR", help="results folder (created)")
    cal.add_argument("--workers", type=_positive_int, default=max(1, min(os.cpu_count() or 1, 4)),
                     help="processes (default: the cores, at most 4)")
    cal.add_argument("--max-evaluations", type=_positive_int, default=None, metavar="N",
                     help="optimiser budget (default: twin.experiments.calibrate.MAX_EVALUATIONS)")
    cal.add_argument("--install", action="store_true",
                     help="also make the result the as-built preset (twin/data/as_built.json)")
    cal.set_defaults(func=_cmd_calibrate)

    view = sub.add_parser("view", help="the joint live in a browser (3D view and control panel)")
    add_scenario_arguments(view)
    view.add_argument("--host", default="127.0.0.1", help="address to listen on (default 127.0.0.1 only)")
    view.add_argument("--port", type=_port, default=7000, help="TCP port (default 7000; 0: any free port)")
    view.add_argument("--speed", type=_speed, default=1.0, help="simulated seconds per second (default 1)")
    view.add_argument("--duration", type=_seconds, default=None, metavar="SECONDS",
                      help="stop after this many seconds of wall time (default: run until Ctrl-C)")
    view.add_argument("--html", type=_writable_file(".html"), metavar="FILE.html",
                      help="on stopping, write a recording of the last model's run (up to 10 min)")
    view.set_defaults(func=_cmd_view)
    return parser


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return args.func(args)
    except TwinError as error:
        print(f"twin: error: {error}", file=sys.stderr)
        return EXIT_USAGE
    except OSError as error:  # an output that passed the checks but still cannot be written
        print(f"twin: error: cannot write {error.filename or ''}: {error.strerror}", file=sys.stderr)
        return EXIT_USAGE


if __name__ == "__main__":
    sys.exit(main())
