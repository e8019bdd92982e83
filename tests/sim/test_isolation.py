"""Reproducibility and no leaked global state between twins in one process."""

from __future__ import annotations

import concurrent.futures
import dataclasses

import numpy as np
import pytest

from twin.envs.runner import run, run_many
from twin.physics import chambers, solenoid
from twin.physics.model import Orientation
from twin.plants.as_built import as_built_plant
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


@pytest.mark.slow  # over ~2.5 s on 2 cores (measured 2026-11-26, a later session's slower machine)
def test_an_as_built_batch_whose_ended_runs_stop_gives_the_numbers_of_one_that_runs_them_on(monkeypatch):
    """In a batch the solenoid valves and chambers of a run that has ended stop being advanced (a
    saving); every run's numbers, every trace field, are those of a loop that advances them to the batch's
    end. Two plants, so each plant's scenarios are picked out of the batch's mask."""
    other = as_built_plant(without=("stiction",), name="as-built-without-stiction")
    batch = [Scenario("smc", 2, plant="as-built", seed=4), Scenario("ffpva", 1, plant=other, seed=5),
             Scenario("pva", 2, plant=other, seed=6), Scenario("ffpva", 1, plant="as-built", seed=7)]  # 1, 3, 1, 3 s
    ended = {"valves": 0, "chambers": 0}  # scenario-ticks a compiled loop was told to skip
    openings, substeps = solenoid.tick_openings, chambers._substeps

    def counting_openings(*args):
        ended["valves"] += int(np.count_nonzero(~args[-1]))
        return openings(*args)

    def counting_substeps(*args):
        ended["chambers"] += int(np.count_nonzero(~args[-2]))
        return substeps(*args)

    monkeypatch.setattr(solenoid, "tick_openings", counting_openings)
    monkeypatch.setattr(chambers, "_substeps", counting_substeps)
    idle = run_many(batch)
    assert ended == {"valves": 2 * 2000, "chambers": 2 * 2000}  # the two 1 s runs, for the 3 s runs' last 2 s

    def running_on(**kwargs):
        return PlantState(**{**kwargs, "idle_after_end": False})

    monkeypatch.setattr(simulation, "PlantState", running_on)
    on = run_many(batch)
    assert ended == {"valves": 4000, "chambers": 4000}  # nothing skipped this time
    for a, b in zip(idle, on, strict=True):
        assert len(a.trace.time) == len(b.trace.time)
        for field in dataclasses.fields(a.trace):
            assert np.array_equal(getattr(a.trace, field.name), getattr(b.trace, field.name)), field.name
        assert a.metrics == b.metrics
