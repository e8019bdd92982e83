"""What the what-ifs share: their common flags, list flags parsed as sweep axes, a progress bar."""

from __future__ import annotations

import argparse
import contextlib
import sys
from collections.abc import Callable, Sequence

from twin.batch import grid
from twin.exceptions import InvalidScenario
from twin.experiments.arguments import seed_count
from twin.plants import PLANTS


def add_common_arguments(parser: argparse.ArgumentParser, default_plant: str, *, seeds: bool = True) -> None:
    parser.add_argument("--plant", choices=sorted(PLANTS), default=default_plant, help=f"default {default_plant}")
    if seeds:
        parser.add_argument("--seeds", type=seed_count, default=3, help="noise seeds per case (default 3)")


def list_flag(args: argparse.Namespace, flag: str, attribute: str, axis: str) -> list:
    """The list flag ``flag`` parsed as the sweep axis ``axis`` (edge units), with every scenario it
    implies on ``args.plant`` built, so bad input fails before anything is written; errors name ``flag``."""
    try:
        values = grid.parse_axis(axis, getattr(args, attribute))
        grid.expand({axis: values, "plant": [args.plant]})
    except InvalidScenario as error:
        message = str(error).replace(f"--{axis.replace('_', '-')}", flag)  # grid names its own flag (--payload)
        raise InvalidScenario(message if flag in message else f"{flag}: {message}") from None
    return values


def refuse_oversized(runs: int, what: str, *, at_most: bool = False) -> None:
    """A what-if of more than :data:`twin.batch.grid.MAX_POINTS` runs, the most a sweep takes, refused before
    anything is built or written, naming ``what`` sets its size ("--periods x --seeds")."""
    if runs > grid.MAX_POINTS:
        raise InvalidScenario(f"{what} would make {'up to ' if at_most else ''}{runs:,} runs: more than the "
                              f"{grid.MAX_POINTS:,} one command takes")


def number_list(text: str, flag: str, what: str, convert=grid.plain_number) -> list:
    """``flag``'s comma-separated values, each through ``convert``, without repeats, sorted; a one-line error
    naming ``flag`` and ``what`` it takes ("--phis: numbers in m/s separated by commas, got '0.2,,0.3'") for an
    empty or unreadable item. Ranges are the caller's to check."""
    parts = [part.strip() for part in text.split(",")]
    try:
        if not all(parts):
            raise ValueError(text)
        return sorted({convert(part) for part in parts})
    except ValueError:
        raise InvalidScenario(f"{flag}: {what} separated by commas, got {text!r}") from None


def simulate_in_parts(scenarios: Sequence, controllers: Sequence, keep: Callable, bar=None) -> list:
    """:func:`twin.sim.simulation.simulate_in_parts` with ``bar`` (tqdm, or None) counting the runs."""
    from twin.sim import simulation

    return simulation.simulate_in_parts(list(scenarios), controllers=list(controllers), keep=keep,
                                        progress_of=lambda count: batch_progress(bar, count))


def batch_progress(bar, count: int):
    """``simulate``'s ``progress(done_ticks, total_ticks)`` for one batch of ``count`` scenarios, shown on
    ``bar`` (tqdm, or None: no progress) in scenarios from where it stands (the batch's scenarios advance
    together)."""
    if bar is None:
        return None
    start = bar.n
    return lambda done, ticks: bar.update(start + count * done // ticks - bar.n)


@contextlib.contextmanager
def progress_bar(name: str):
    """A scenario-counting progress bar on stderr, labelled ``name``. Drawn first when its total is given
    (``reset(total=...)``) or at its first count: not as "0scenario" before it knows its total (the ``delay``),
    which a log kept as a stray line (a probe, 2026-12-08)."""
    from tqdm import tqdm

    with tqdm(unit="scenario", file=sys.stderr, dynamic_ncols=True, desc=name, delay=1e-9) as bar:
        yield bar
