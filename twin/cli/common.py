"""What several commands share: the parser that fails in one line, and the scenario flags."""

from __future__ import annotations

import argparse
import contextlib
import os
import pathlib
import sys

from twin.exceptions import InvalidScenario
from twin.experiments import arguments
from twin.physics.model import Orientation
from twin.plants import PLANTS, Plant
from twin.plants.as_built import EFFECTS, as_built_plant
from twin.sim.scenario import CONTROLLER_NAMES, Scenario

EXIT_USAGE = 2


class Parser(argparse.ArgumentParser):
    def error(self, message: str) -> None:  # one line, no usage dump, one prefix for every command
        command = " ".join(self.prog.split()[1:])
        self.exit(EXIT_USAGE, f"twin: error: {command + ': ' if command else ''}{message}\n")


def add_scenario_arguments(parser: argparse.ArgumentParser) -> None:
    """The scenario flags shared by ``run`` and later commands."""
    parser.add_argument("--controller", choices=CONTROLLER_NAMES, required=True)
    parser.add_argument("--trajectory", type=int, choices=(1, 2, 3, 4), required=True)
    parser.add_argument("--payload", type=arguments.grams, default=0.0, metavar="GRAMS", help="mass at the link tip (g)")
    parser.add_argument("--orientation", choices=[o.value for o in Orientation], default="horizontal")
    parser.add_argument("--plant", choices=sorted(PLANTS), default="thesis")
    parser.add_argument("--seed", type=arguments.seed, default=0)
    parser.add_argument("--noise", action=argparse.BooleanOptionalAction, default=True,
                        help="the thesis's sensor noise, seeded (default on)")
    parser.add_argument("--supply-kpa", type=arguments.kpa, default=None, help="supply pressure (kPa gauge)")
    parser.add_argument("--without", type=effects, default=(), metavar="EFFECT[,EFFECT]",
                        help=f"as-built effects to switch off ({', '.join(EFFECTS)}); only with --plant as-built")


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


@contextlib.contextmanager
def all_or_nothing(paths: list[pathlib.Path]):
    """Temporary files beside ``paths`` (same folder, same suffix) to write into; each becomes its path
    only once every one was written, and none is left behind if any write fails."""
    temporary = [path.with_name(f".{path.stem}.tmp-{os.getpid()}{path.suffix}") for path in paths]
    try:
        yield temporary
        for tmp, path in zip(temporary, paths, strict=True):
            os.replace(tmp, path)
    except OSError as error:  # name the file the user asked for, not its temporary
        named = {str(tmp): str(path) for tmp, path in zip(temporary, paths, strict=True)}
        raise OSError(error.errno, error.strerror, named.get(str(error.filename), error.filename)) from None
    finally:
        for tmp in temporary:
            tmp.unlink(missing_ok=True)


def say_written(paths: list[pathlib.Path]) -> None:
    """``wrote PATH`` for each, on stderr (stdout may be one JSON object)."""
    for path in paths:
        print(f"wrote {path}", file=sys.stderr)
