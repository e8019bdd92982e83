"""The messages a ``twin view`` page may send, and their checks.

Every message is one JSON object with a ``type``; anything else (bad JSON, an
unknown type, a missing or mistyped field, a value out of range) raises
:class:`BadMessage`, whose text the page shows. Units at this edge are the
user's: degrees and grams.
"""

from __future__ import annotations

import dataclasses
import json
import math

from twin.physics.model import Orientation
from twin.sim.scenario import CONTROLLER_NAMES

TARGET_RANGE_DEG = (0.0, 180.0)
PAYLOAD_RANGE_G = (0.0, 50.0)
MAX_MESSAGE_BYTES = 1024


class BadMessage(ValueError):
    """A message from the page that the session refuses; its text says why."""


@dataclasses.dataclass(frozen=True)
class Target:
    angle: float  # rad


@dataclasses.dataclass(frozen=True)
class PlayTrajectory:
    number: int


@dataclasses.dataclass(frozen=True)
class SwitchController:
    name: str


@dataclasses.dataclass(frozen=True)
class Rebuild:
    """A new model: payload (kg) or orientation; the run restarts."""

    payload: float | None = None
    orientation: Orientation | None = None


def _number(message: dict, field: str, low: float, high: float, unit: str) -> float:
    value = message.get(field)
    try:
        number = float(value) if isinstance(value, int | float) and not isinstance(value, bool) else math.nan
    except OverflowError:  # an integer too large for a float
        number = math.inf
    if math.isnan(number):
        got = ("nothing (a browser sends Infinity and NaN as null)" if value is None else repr(str(value)[:40]))
        raise BadMessage(f"{message['type']}: {field} must be a number, got {got}")
    if not low <= number <= high:
        raise BadMessage(f"{message['type']}: {field} must be in [{low:g}, {high:g}] {unit}, got {str(value)[:40]}")
    return number


def _choice(message: dict, field: str, choices) -> str:
    value = message.get(field)
    if value not in choices:
        raise BadMessage(f"{message['type']}: {field} must be one of {', '.join(map(str, choices))}, got {value!r}")
    return value


def parse(text: str | bytes) -> Target | PlayTrajectory | SwitchController | Rebuild:
    """The checked command in one message from the page."""
    size = len(text.encode("utf-8")) if isinstance(text, str) else len(text)
    if size > MAX_MESSAGE_BYTES:
        raise BadMessage(f"message too long ({size} bytes, at most {MAX_MESSAGE_BYTES})")
    try:
        message = json.loads(text)
    except (ValueError, UnicodeDecodeError, RecursionError):  # RecursionError: "[[[[..." nested past the stack
        raise BadMessage("message is not JSON") from None
    if not isinstance(message, dict):
        raise BadMessage("message must be a JSON object")
    kind = message.get("type")
    if kind == "target":
        return Target(math.radians(_number(message, "angle_deg", *TARGET_RANGE_DEG, "deg")))
    if kind == "trajectory":
        number = message.get("number")
        if isinstance(number, bool) or number not in (1, 2, 3, 4):
            raise BadMessage(f"trajectory: number must be 1, 2, 3 or 4, got {number!r}")
        return PlayTrajectory(int(number))
    if kind == "controller":
        return SwitchController(_choice(message, "name", CONTROLLER_NAMES))
    if kind == "payload":
        return Rebuild(payload=_number(message, "grams", *PAYLOAD_RANGE_G, "g") / 1e3)
    if kind == "orientation":
        return Rebuild(orientation=Orientation(_choice(message, "value", [o.value for o in Orientation])))
    raise BadMessage(f"unknown message type {kind!r}: target, trajectory, controller, payload or orientation")
