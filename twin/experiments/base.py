"""One interface for every experiment the CLI runs: what-ifs (``twin whatif NAME``) and studies
(``twin study NAME``).

An experiment is a module-level object with

``name``           the command word and the stem of its output files (``DIR/NAME.csv`` ...)
``help``           one line for ``--help``
``add_arguments``  its own flags (``--out`` is added for it)
``check(args)``    every input checked, raising :class:`twin.exceptions.InvalidScenario`, before
                   anything is written
``run(args, out)`` the work, returning an :class:`Outcome`
``write``          the outcome's files: ``NAME.csv`` (its rows) and ``NAME.txt`` (its answer) unless
                   the experiment writes others
``plot``           ``NAME.png``

:func:`run_experiment` drives one through that order, so a new what-if is one new module
registered in :mod:`twin.experiments.whatifs`.
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import errno
import os
import pathlib
import shutil
import signal
import sys
import tempfile
import threading
from collections.abc import Callable
from typing import Any, ClassVar

from twin.batch.stops import STOP_SIGNALS, raise_if_stopped
from twin.batch.tables import write_csv


@dataclasses.dataclass(frozen=True)
class Outcome:
    """What an experiment found: rows (one per CSV line, edge units: deg, g, kPa, ms), the short
    answer, how many runs failed, and whatever else its plot draws."""

    rows: list[dict]
    answer: str
    failed: int = 0
    detail: Any = None


class Experiment:
    """Base of the experiments: the defaults of the interface above."""

    name: ClassVar[str]
    help: ClassVar[str]
    resumable: ClassVar[bool] = False  # keeps finished runs in DIR/results.sqlite across interruptions

    def add_arguments(self, parser: argparse.ArgumentParser) -> None:
        """Flags of this experiment (``--out`` is common)."""

    def check(self, args: argparse.Namespace) -> None:
        """Raise InvalidScenario for bad input, before any output exists."""

    def file_names(self) -> tuple[str, ...]:
        """The files :meth:`outputs` writes (``NAME.csv``, ``NAME.txt``, ``NAME.png`` unless it writes others), for
        a check before the run that none is a folder (:func:`staged` checks what it actually wrote, again)."""
        return (f"{self.name}.csv", f"{self.name}.txt", f"{self.name}.png")

    def run(self, args: argparse.Namespace, out: pathlib.Path) -> Outcome:
        raise NotImplementedError

    def write(self, outcome: Outcome, out: pathlib.Path) -> list[pathlib.Path]:
        """``NAME.csv`` and ``NAME.txt``."""
        csv_path, txt_path = out / f"{self.name}.csv", out / f"{self.name}.txt"
        write_csv(outcome.rows, list(outcome.rows[0]), csv_path)
        txt_path.write_text(outcome.answer + "\n")
        return [csv_path, txt_path]

    def plot(self, outcome: Outcome, path: pathlib.Path) -> None:
        raise NotImplementedError

    def outputs(self, outcome: Outcome, out: pathlib.Path, undrawn: list[tuple[str, str]]) -> list[pathlib.Path]:
        """Write the files and the plot (:func:`drawn`: a plot that fails goes into ``undrawn``); the paths
        written, the plot last."""
        paths = self.write(outcome, out)
        png = out / f"{self.name}.png"
        return paths + drawn(lambda path: self.plot(outcome, path), png, undrawn)

    def store(self, out: pathlib.Path) -> pathlib.Path:
        """Where a :attr:`resumable` experiment keeps its finished runs in ``out``."""
        return out / "results.sqlite"

    def kept(self, out: pathlib.Path) -> list[pathlib.Path]:
        """What :meth:`run` itself keeps in ``out`` to list among the files written (a resumable store)."""
        return []

    def publish(self, outcome: Outcome, out: pathlib.Path) -> tuple[list[pathlib.Path], list[tuple[str, str]]]:
        """:meth:`outputs` all or nothing (:func:`staged`), but for a figure whose drawing fails otherwise
        than by the disk, which is left out so that the tables are not lost with it. Returns the final
        paths, in :meth:`outputs`'s order, then :meth:`kept`; and the figures left out, as (file name,
        reason)."""
        with staged(out, self.name) as stage:
            stage.names += [path.relative_to(stage.folder) for path in self.outputs(outcome, stage.folder,
                                                                                    stage.undrawn)]
        return [out / name for name in stage.names] + self.kept(out), stage.undrawn


@dataclasses.dataclass
class Staging:
    """What :func:`staged` yields: the staging ``folder`` to write into, the ``names`` (relative paths)
    written there that go into place, and the figures left out (:func:`drawn`)."""

    folder: pathlib.Path
    names: list[pathlib.Path | str] = dataclasses.field(default_factory=list)
    undrawn: list[tuple[str, str]] = dataclasses.field(default_factory=list)

    def figure(self, name: str, draw: Callable[[pathlib.Path], None]) -> None:
        """``draw`` the figure ``name`` into the staging folder, best effort (:func:`drawn`)."""
        self.names += [path.name for path in drawn(draw, self.folder / name, self.undrawn)]


@contextlib.contextmanager
def staged(out: pathlib.Path, prefix: str):
    """A set of outputs put into ``out``: written into a staging folder inside ``out`` (the
    :class:`Staging` yielded), then, once the block has written them all, each renamed into ``out`` (renames
    need no space) and an earlier run's copy of each figure left out removed (it must not pass for this
    run's). If the block fails (a full disk, an interrupt), ``out`` keeps what it had. A Ctrl-C or SIGTERM
    that comes while the set is renamed in waits until it is in and the staging folder is gone
    (:func:`stops_held`), so a stop never mixes an old set with a new one; a rename that itself fails (the
    disk, not a stop) can. The staging folder goes either way."""
    stage = Staging(pathlib.Path(tempfile.mkdtemp(prefix=f".{prefix}-", dir=out)))
    try:
        with naming(out):  # a write's own error (a full disk) names no file: name the folder the set goes into
            yield stage
            raise_if_stopped()
            refuse_folders_in_the_way(out, stage.names)  # before any file of the set moves
    except BaseException:
        shutil.rmtree(stage.folder, ignore_errors=True)
        raise
    with stops_held():
        try:
            for name in stage.names:
                os.replace(stage.folder / name, out / name)
            for name, _ in stage.undrawn:
                (out / name).unlink(missing_ok=True)
        finally:
            shutil.rmtree(stage.folder, ignore_errors=True)


def named_error(error: OSError, filename: pathlib.Path | str) -> OSError:
    """``error`` naming ``filename`` (for the one-line error): the same errno and words, or ``error`` itself
    where it has no errno (a library's own message, which a rebuilt OSError would print as "None")."""
    return error if error.errno is None else OSError(error.errno, error.strerror, str(filename))


@contextlib.contextmanager
def naming(path: pathlib.Path):
    """An OSError of the block that names no file (a write's own: a full disk) names ``path``, so that its
    one-line error says which output could not be written."""
    try:
        yield
    except OSError as error:
        if error.filename is not None:
            raise
        raise named_error(error, path) from None


def refuse_folders_in_the_way(out: pathlib.Path, names) -> None:
    """Raise IsADirectoryError (an OSError naming the path) if any of ``names`` in ``out`` is a folder."""
    for name in names:
        if (out / name).is_dir():
            raise IsADirectoryError(errno.EISDIR, "a folder is in the way of this file", str(out / name))


@contextlib.contextmanager
def stops_held():
    """Hold Ctrl-C, SIGTERM and SIGHUP for the block, then put back the handlers they had and deliver each that
    came, once, in the order they came (each even when an earlier one's handler raised): for a few
    renames that must all happen or none. A handler set outside Python (``None``) comes back as the
    default. Python runs signal handlers in the main thread only, so outside it this holds nothing."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    caught: list[int] = []
    before = {signum: signal.signal(signum, lambda signum, _frame: caught.append(signum)) for signum in STOP_SIGNALS
              if signal.getsignal(signum) is not signal.SIG_IGN}  # an ignored one (``nohup``) stays ignored
    try:
        yield
    finally:
        for signum, handler in before.items():
            signal.signal(signum, signal.SIG_DFL if handler is None else handler)
        _deliver(list(dict.fromkeys(caught)))


def _deliver(signums: list[int]) -> None:
    """Raise each signal in turn, the later ones even if an earlier one's handler raises."""
    if signums:
        try:
            signal.raise_signal(signums[0])
        finally:
            _deliver(signums[1:])


def tell_undrawn(undrawn: list[tuple[str, str]]) -> None:
    """One line on stderr for each figure left out."""
    for name, reason in undrawn:
        print(f"twin: could not draw {name}: {reason}", file=sys.stderr)


DISK_ERRORS = frozenset({errno.ENOSPC, errno.EDQUOT, errno.EIO, errno.EROFS, errno.EACCES, errno.EPERM})


def drawn(draw: Callable[[pathlib.Path], None], path: pathlib.Path,
          undrawn: list[tuple[str, str]]) -> list[pathlib.Path]:
    """``draw(path)``: the figure at ``path``, best effort: ``[path]``, or ``[]`` with (its name, the reason)
    added to ``undrawn`` when the drawing fails. The disk failing (an OSError of :data:`DISK_ERRORS`: full,
    read-only, refused) and a stop (KeyboardInterrupt, which is no Exception) still stop the whole
    publication; any other error, a plotting library's own OSErrors included (a font file, an image
    encoder), only costs the figure."""
    try:
        draw(path)
    except OSError as error:
        if error.errno in DISK_ERRORS:
            raise
        return _left_out(path, error, undrawn)
    except Exception as error:  # noqa: BLE001 - a plotting library's error of any kind must not cost the tables
        return _left_out(path, error, undrawn)
    return [path]


def _left_out(path: pathlib.Path, error: Exception, undrawn: list[tuple[str, str]]) -> list[pathlib.Path]:
    path.unlink(missing_ok=True)
    undrawn.append((path.name, f"{type(error).__name__}: {error}".splitlines()[0]))
    return []
