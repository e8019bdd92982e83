"""What several commands share: the parser that fails in one line, and the scenario flags."""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import os
import pathlib
import shutil
import signal
import sys
import threading

from twin.batch.lock import folder_lock
from twin.batch.stops import raise_if_stopped, swallowed_stops_kept
from twin.exceptions import InvalidScenario
from twin.experiments import arguments
from twin.experiments.base import named_error
from twin.physics.model import Orientation
from twin.plants import PLANTS, Plant
from twin.plants.as_built import EFFECTS, as_built_plant
from twin.sim.scenario import CONTROLLER_NAMES, Scenario

EXIT_USAGE = 2
EXIT_INTERRUPTED = 130  # 128 + SIGINT, as a shell reports Ctrl-C


class Parser(argparse.ArgumentParser):
    def error(self, message: str) -> None:  # one line, no usage dump, one prefix for every command
        command = " ".join(self.prog.split()[1:])
        self.exit(EXIT_USAGE, f"twin: error: {command + ': ' if command else ''}{message}\n")


def add_scenario_arguments(parser: argparse.ArgumentParser) -> None:
    """The scenario flags shared by ``run`` and later commands."""
    parser.add_argument("--controller", choices=CONTROLLER_NAMES, required=True)
    parser.add_argument("--trajectory", type=arguments.trajectory, required=True, metavar="{1,2,3,4}")
    parser.add_argument("--payload", type=arguments.grams, default=0.0, metavar="GRAMS", help="mass at the link tip (g)")
    parser.add_argument("--orientation", choices=[o.value for o in Orientation], default="horizontal")
    parser.add_argument("--plant", choices=sorted(PLANTS), default="thesis")
    parser.add_argument("--seed", type=arguments.seed, default=0)
    parser.add_argument("--noise", action=argparse.BooleanOptionalAction, default=True,
                        help="the thesis's sensor noise, seeded (default on)")
    parser.add_argument("--supply-kpa", type=arguments.kpa, default=None, help="supply pressure (kPa gauge)")
    parser.add_argument("--without", type=effects, default=(), metavar="EFFECT[,EFFECT]",
                        help=f"as-built effects to switch off ({', '.join(EFFECTS)}); only with --plant as-built")


# --compare KEY=VALUE: the scenario flags a second joint may change (not --trajectory: both joints
# share the targets and replays), each checked by its own flag's type; a Scenario field per key.
COMPARE_FIELDS = {"controller": "controller", "plant": "plant", "payload": "payload", "orientation": "orientation",
                  "seed": "seed", "noise": "noise", "supply-kpa": "supply_pressure", "without": "plant"}


def _flag_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(add_help=False, exit_on_error=False)
    add_scenario_arguments(parser)
    return parser


def compare_settings(text: str) -> dict[str, str]:
    """``--compare KEY=VALUE[,KEY=VALUE]``: the user's settings, each value checked by the scenario
    flag of the same name (``noise=on|off``; ``without=EFFECT[+EFFECT]``)."""
    settings: dict[str, str] = {}
    for item in (part.strip() for part in text.split(",")):
        key, equals, value = item.partition("=")
        key, value = key.strip(), value.strip()
        if not equals or not key or not value:
            raise argparse.ArgumentTypeError(f"expected KEY=VALUE[,KEY=VALUE], got {item!r}")
        if key not in COMPARE_FIELDS:
            why = "both joints share it" if key == "trajectory" else f"choose from {', '.join(COMPARE_FIELDS)}"
            raise argparse.ArgumentTypeError(f"key {key!r} cannot be compared: {why}")
        if key in settings:
            raise argparse.ArgumentTypeError(f"key {key!r} given twice")
        _flag_values({key: value})  # raises with the flag's own reason
        settings[key] = value
    return settings


def _flag_values(settings: dict[str, str]) -> argparse.Namespace:
    """The scenario flags' namespace for ``settings`` (on top of the required flags' placeholders)."""
    argv = ["--controller", "ffpva", "--trajectory", "1"]
    for key, value in settings.items():
        if key == "noise":
            if value not in ("on", "off"):
                raise argparse.ArgumentTypeError(f"key 'noise': expected on or off, got {value!r}")
            argv.append("--noise" if value == "on" else "--no-noise")
        else:
            argv += [f"--{key}", value.replace("+", ",") if key == "without" else value]
    try:
        namespace, rest = _flag_parser().parse_known_args(argv)
    except argparse.ArgumentError as error:
        raise argparse.ArgumentTypeError(f"key {error.argument_name.lstrip('-')!r}: {error.message}") from None
    if rest:
        raise argparse.ArgumentTypeError(f"cannot read {' '.join(rest)!r}")
    return namespace


def _as_run(scenario: Scenario, field: str):
    """``scenario``'s ``field`` as the run takes it (a supply pressure not given is the plant's)."""
    return scenario.supply if field == "supply_pressure" else getattr(scenario, field)


def compare_of(args: argparse.Namespace, settings: dict[str, str]):
    """:class:`twin.envs.live.Compare` for ``settings`` on top of the command's scenario flags."""
    from twin.envs.live import Compare

    parsed = _flag_values(settings)
    merged = argparse.Namespace(**vars(args))
    for key in settings:
        dest = key.replace("-", "_")
        setattr(merged, dest, getattr(parsed, dest))
    if "plant" in settings and "without" not in settings and merged.plant != "as-built":
        merged.without = None  # --without is the as-built plant's: another plant compared drops it
    try:
        scenario = scenario_from(merged)
    except InvalidScenario as error:
        raise InvalidScenario(f"--compare {','.join(f'{k}={v}' for k, v in settings.items())}: {error}") from None
    changes = {COMPARE_FIELDS[key]: getattr(scenario, COMPARE_FIELDS[key]) for key in settings}
    first = scenario_from(args)
    if all(_as_run(first, field) == _as_run(scenario, field) for field in changes):
        raise InvalidScenario(f"--compare {','.join(f'{k}={v}' for k, v in settings.items())}: the first joint "
                              "has these settings already: nothing to compare")
    return Compare(changes=changes, text=dict(settings))


