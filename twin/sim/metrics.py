"""Tracking metrics of §7, computed on the output angle error e = theta_d - theta."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence

import numpy as np

from twin.physics.ticks import whole_ticks
from twin.physics.trajectories import Trajectory


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


LONGEST_LAG = 0.3  # s, the top of delay_for_rmse's search: past any law's on this joint (the rig's laws lag 13-25 ms)


def lagging_metrics(path: Trajectory, delay: float, *, spur_radius: float, timestep: float) -> Metrics:
    """The metrics of a joint that follows ``path`` a fixed ``delay`` (s) behind, at rest at its start before it:
    e(t) = theta_d(t) - theta_d(t - delay), at the run's ticks (``timestep`` apart, as :func:`tracking_metrics`
    reads a run). A ruler for reading measured RMSEs against each other, not a plant: it knows no valve or
    friction."""
    t = np.arange(whole_ticks(path.duration, timestep, what="trajectory")) * timestep
    desired = path.sample(t, spur_radius).position / spur_radius
    lagging = path.sample(t - delay, spur_radius).position / spur_radius
    return tracking_metrics(desired, lagging, ends_at_rest=path.ends_at_rest)


def delay_for_rmse(path: Trajectory, rmse: float, *, spur_radius: float, timestep: float) -> float:
    """s, the delay at which :func:`lagging_metrics` on ``path`` has RMSE ``rmse`` (rad); nan when no delay up to
    :data:`LONGEST_LAG` gives it."""
    from scipy.optimize import brentq  # here, not at the top: every run imports this module, few read a lag

    def gap(delay: float) -> float:
        return lagging_metrics(path, delay, spur_radius=spur_radius, timestep=timestep).rmse - rmse
    low, high = 1e-6, LONGEST_LAG
    if not gap(low) <= 0.0 <= gap(high):
        return math.nan
    return brentq(gap, low, high, xtol=1e-9)


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
