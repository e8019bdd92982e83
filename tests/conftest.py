"""Shared helpers: open-loop runs on custom plants."""

from __future__ import annotations

import contextlib
import dataclasses
import io
import math
import os
import pathlib
import signal
import subprocess
import sys

import pytest

from controllers.open_loop import OpenLoop
from twin.physics.model import Orientation
from twin.physics.params import FrictionParams, JointParams, ValveParams
from twin.physics.valves import ValveModel
from twin.plants import PLANTS, Plant
from twin.sim.scenario import Scenario
from twin.sim.simulation import Result, simulate

R_SPUR = JointParams().gears.spur_radius  # m
AREA = JointParams().cylinder.bore_area  # m^2


def custom_plant(name: str, *, friction: FrictionParams | None = None, valves: ValveParams | None = None,
                 valve_model: ValveModel = ValveModel.AVERAGED) -> Plant:
    base = PLANTS["thesis"]
    params = base.params
    if friction is not None:
        params = dataclasses.replace(params, friction=friction)
    if valves is not None:
        params = dataclasses.replace(params, valves=valves)
    return Plant(name, params, valve_model, base.gain_set)


def open_loop(duty, *, plant: str | Plant = "thesis", trajectory: int = 1, payload: float = 0.0,
              orientation: Orientation = Orientation.HORIZONTAL, supply: float | None = None,
              period: float = 16e-3) -> Result:
    """Run with the duty schedule ``duty(t)`` (or a constant) and no sensor noise.

    The trajectory only sets the start angle and duration: T1 starts at 30 deg
    for 3 s, T3 at 80 deg for 4 s.
    """
    schedule = duty if callable(duty) else (lambda t: duty)
    scenario = Scenario("ffpva", trajectory, payload=payload, orientation=orientation, plant=plant,
                        noise=False, supply_pressure=supply)
    return simulate([scenario], controllers=[OpenLoop(schedule=schedule, tick=1e-3, period=period)])[0]


def deg(x: float) -> float:
    return math.degrees(x)


def pytest_addoption(parser: pytest.Parser) -> None:
    parser.addoption("--every-kept-row", action="store_true",
                     help="the two longest kept-result reruns (tests/experiments/test_trials_refits.py's start refit, "
                          "test_trials_effects.py's chambers) run every kept file and row, not CI's few "
                          "(docs/testing.md says which, and how much longer that takes)")


@pytest.fixture
def every_kept_row(request: pytest.FixtureRequest) -> bool:
    """Whether ``--every-kept-row`` was given: a rerun of kept results runs all of them, not CI's subset."""
    return request.config.getoption("--every-kept-row")


@pytest.fixture
def ctrl_c_as_in_a_terminal():
    """SIGINT raising KeyboardInterrupt for the test, as in a terminal, whatever started pytest: a background job
    of a non-interactive shell (``cmd &`` in a script) starts with SIGINT ignored, Python then leaves it ignored,
    and `twin` rightly keeps an ignored SIGINT ignored (as under ``nohup``), so a test sending one would see
    nothing. Put back afterwards."""
    before = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, before)


@pytest.fixture
def frictionless() -> Plant:
    return custom_plant("frictionless", friction=FrictionParams(
        viscous=45.9, coulomb_poly=(0.0,), stiction=0.0))


def listening_addresses(port: int) -> set[str]:
    """Local addresses in LISTEN state on ``port``, read from /proc/net/tcp and tcp6."""
    found = set()
    for name in ("tcp", "tcp6"):
        table = pathlib.Path("/proc/net") / name
        if not table.exists():
            continue
        for line in table.read_text().splitlines()[1:]:
            local, state = line.split()[1], line.split()[3]
            address, hex_port = local.split(":")
            if int(hex_port, 16) != port or state != "0A":
                continue
            if len(address) == 8:
                found.add(".".join(str(b) for b in reversed(bytes.fromhex(address))))
            else:
                found.add(address)
    return found


def twin_in_process(cwd: pathlib.Path, *args: str) -> subprocess.CompletedProcess:
    """``twin ARGS`` in ``cwd``, run by :func:`twin.cli.main` in this process: for refusals, which must
    exit 2 with one line before running anything, without paying a new interpreter's imports (1.5-2 s a
    call). Runs that go through the installed entry point use each file's subprocess form. Unlike a new
    interpreter it does not see Python's warnings on stderr (pytest collects them)."""
    from twin.cli import main

    out, err, here = io.StringIO(), io.StringIO(), os.getcwd()
    os.chdir(cwd)
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                code = main(list(args))
            except SystemExit as stop:  # argparse's refusals; otherwise as the interpreter reads sys.exit's code
                if stop.code is None or isinstance(stop.code, int):
                    code = stop.code or 0
                else:
                    print(stop.code, file=sys.stderr)
                    code = 1
    finally:
        os.chdir(here)
    return subprocess.CompletedProcess(["twin", *args], code, out.getvalue(), err.getvalue())
