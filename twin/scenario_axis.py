"""Arrays with a leading scenario axis, as the compiled per-tick loops take them."""

from __future__ import annotations

import numpy as np


def per_scenario(x, n: int, dtype=float) -> np.ndarray:
    """``x`` as a contiguous (n,) array for a compiled loop that reads x[i] unchecked: a scalar is
    the same for every scenario; any shape other than (n,) is an error."""
    if np.ndim(x) == 0:
        return np.full(n, x, dtype=dtype)
    x = np.ascontiguousarray(x, dtype=dtype)
    if x.shape != (n,):
        raise ValueError(f"expected one value per scenario, shape ({n},), got {x.shape}")
    return x
