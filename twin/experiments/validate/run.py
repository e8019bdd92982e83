"""One validation run: :func:`validate` runs every comparison and the prediction into a :class:`Validation`."""

from __future__ import annotations

import dataclasses

from twin.experiments import calibrate
from twin.experiments.validate.common import FRESH_SEEDS, SEEDS, stalled_runs
from twin.experiments.validate.comparisons import (
    full_duty_rows,
    max_error_rows,
    measured_rows,
    openloop_rows,
    payload_effects,
    seed_rows,
    simulation_rows,
    valve_rows,
)
from twin.experiments.validate.ensemble import prediction
from twin.experiments.validate.motion import payload_phases, pulse_cycle, sliding_mode_parts


@dataclasses.dataclass
class Validation:
    """What one :func:`validate` found: every file and the report are written from it alone."""

    rows: list[dict]
    prediction: list[dict]
    prediction_detail: dict
    failed: int  # runs with MuJoCo warnings
    stalled: dict  # (controller, trajectory, payload g, orientation) -> stalled runs of the committed preset
    sliding_mode: dict | None = None  # sliding_mode_parts
    pulses: dict | None = None  # pulse_cycle
    seeds: list[dict] | None = None  # seed_rows on FRESH_SEEDS
    max_errors: list[dict] | None = None  # max_error_rows
    full_duty: list[dict] | None = None  # full_duty_rows
    phases: list[dict] | None = None  # payload_phases

    @property
    def effects(self) -> list[dict]:
        """:func:`payload_effects` of :attr:`seeds` ([] when they were not run)."""
        return payload_effects(self.seeds or [])


def validate(*, workers: int = 2, progress=None) -> Validation:
    """Every comparison, then the prediction; ``progress()`` after the simulations, the fitted cells, the
    fresh seeds, the valve, the open loop, the full-duty runs, sliding mode's parts, the pulse cycle, the payload's
    phases and each ensemble member."""
    from twin.plants.as_built import calibrated_values

    step = progress or (lambda: None)
    rows = simulation_rows()
    step()
    committed = calibrated_values()
    with calibrate.Evaluator(seeds=SEEDS, workers=workers) as evaluator:
        cells = evaluator.cells(committed)
        rows += measured_rows(cells)
        step()
        fresh = evaluator.cells(committed, seeds=FRESH_SEEDS)
        seeds = seed_rows(fresh, cells)
        largest = max_error_rows(cells, fresh)
        step()
        rows += valve_rows()
        step()
        lag_rows, study = openloop_rows()
        rows += lag_rows
        step()
        full_duty = full_duty_rows()
        step()
        parts = sliding_mode_parts(committed)
        step()
        pulses = pulse_cycle(committed)
        step()
        phases = payload_phases(committed)
        step()
        predicted, own, detail = prediction(evaluator, committed, progress=step, ran=cells)
    failed = sum(c.failed for c in (*cells, *fresh, *own)) + sum(len(run.warnings) > 0 for run in study.runs)
    failed += sum(run["warnings"] > 0 for r in full_duty for run in r["runs"].values())
    failed += sum(r["failed_runs"] for r in phases)
    return Validation(rows=rows, prediction=predicted, prediction_detail=detail, failed=failed,
                      stalled={c.key: stalled_runs(c) for c in cells}, sliding_mode=parts, pulses=pulses,
                      seeds=seeds, max_errors=largest, full_duty=full_duty, phases=phases)
