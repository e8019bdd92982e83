"""Sweep grids: axes named like the flags of ``twin run``, as comma lists or a TOML file.

    --controller ffpva,smc --trajectory 1,3 --payload 0:13.5:6.75 --seed 0-4

Numbers also take ``start:stop:step`` (stop included when it lands on the
grid); seeds also ``a-b``. Units at this edge: grams, kPa, ms. One physical
scenario is one grid point with one key: repeated values count once, and a
supply pressure or PWM period equal to the plant's becomes None (the plant's).
"""

from __future__ import annotations

import dataclasses
import itertools
import math
import re
import tomllib
from collections.abc import Iterable

from twin.exceptions import InvalidScenario
from twin.physics.model import Orientation
from twin.plants import plant
from twin.sim.scenario import Scenario

AXES = ("controller", "trajectory", "payload", "orientation", "plant", "seed", "supply_kpa", "pwm_period_ms")
DEFAULTS = {"controller": ["ffpva"], "trajectory": [1], "payload": [0.0], "orientation": ["horizontal"],
            "plant": ["thesis"], "seed": [0], "supply_kpa": [None], "pwm_period_ms": [None]}
MAX_POINTS = 100_000  # scenarios in one sweep (about 3 days of 4 s runs on 2 cores)
NUMERIC = {"payload": float, "supply_kpa": float, "pwm_period_ms": float, "trajectory": int, "seed": int}


PLAIN_NUMBER = re.compile(r"\s*[+-]?(?:(?:\d+\.?\d*|\.\d+)(?:e[+-]?\d+)?|inf(?:inity)?|nan)\s*",
                          re.ASCII | re.IGNORECASE)


def plain_number(text: str, kind: type = float) -> int | float:
    """``kind(text)`` (int or float) for a number written as people write one: ASCII digits, a point, an
    exponent (and inf or nan, for the caller's range check to name). ValueError for Python's other
    spellings, which a user hardly means: ``5_0`` (50), full-width or other scripts' digits."""
    if not PLAIN_NUMBER.fullmatch(text):
        raise ValueError(f"not a plainly written number: {text!r}")
    return kind(text)


def _whole(value: float) -> int:
    if not value.is_integer():
        raise ValueError(f"{value!r} is not a whole number")
    return int(value)


def _number(text: str, kind: type) -> int | float:
    """``kind`` from ``text``; an int axis takes ``"3"`` or ``"3.0"`` but refuses ``"2.7"`` (never truncates)."""
    if kind is int:
        try:
            return plain_number(text, int)
        except ValueError:
            return _whole(plain_number(text))
    value = plain_number(text)
    if not math.isfinite(value):  # 1e400 too: named as written, not as the inf it became
        raise ValueError(f"not a finite number: {text!r}")
    return value + 0.0  # + 0.0 turns -0.0 into 0.0: one value, one key


def _range(text: str, kind: type, flag: str) -> list:
    parts = text.split(":")
    if len(parts) != 3:
        raise InvalidScenario(f"bad range {text!r} for {flag}: a range is start:stop:step")
    start, stop, step = (plain_number(p) for p in parts)
    if not all(math.isfinite(x) for x in (start, stop, step)):
        raise InvalidScenario(f"bad range {text!r} for {flag}: start, stop and step must be finite")
    if step <= 0:
        raise InvalidScenario(f"bad range {text!r} for {flag}: step must be positive")
    if stop < start:
        raise InvalidScenario(f"bad range {text!r} for {flag}: stop before start")
    span = (stop - start) / step  # inf when a tiny step overflows it
    if not span + 1 <= MAX_POINTS:
        size = f"{int(span) + 1:,} values" if span < 1e12 else "over a trillion values"
        raise InvalidScenario(f"range {text!r} for {flag} has {size}: more than the {MAX_POINTS:,} "
                              "scenarios a sweep takes")
    count = int(math.floor(span + 1e-9)) + 1
    values = [round(start + i * step, 12) + 0.0 for i in range(count)]
    return [_whole(v) for v in values] if kind is int else values


def parse_axis(name: str, value) -> list:
    """One axis from a flag string (``"0,6.5,13.5"``, ``"0:30:5"``, ``"0-4"``) or a TOML list."""
    if name not in AXES:
        raise InvalidScenario(f"unknown sweep axis {name!r}: choose from {', '.join(AXES)}")
    items: Iterable = value if isinstance(value, list) else str(value).split(",")
    kind = NUMERIC.get(name, str)
    out: dict = {}  # the distinct values in the order given ("0,0" is one value)
    for item in items:
        text = str(item).strip()
        flag = f"--{name.replace('_', '-')}"
        try:
            if kind is not str and ":" in text:
                out.update(dict.fromkeys(_range(text, kind, flag)))
            elif name == "seed" and "-" in text.lstrip("-"):
                low, high = (plain_number(x, int) for x in text.split("-"))
                if high < low:
                    raise InvalidScenario(f"bad range {text!r} for {flag}: stop before start")
                if high - low + 1 > MAX_POINTS:
                    raise InvalidScenario(f"range {text!r} for {flag} has {high - low + 1:,} values: more than "
                                          f"the {MAX_POINTS:,} scenarios a sweep takes")
                out.update(dict.fromkeys(range(low, high + 1)))
            else:
                out[kind(text) if kind is str else _number(text, kind)] = None
            if len(out) > MAX_POINTS:  # many ranges, each under the cap: their distinct values refused together
                raise InvalidScenario(f"{flag} has more than the {MAX_POINTS:,} values a sweep takes")
        except InvalidScenario:
            raise
        except ValueError:
            expected = {int: ": expected whole numbers", float: ": expected finite numbers"}.get(kind, "")
            raise InvalidScenario(f"bad value {text!r} for --{name.replace('_', '-')}{expected}") from None
    if not out:
        raise InvalidScenario(f"--{name.replace('_', '-')} is empty")
    return list(out)


