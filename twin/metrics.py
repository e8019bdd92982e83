"""Tracking metrics of §7, computed on the output angle error e = theta_d - theta."""

from __future__ import annotations

import dataclasses

import numpy as np


@dataclasses.dataclass(frozen=True)
class Metrics:
    rmse: float  # rad, sqrt(mean(e^2)) over the run (eq. 5.2.8)
    sse: float  # rad, the error at the end of the run (signed)
    max_error: float  # rad, max |e|


def tracking_metrics(desired: np.ndarray, actual: np.ndarray) -> Metrics:
    """Metrics of one run; ``desired`` and ``actual`` are (T,) angles in rad."""
    error = desired - actual
    return Metrics(rmse=float(np.sqrt(np.mean(error**2))), sse=float(error[-1]),
                   max_error=float(np.max(np.abs(error))))
