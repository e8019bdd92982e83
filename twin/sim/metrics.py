"""Tracking metrics of §7, computed on the output angle error e = theta_d - theta."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence

import numpy as np


@dataclasses.dataclass(frozen=True)
class Metrics:
    rmse: float  # rad, sqrt(mean(e^2)) over the run (eq. 5.2.8)
    sse: float  # rad, signed error at the end of the run; nan when the reference ends moving (T3)
    max_error: float  # rad, max |e|
    rest_errors: tuple[float, ...] = ()  # rad, signed error at the end of each rest (T4's four "rests")


def tracking_metrics(desired: np.ndarray, actual: np.ndarray, *, ends_at_rest: bool = True,
                     rest_end_ticks: Sequence[int] = ()) -> Metrics:
    """Metrics of one run; ``desired`` and ``actual`` are (T,) angles in rad sampled every tick;
    ``rest_end_ticks`` index the samples that end each rest."""
    error = desired - actual
    return Metrics(rmse=float(np.sqrt(np.mean(error**2))), sse=float(error[-1]) if ends_at_rest else math.nan,
                   max_error=float(np.max(np.abs(error))),
                   rest_errors=tuple(float(error[min(k, len(error) - 1)]) for k in rest_end_ticks))
