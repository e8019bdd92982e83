"""Argument types of the command line, in edge units (degrees, grams, kPa, ms): each parses one
flag's text or raises ``argparse.ArgumentTypeError`` with a one-line reason. The CLI and the
experiments' own flags share them."""

from __future__ import annotations

import argparse
import math
import os
import pathlib
import tempfile

from twin.batch.grid import plain_number
from twin.sim.scenario import MAX_SEED

MAX_SEEDS = 1000  # noise seeds per case a command takes (a what-if's cells times 1000 is already a day's work)
MAX_WORKERS = 4 * len(os.sched_getaffinity(0))  # local processes a command may start: more only queue for the
# cores this process may use


def writable_file(suffix: str):
    """An argparse type for an output file with ``suffix`` in an existing, writable folder."""
    def check(text: str) -> pathlib.Path:
        path = pathlib.Path(text)
        if path.suffix.lower() != suffix or not path.stem:
            raise argparse.ArgumentTypeError(f"{text!r} must be a file name ending in {suffix}")
        if path.parent.exists() and not path.parent.is_dir():
            raise argparse.ArgumentTypeError(f"{str(path.parent)!r} of {text!r} is a file, not a folder")
        if not path.parent.is_dir():
            raise argparse.ArgumentTypeError(f"folder {str(path.parent)!r} of {text!r} does not exist")
        if path.is_dir():
            raise argparse.ArgumentTypeError(f"{text!r} is a folder, not a file")
        if not os.access(path.parent, os.W_OK) or (path.exists() and not os.access(path, os.W_OK)) \
                or not can_create_in(path.parent):
            raise argparse.ArgumentTypeError(f"cannot write {text!r}")
        return path

    return check


def can_create_in(folder: pathlib.Path) -> bool:
    """Whether a file can be made in ``folder``, tried rather than asked: ``os.access`` says yes to root
    for folders no one can write to (``/proc``), and an output is written only after the work."""
    try:
        with tempfile.TemporaryFile(dir=folder):
            return True
    except OSError:
        return False


def checked(kind: type, accept, requirement: str):
    """An argparse type: parse with ``kind``, keep it if ``accept(value)``, else name the bad text."""
    def parse(text: str):
        try:
            value = plain_number(text, kind)
        except ValueError:  # not a number (``5_0`` neither); or an integer of over 4300 digits
            value = None
        # An int is always finite, and too long a one would overflow math.isfinite's float.
        if value is None or (isinstance(value, float) and not math.isfinite(value)) or not accept(value):
            raise argparse.ArgumentTypeError(f"{requirement}, got {text!r}")
        return value

    return parse


def _named(text: str, what: str, hint: str = "") -> str:
    """``text``, unless it is blank: then a one-line error that ``what`` must be named (``hint``: how)."""
    if not text.strip():
        raise argparse.ArgumentTypeError(f"{what} must be named{hint}, got ''")
    return text


def out_dir(text: str) -> pathlib.Path:
    """An output folder: created later, so only its parent must exist."""
    _named(text, "the output folder")
    path = pathlib.Path(text)
    if not path.parent.exists():
        raise argparse.ArgumentTypeError(f"folder {str(path.parent)!r} does not exist")
    if path.exists() and not path.is_dir():
        raise argparse.ArgumentTypeError(f"{text!r} is a file, not a folder")
    return path


def named_path(text: str) -> pathlib.Path:
    """An input file or folder: named, since ``pathlib.Path("")`` is the current folder (a probe, 2026-12-08)."""
    return pathlib.Path(_named(text, "the path"))


def ray_address(text: str) -> str:
    """``--ray-address``: named; an empty one read as "not given" and ran on RAY_ADDRESS or a local Ray."""
    return _named(text, "the address", " (HOST:PORT, ray://HOST:PORT, auto or local)")


grams = checked(float, lambda v: v >= 0, "payload must be a non-negative number of grams")
kpa = checked(float, lambda v: 0 < v <= 700, "supply pressure must be in (0, 700] kPa (cylinder rating)")
seed = checked(int, lambda v: 0 <= v <= MAX_SEED, "seed must be an integer from 0 to 2^63 - 1")
positive_int = checked(int, lambda v: v >= 1, "expected a positive integer")
seed_count = checked(int, lambda v: 1 <= v <= MAX_SEEDS, f"seeds per case must be an integer from 1 to {MAX_SEEDS}")
workers = checked(int, lambda v: 1 <= v <= MAX_WORKERS,
                  f"workers must be an integer from 1 to {MAX_WORKERS} (four per core)")
port = checked(int, lambda v: 0 <= v <= 65535, "port must be an integer in [0, 65535]")
speed = checked(float, lambda v: 0 < v <= 10, "speed must be in (0, 10] times real time")
seconds = checked(float, lambda v: v > 0, "duration must be a positive number of seconds")
trajectory = checked(int, lambda v: 1 <= v <= 4, "trajectory must be 1, 2, 3 or 4")
kpa_number = checked(float, lambda v: True, "expected a number of kPa")  # its range: the command's check


def host(text: str) -> str:
    """``--host``: a name or address, not empty (which listened on every interface, unsaid) nor padded."""
    if not text or text.strip() != text:
        raise argparse.ArgumentTypeError(f"give a host name or address to listen on (0.0.0.0 for every interface), "
                                         f"got {text!r}")
    return text