def effects(text: str) -> tuple[str, ...]:
    names = tuple(sorted({name.strip() for name in text.split(",") if name.strip()}))
    unknown = [name for name in names if name not in EFFECTS]
    if not names or unknown:
        raise argparse.ArgumentTypeError(f"unknown as-built effect {', '.join(unknown) or repr(text)}: "
                                         f"choose from {', '.join(EFFECTS)}")
    return names


def plant_of(args: argparse.Namespace) -> str | Plant:
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
        orientation=Orientation(args.orientation), plant=plant_of(args), seed=args.seed, noise=args.noise,
        supply_pressure=None if args.supply_kpa is None else args.supply_kpa * 1e3,
    )


STOPPED_AS_CTRL_C = (signal.SIGTERM, signal.SIGHUP)  # besides Ctrl-C itself


@contextlib.contextmanager
def sigterm_as_interrupt():
    """SIGTERM (``kill``, a job scheduler) and SIGHUP (the terminal or ssh session closed) stop the ``with``
    block as Ctrl-C does, so the same clean-up runs; the previous handlers afterwards. A signal the process
    was started ignoring (``nohup`` ignores SIGHUP) stays ignored. A stop that Python swallowed (it came
    inside a garbage collector's callback) is raised again before any output goes into place
    (:func:`swallowed_stops_kept`). Only the main thread may set handlers: elsewhere a no-op."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {signum: signal.signal(signum, signal.default_int_handler) for signum in STOPPED_AS_CTRL_C
                if signal.getsignal(signum) is not signal.SIG_IGN}  # ignored (``nohup``): left ignored
    try:
        with swallowed_stops_kept():
            yield
    finally:
        for signum, handler in previous.items():
            if handler is not None:  # None: a handler set outside Python, which cannot be put back from here
                signal.signal(signum, handler)


@dataclasses.dataclass
class OutputFolder:
    """What :func:`output_folder` yields: whether the command made the folder, and whether to keep it
    if the block fails from here on (set ``keep`` once a result worth keeping is in it)."""

    made: bool
    keep: bool


@contextlib.contextmanager
def output_folder(out: pathlib.Path, *, keep_on_failure: bool = False):
    """A command's ``--out`` for the ``with`` block: made if it does not exist (atomically, so two
    commands cannot both think they made it), its lock held (one writer; taking it also finds out, before
    any work, that no file can be made there), SIGTERM taken as Ctrl-C. If the block fails or is
    stopped, a folder made here is removed again while the lock is still held, unless the yielded
    :class:`OutputFolder`'s ``keep`` is set (``keep_on_failure``: from the start, for a store of finished
    runs)."""
    try:
        out.mkdir()
        made = True
    except FileExistsError:
        made = False
    folder, entered = OutputFolder(made=made, keep=keep_on_failure), False
    try:
        with sigterm_as_interrupt(), folder_lock(out):
            entered = True
            try:
                yield folder
            except BaseException:
                if folder.made and not folder.keep:
                    shutil.rmtree(out, ignore_errors=True)
                raise
    except OSError:
        if not entered and folder.made and not folder.keep:  # the lock file could not be made: nothing written
            shutil.rmtree(out, ignore_errors=True)
        raise


def check_out_folder(out: pathlib.Path, command: str, names) -> None:
    """Before ``twin demo``'s or ``twin sweep``'s work: no folder in the way of the files ``names`` it will write
    in ``out``, and ``out`` not written by the other of the two. Both write ``results.csv``, and each would
    overwrite the other's in part, leaving the rest to describe other runs; the other is found by
    :func:`twin.experiments.demo.wrote_folder` and :func:`twin.batch.tables.sweep_mark`."""
    from twin.batch.tables import sweep_mark
    from twin.experiments.base import refuse_folders_in_the_way
    from twin.experiments.demo import wrote_folder

    refuse_folders_in_the_way(out, names)
    if command == "sweep" and wrote_folder(out):
        other, shown_by = "demo", "summary.md"
    elif command == "demo" and (mark := sweep_mark(out)):
        other, shown_by = "sweep", mark
    else:
        return
    raise InvalidScenario(f"--out {out} holds twin {other}'s results ({shown_by}): give twin {command} a folder "
                          "of its own")


@contextlib.contextmanager
def all_or_nothing(paths: list[pathlib.Path]):
    """Temporary files beside ``paths`` (same folder, same suffix) to write into; each becomes its path
    only once every one was written, and none is left behind if any write fails. An OSError that names a
    temporary names its path instead (write each inside :func:`twin.experiments.base.naming` so that a full disk's names one)."""
    temporary = [path.with_name(f".{path.stem}.tmp-{os.getpid()}{path.suffix}") for path in paths]
    try:
        yield temporary
        raise_if_stopped()
        for tmp, path in zip(temporary, paths, strict=True):
            os.replace(tmp, path)
    except OSError as error:  # name the file the user asked for, not its temporary
        named = {str(tmp): str(path) for tmp, path in zip(temporary, paths, strict=True)}
        if str(error.filename) not in named:
            raise
        raise named_error(error, named[str(error.filename)]) from None
    finally:
        for tmp in temporary:
            tmp.unlink(missing_ok=True)


def say_written(paths: list[pathlib.Path]) -> None:
    """``wrote PATH`` for each, on stderr (stdout may be one JSON object)."""
    for path in paths:
        print(f"wrote {path}", file=sys.stderr)
