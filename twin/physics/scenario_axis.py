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


def selector(idx: np.ndarray) -> slice | np.ndarray:
    """The scenarios ``idx`` (ascending) as a slice when they are one contiguous run, else ``idx``:
    slicing makes views, where an index array copies, so the per-tick loop indexes a run cheaply."""
    idx = np.asarray(idx)
    if len(idx) and idx[-1] - idx[0] == len(idx) - 1 and np.all(np.diff(idx) == 1):
        return slice(int(idx[0]), int(idx[-1]) + 1)
    return idx
