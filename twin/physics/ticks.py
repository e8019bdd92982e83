"""Integer tick counting: every period in the twin is a whole number of physics ticks."""

from __future__ import annotations

import math

from twin.exceptions import InvalidScenario, TwinError


def whole_ticks(duration: float, tick: float, *, what: str = "period",
                error: type[TwinError] = InvalidScenario) -> int:
    """``duration / tick`` as an int, or ``error`` if it is not a positive whole number."""
    ticks = duration / tick
    if not (duration > 0 and math.isfinite(ticks) and abs(ticks - round(ticks)) <= 1e-9):  # nan and inf too
        raise error(f"{what} of {duration} s is not a whole number of {tick} s ticks")
    return int(round(ticks))
