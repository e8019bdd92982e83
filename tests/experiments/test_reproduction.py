"""The thesis's simulated results (SPEC §8) against the 'thesis' plant, mean over seeds 0-4.

Nothing in the twin is tuned to these numbers; this checks how close the twin
lands and records where it does not (see docs/reproduction.md).
"""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest

from twin.envs.runner import run_many
from twin.experiments.reference import THESIS_SIMULATED_RMSE_DEG
from twin.sim.scenario import Scenario

SEEDS = range(5)
TOLERANCE_DEG = 0.35  # issue "The twin, end to end"


@functools.cache
def _results(controller: str) -> dict[int, list]:
    results = run_many([Scenario(controller, t, seed=s) for t in (1, 2, 3, 4) for s in SEEDS])
    by_trajectory: dict[int, list] = {}
    for r in results:
        by_trajectory.setdefault(r.scenario.trajectory, []).append(r)
    return by_trajectory


def _mean_rmse_deg(controller: str, trajectory: int) -> float:
    return float(np.mean([math.degrees(r.metrics.rmse) for r in _results(controller)[trajectory]]))


@pytest.mark.parametrize("trajectory", [1, 2, 3, 4])
def test_ffpva_mean_rmse_is_within_0_35_deg_of_the_thesis_simulation(trajectory):
    twin = _mean_rmse_deg("ffpva", trajectory)
    thesis = THESIS_SIMULATED_RMSE_DEG["ffpva"][trajectory]
    assert abs(twin - thesis) <= TOLERANCE_DEG, f"T{trajectory}: twin {twin:.2f} deg, thesis {thesis:.2f} deg"


@pytest.mark.parametrize("controller", ["pva", "ffpva", "smc"])
def test_every_thesis_run_finishes_without_warnings_and_tracks(controller):
    for trajectory, results in _results(controller).items():
        for r in results:
            assert r.warnings == ()
            assert math.degrees(r.metrics.max_error) < 10.0, (controller, trajectory)


def test_feed_forward_beats_the_pva_baseline_on_every_trajectory():
    """The thesis's ordering of model-based control over PVA + DZC (§8)."""
    for trajectory in (1, 2, 3, 4):
        assert _mean_rmse_deg("ffpva", trajectory) < _mean_rmse_deg("pva", trajectory)
