"""Reproducibility and no leaked global state between twins in one process."""

from __future__ import annotations

import concurrent.futures

import numpy as np
import pytest

from twin.envs.runner import run, run_many
from twin.physics.model import Orientation
from twin.sim import simulation
from twin.sim.plant_state import PlantState
from twin.sim.scenario import Scenario

A = Scenario("ffpva", 1, seed=0)
B = Scenario("smc", 3, payload=13.5e-3, orientation=Orientation.VERTICAL, seed=1)


def _same(r1, r2) -> bool:
    return all(np.array_equal(getattr(r1.trace, f), getattr(r2.trace, f))
               for f in ("angle", "duty", "pressure_a", "valve_open"))


def test_same_scenario_and_seed_give_the_same_numbers():
    assert _same(run(A), run(A))


def test_different_seeds_give_different_noise():
    assert not np.array_equal(run(A).trace.measured_position, run(Scenario("ffpva", 1, seed=1)).trace.measured_position)


@pytest.mark.slow  # over ~2.5 s on 2 cores (measured 2026-11-26)
def test_two_twins_with_different_models_do_not_cross_talk():
    alone_a, alone_b = run(A), run(B)
    together = run_many([A, B])
    assert _same(alone_a, together[0]) and _same(alone_b, together[1])
    assert _same(alone_a, run(A))  # nothing left behind by B


@pytest.mark.slow  # over ~2.5 s on 2 cores (measured 2026-11-26)
def test_two_twins_in_parallel_threads_match_each_alone():
    alone_a, alone_b = run(A), run(B)
    with concurrent.futures.ThreadPoolExecutor(max_workers=2) as pool:
        fa, fb = pool.submit(run, A), pool.submit(run, B)
        assert _same(fa.result(), alone_a) and _same(fb.result(), alone_b)


def test_batching_does_not_change_a_scenario():
    batch = run_many([Scenario("pva", t, seed=s) for t in (1, 2) for s in (0, 1)])
    single = run(Scenario("pva", 2, seed=1))
    assert _same(batch[3], single)



def test_an_as_built_batch_whose_ended_runs_stop_gives_the_numbers_of_one_that_runs_them_on(monkeypatch):
    """In a batch the solenoid valves and chambers of a run that has ended stop being advanced (a
    saving); every run's numbers are those of a loop that advances them to the batch's end."""
    batch = [Scenario("smc", 2, plant="as-built", seed=4), Scenario("ffpva", 1, plant="as-built", seed=5),
             Scenario("pva", 2, plant="as-built", seed=6)]  # 1 s, 3 s, 1 s
    idle = run_many(batch)

    def running_on(**kwargs):
        return PlantState(**{**kwargs, "idle_after_end": False})

    monkeypatch.setattr(simulation, "PlantState", running_on)
    on = run_many(batch)
    fields = ("angle", "duty", "pressure_a", "pressure_b", "supply_pressure", "valve_open", "velocity",
              "estimated_velocity")
    for a, b in zip(idle, on, strict=True):
        assert len(a.trace.angle) == len(b.trace.angle)
        assert all(np.array_equal(getattr(a.trace, f), getattr(b.trace, f)) for f in fields)
        assert a.metrics == b.metrics
