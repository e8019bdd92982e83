"""Breakaway force that varies along the stroke (as-built; SPEC §4 stiction, §10 future work 2).

SPEC §4 gives only an average static friction (3.6 N) over a fit "with large
scatter". The as-built joint draws one map per joint:

    F_s(y) = max(F_s0 + s u_k, 0)  at knots y_k = y_0 + k dy (and y_k = y_1 last),
    u_k ~ U[-1, 1] from ``seed``,

piecewise linear between knots and held at the end values outside the stroke.
s = 0 gives the constant F_s0. Forces in N, positions in m.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from twin.exceptions import InvalidParameter
from twin.physics.params import StictionMapParams


class StictionMap:
    """F_s(y) in N: ``StictionMap(params, base=F_s0 [N], stroke=(y_0, y_1) [m])``, then ``map(y)``."""

    def __init__(self, params: StictionMapParams, base: float, stroke: tuple[float, float]) -> None:
        if not (base >= 0 and math.isfinite(base)):
            raise InvalidParameter(f"base stiction must be >= 0 and finite, got {base!r}")
        low, high = (float(v) for v in stroke)
        if not (math.isfinite(low) and math.isfinite(high) and high > low):
            raise InvalidParameter(f"stroke must be finite with stroke[1] > stroke[0], got {stroke!r}")
        # Rounding keeps a float ratio such as 20.000000000000004 from adding a sliver interval.
        intervals = math.ceil(round((high - low) / params.knot_spacing, 9))
        knots = np.append(low + params.knot_spacing * np.arange(intervals), high)  # m, (K,)
        if params.seed is None:
            raise InvalidParameter("a stiction map needs a seed (StictionMaps gives each run its own)")
        u = np.random.default_rng(params.seed).uniform(-1.0, 1.0, knots.size)
        self.base = float(base)  # N
        self.scatter = params.scatter  # N
        self.knots = knots  # m, (K,) increasing
        self.values = np.maximum(self.base + self.scatter * u, 0.0)  # N, (K,)
        self.knots.flags.writeable = False
        self.values.flags.writeable = False

    def __call__(self, y: np.ndarray) -> np.ndarray:
        """Breakaway force F_s(y) >= 0 in N at rack positions ``y`` (m, any shape)."""
        if self.scatter == 0.0:
            return np.full(np.shape(y), self.base)
        return np.interp(y, self.knots, self.values)


class StictionMaps:
    """One :class:`StictionMap` per scenario, evaluated together: ``maps(y)`` with y (n,) -> (n,) in N.

    ``seeds[i]`` draws scenario i's map, so an ensemble of runs spans the unknown
    map as well as the sensor noise (the thesis gives no map, only its scatter)."""

    def __init__(self, params: StictionMapParams, base: float, stroke: tuple[float, float], seeds) -> None:
        maps = [StictionMap(dataclasses.replace(params, seed=seed), base, stroke) for seed in seeds]
        self.knots = maps[0].knots  # m, (K,), shared
        self.values = np.stack([m.values for m in maps])  # N, (n, K)
        self._rows = np.arange(len(maps))

    def __call__(self, y: np.ndarray) -> np.ndarray:
        knots = self.knots
        y = np.clip(y, knots[0], knots[-1])
        i = np.clip(np.searchsorted(knots, y, side="right") - 1, 0, knots.size - 2)
        t = (y - knots[i]) / (knots[i + 1] - knots[i])
        return self.values[self._rows, i] * (1.0 - t) + self.values[self._rows, i + 1] * t
