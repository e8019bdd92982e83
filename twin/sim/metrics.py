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


@dataclasses.dataclass(frozen=True)
class Spread:
    """Summary statistics of one metric over repeated runs (the thesis's "mean ± std of 5 runs")."""

    n: int
    mean: float
    std: float  # sample std (ddof 1), as the thesis's tables give it; 0 for a single run
    min: float
    max: float


def spread(values: Sequence[float]) -> Spread:
    """The one summary of repeated runs: every table of the twin (demo, sweep summaries, studies,
    calibration) takes its mean, std and range from here. nan values propagate."""
    array = np.asarray(values, dtype=float)
    return Spread(n=len(array), mean=float(np.mean(array)), std=sample_std(array),
                  min=float(np.min(array)), max=float(np.max(array)))


def sample_std(values: Sequence[float]) -> float:
    """The std of runs as the thesis's tables give it (ddof 1); 0 for a single run."""
    return float(np.std(values, ddof=1)) if len(values) > 1 else 0.0