CONFIG_MAX_BYTES = 1_000_000  # a grid's TOML is a few lines


def read_toml(path) -> dict[str, list]:
    """Axes from a TOML file: top-level keys or a ``[grid]`` table, named like the flags."""
    try:
        with open(path, "rb") as handle:
            raw = handle.read(CONFIG_MAX_BYTES + 1)  # no more: /dev/zero or a huge file must not fill the memory
    except OSError as error:
        raise InvalidScenario(f"cannot read --config {str(path)!r}: {error.strerror}") from None
    if len(raw) > CONFIG_MAX_BYTES:
        raise InvalidScenario(f"--config {str(path)!r} is over {CONFIG_MAX_BYTES // 1_000_000} MB: not a grid")
    try:
        data = tomllib.loads(raw.decode("utf-8"))
    except ValueError as error:  # TOMLDecodeError, or bytes that are not UTF-8
        raise InvalidScenario(f"--config {str(path)!r} is not valid TOML: {error}") from None
    table = data.get("grid", data)
    if not isinstance(table, dict):
        raise InvalidScenario(f"--config {str(path)!r}: [grid] must be a table of axes")
    if table is not data and len(data) > 1:  # keys beside [grid] were ignored silently until stop 60
        beside = sorted(key for key in data if key != "grid")
        raise InvalidScenario(f"--config {str(path)!r}: axes go either at the top or under [grid], not both "
                              f"(found {', '.join(beside)} beside [grid])")
    if not table:
        raise InvalidScenario(f"--config {str(path)!r} names no axes: give at least one, e.g. seed = [0, 1, 2]")
    axes: dict[str, list] = {}
    for key, value in table.items():
        name = key.replace("-", "_")
        if name in axes:  # supply_kpa and supply-kpa: one was dropped silently until stop 60
            raise InvalidScenario(f"--config {str(path)!r}: the axis {name} is given twice ({key!r} and its other "
                                  "spelling)")
        axes[name] = parse_axis(name, value)
    return axes


@dataclasses.dataclass(frozen=True)
class GridPoint:
    """One scenario of a sweep, in edge units, with a stable key."""

    controller: str
    trajectory: int
    payload_g: float
    orientation: str
    plant: str
    seed: int
    supply_kpa: float | None
    pwm_period_ms: float | None

    @property
    def key(self) -> str:
        return "|".join(str(v) for v in dataclasses.astuple(self))

    def scenario(self) -> Scenario:
        return Scenario(controller=self.controller, trajectory=self.trajectory, payload=self.payload_g / 1e3,
                        orientation=_orientation(self.orientation), plant=self.plant, seed=self.seed,
                        supply_pressure=None if self.supply_kpa is None else self.supply_kpa * 1e3,
                        pwm_period=None if self.pwm_period_ms is None else self.pwm_period_ms / 1e3)


def _orientation(text: str) -> Orientation:
    try:
        return Orientation(text)
    except ValueError:
        choices = ", ".join(o.value for o in Orientation)
        raise InvalidScenario(f"unknown orientation {text!r}: choose one of {choices}") from None


def _without_plant_defaults(point: GridPoint) -> GridPoint:
    """``point`` with a supply pressure or PWM period equal to its plant's set to None (the plant's), so
    that a scenario has one key whether or not its plant's value was given explicitly."""
    params = plant(point.plant).params
    scenario = point.scenario()
    return dataclasses.replace(
        point,
        supply_kpa=None if scenario.supply_pressure == params.supply.pressure else point.supply_kpa,
        pwm_period_ms=None if scenario.pwm_period == params.valves.pwm_period else point.pwm_period_ms,
    )


def grid_size(axes: dict[str, list]) -> int:
    """Scenarios the axes span before duplicates are merged (defaults count once)."""
    return math.prod(len(values) for values in {**DEFAULTS, **axes}.values())


def expand(axes: dict[str, list]) -> list[GridPoint]:
    """Every distinct combination, in a fixed order; each checked by building its Scenario. A grid of
    more than MAX_POINTS scenarios is refused before any is built."""
    size = grid_size(axes)
    if size > MAX_POINTS:
        raise InvalidScenario(f"the grid has {size:,} scenarios: more than the {MAX_POINTS:,} a sweep takes")
    merged = {**DEFAULTS, **axes}
    points = (GridPoint(*combo) for combo in itertools.product(*(merged[a] for a in AXES)))
    return list(dict.fromkeys(_without_plant_defaults(p) for p in points))  # scenario() names a bad value
