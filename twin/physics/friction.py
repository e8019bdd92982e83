"""Force loss of the joint (eqs. 4.5.5 and 4.5.7).

    F_l = F_c(y) sgn(v) + F_v v
    F_c(y) = -3.051e14 y^6 + 1.587e13 y^5 - 3.244e11 y^4 + 3.294e9 y^3 - 1.727e7 y^2 + 4.36e4 y - 39.551

*Resolution* (SPEC §4): the fit is sane only on y = 2 - 14.5 mm, so ``y`` is
clamped to that range and ``F_c`` to >= 0. The direction-dependent variant
scales ``F_c`` by ``ccw_coulomb_scale`` when moving towards 0 deg (v < 0).

The plants add, to the Coulomb force and to the breakaway alike, a dry friction that grows with the load
the gear train carries (``load_friction`` |F_ext|, :func:`load_friction`): the thesis's friction tests
carried no load beyond the train's own, so eq. 4.5.7 holds none of it.
"""

from __future__ import annotations

import functools

import numba
import numpy as np

from twin.physics.params import FrictionParams


@numba.njit(cache=True)
def _coulomb(poly, low, high, ccw_scale, y, direction, out):  # pragma: no cover - compiled
    """Eq. 4.5.7 by Horner's rule (as np.polyval), clamped, per element of the flat ``y``."""
    for i in range(y.shape[0]):
        clamped = min(max(y[i], low), high)
        magnitude = 0.0
        for c in poly:
            magnitude = magnitude * clamped + c
        magnitude = max(magnitude, 0.0)
        out[i] = ccw_scale * magnitude if direction[i] < 0 else magnitude


@functools.lru_cache(maxsize=16)
def _coefficients(params: FrictionParams) -> np.ndarray:
    return np.array(params.coulomb_poly, dtype=float)


def coulomb_force(params: FrictionParams, y: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """F_c(y) >= 0 in N, for rack positions ``y`` (m) moving in ``direction`` (sign); any shapes that
    broadcast. Compiled: it runs every tick of every plant and every feed-forward update."""
    y, direction = np.asarray(y, dtype=float), np.asarray(direction, dtype=float)
    if y.shape != direction.shape:
        y, direction = np.broadcast_arrays(y, direction)
    out = np.empty(y.shape)
    _coulomb(_coefficients(params), float(params.fit_range[0]), float(params.fit_range[1]),
             float(params.ccw_coulomb_scale), np.ascontiguousarray(y).reshape(-1),
             np.ascontiguousarray(direction).reshape(-1), out.reshape(-1))
    return out


def coulomb_level(params: FrictionParams, y: np.ndarray) -> np.ndarray:
    """F_c(y) >= 0 in N moving towards +y, in plain numpy (no compile): eq. 4.5.7 clamped as
    :func:`coulomb_force` does, for closed forms worked out when a module loads."""
    return np.maximum(np.polyval(params.coulomb_poly, np.clip(np.asarray(y, dtype=float), *params.fit_range)), 0.0)


def coulomb_both_ways(params: FrictionParams, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """F_c(y) moving towards +y and towards 0 deg, for the steps that decide the direction inside their
    compiled loops; each the same numbers as :func:`coulomb_force` in that direction."""
    forward = coulomb_force(params, y, np.ones(np.shape(y)))
    return forward, forward * params.ccw_coulomb_scale


def load_friction(params: FrictionParams, load: np.ndarray | float) -> np.ndarray:
    """The dry friction (N, >= 0) that carrying ``load`` (N along the rack: gravity through the gears)
    adds to the train's, in either direction and at rest: ``params.load_friction`` |load|."""
    return params.load_friction * np.abs(np.asarray(load, dtype=float))


def dry_limits(params: FrictionParams, y: np.ndarray, load: np.ndarray | float, static: np.ndarray | float
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The dry friction a step may apply at rack positions ``y`` carrying ``load`` (N, the external force
    along y): Coulomb moving towards +y, Coulomb towards 0 deg, and the breakaway ``static`` (N) at rest,
    each plus the load friction (computed once)."""
    forward, backward = coulomb_both_ways(params, y)
    extra = load_friction(params, load)
    return forward + extra, backward + extra, static + extra


def force_loss(params: FrictionParams, y: np.ndarray, v: np.ndarray) -> np.ndarray:
    """F_l(y, v) = F_c(y) sgn(v) + F_v v in N (eq. 4.5.5), the model the controllers invert."""
    direction = np.sign(v)
    return coulomb_force(params, y, direction) * direction + params.viscous * v
