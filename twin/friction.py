"""Force loss of the joint (eqs. 4.5.5 and 4.5.7).

    F_l = F_c(y) sgn(v) + F_v v
    F_c(y) = -3.051e14 y^6 + 1.587e13 y^5 - 3.244e11 y^4 + 3.294e9 y^3 - 1.727e7 y^2 + 4.36e4 y - 39.551

*Resolution* (SPEC §4): the fit is sane only on y = 2 - 14.5 mm, so ``y`` is
clamped to that range and ``F_c`` to >= 0. The direction-dependent variant
scales ``F_c`` by ``ccw_coulomb_scale`` when moving towards 0 deg (v < 0).
"""

from __future__ import annotations

import numpy as np

from twin.params import FrictionParams


def coulomb_force(params: FrictionParams, y: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """F_c(y) >= 0 in N, for rack positions ``y`` (m) moving in ``direction`` (sign, (N,))."""
    clamped = np.clip(y, *params.fit_range)
    magnitude = np.maximum(np.polyval(params.coulomb_poly, clamped), 0.0)
    return np.where(direction < 0, params.ccw_coulomb_scale * magnitude, magnitude)


def force_loss(params: FrictionParams, y: np.ndarray, v: np.ndarray) -> np.ndarray:
    """F_l(y, v) = F_c(y) sgn(v) + F_v v in N (eq. 4.5.5), the model the controllers invert."""
    direction = np.sign(v)
    return coulomb_force(params, y, direction) * direction + params.viscous * v
