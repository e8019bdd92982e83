"""Sweep grids: axes named like the flags of ``twin run``, as comma lists or a TOML file.

    --controller ffpva,smc --trajectory 1,3 --payload 0:13.5:6.75 --seed 0-4

Numbers also take ``start:stop:step`` (stop included when it lands on the
grid); seeds also ``a-b``. Units at this edge: grams, kPa, ms.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
import tomllib
from collections.abc import Iterable

from twin.exceptions import InvalidScenario
from twin.model import Orientation
from twin.scenario import Scenario

AXES = ("controller", "trajectory", "payload", "orientation", "plant", "seed", "supply_kpa", "pwm_period_ms")
DEFAULTS = {"controller": ["ffpva"], "trajectory": [1], "payload": [0.0], "orientation": ["horizontal"],
            "plant": ["thesis"], "seed": [0], "supply_kpa": [None], "pwm_period_ms": [None]}
NUMERIC = {"payload": float, "supply_kpa": float, "pwm_period_ms": float, "trajectory": int, "seed": int}


def _range(text: str, kind: type) -> list:
    parts = text.split(":")
    if len(parts) != 3:
        raise InvalidScenario(f"a range is start:stop:step, got {text!r}")
    start, stop, step = (float(p) for p in parts)
    if step <= 0 or stop < start:
        raise InvalidScenario(f"a range needs step > 0 and stop >= start, got {text!r}")
    count = int(math.floor((stop - start) / step + 1e-9)) + 1
    return [kind(round(start + i * step, 12)) for i in range(count)]


def parse_axis(name: str, value) -> list:
    """One axis from a flag string (``"0,6.5,13.5"``, ``"0:30:5"``, ``"0-4"``) or a TOML list."""
    if name not in AXES:
        raise InvalidScenario(f"unknown sweep axis {name!r}: choose from {', '.join(AXES)}")
    items: Iterable = value if isinstance(value, list) else str(value).split(",")
    kind = NUMERIC.get(name, str)
    out: list = []
    for item in items:
        text = str(item).strip()
        try:
            if kind is not str and ":" in text:
                out += _range(text, kind)
            elif name == "seed" and "-" in text.lstrip("-"):
                low, high = (int(x) for x in text.split("-"))
                out += list(range(low, high + 1))
            else:
                out.append(kind(float(text)) if kind is int else kind(text))
        except ValueError:
            raise InvalidScenario(f"bad value {text!r} for --{name.replace('_', '-')}") from None
    if not out:
        raise InvalidScenario(f"--{name.replace('_', '-')} is empty")
    return out


def read_toml(path) -> dict[str, list]:
    """Axes from a TOML file: top-level keys or a ``[grid]`` table, named like the flags."""
    with open(path, "rb") as handle:
        data = tomllib.load(handle)
    table = data.get("grid", data)
    return {key.replace("-", "_"): parse_axis(key.replace("-", "_"), value) for key, value in table.items()}


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
                        orientation=Orientation(self.orientation), plant=self.plant, seed=self.seed,
                        supply_pressure=None if self.supply_kpa is None else self.supply_kpa * 1e3,
                        pwm_period=None if self.pwm_period_ms is None else self.pwm_period_ms / 1e3)


def expand(axes: dict[str, list]) -> list[GridPoint]:
    """Every combination, in a fixed order; each checked by building its Scenario."""
    merged = {**DEFAULTS, **axes}
    points = [GridPoint(*combo) for combo in itertools.product(*(merged[a] for a in AXES))]
    for p in points:
        p.scenario()  # raises InvalidScenario naming the bad value
    return points
