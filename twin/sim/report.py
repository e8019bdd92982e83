"""Results at the user-facing edge: degrees, grams, millimetres and kPa."""

from __future__ import annotations

import csv
import io
import math
import pathlib

import numpy as np

from twin.sim.simulation import Result


def summary(result: Result) -> dict:
    """The one-line JSON record of ``twin run --json``."""
    s, m = result.scenario, result.metrics
    return {
        "controller": s.controller,
        "trajectory": s.trajectory,
        "payload_g": round(s.payload * 1e3, 6),
        "orientation": s.orientation.value,
        "plant": s.plant_name,
        "seed": s.seed,
        "noise": s.noise,
        "supply_kpa": round(s.supply / 1e3, 6),
        "rmse_deg": math.degrees(m.rmse),
        "sse_deg": None if math.isnan(m.sse) else math.degrees(m.sse),
        "rest_errors_deg": [math.degrees(e) for e in m.rest_errors],
        "max_error_deg": math.degrees(m.max_error),
        "duration_s": round(float(result.trace.time[-1] + (result.trace.time[1] - result.trace.time[0])), 9),
        "warnings": list(result.warnings),
    }


TRACE_COLUMNS = ("t_s", "theta_d_deg", "theta_deg", "y_mm", "y_measured_mm", "duty_pct",
                 "v1_open", "v2_open", "v3_open", "v4_open", "p_a_kpa", "p_b_kpa", "p_supply_kpa")


def trace_csv(result: Result) -> str:
    """The run's time series as CSV text with :data:`TRACE_COLUMNS`."""
    tr = result.trace
    columns = np.column_stack([
        tr.time, np.degrees(tr.desired_angle), np.degrees(tr.angle), tr.rack_position * 1e3,
        tr.measured_position * 1e3, tr.duty, tr.valve_open.astype(float),
        tr.pressure_a / 1e3, tr.pressure_b / 1e3, tr.supply_pressure / 1e3,
    ])
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(TRACE_COLUMNS)
    for row in columns:
        writer.writerow([f"{x + 0.0:.6g}" for x in row])  # + 0.0: no "-0"
    return out.getvalue()


def write_trace(result: Result, path: pathlib.Path) -> None:
    path.write_text(trace_csv(result))
