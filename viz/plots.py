"""Static plots of runs, in the style of the thesis's figures (degrees at this edge)."""

from __future__ import annotations

import math
import pathlib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from twin.sim.simulation import Result  # noqa: E402


def title(result: Result) -> str:
    s = result.scenario
    return (f"{s.controller.upper()}  T{s.trajectory}  plant={s.plant_name}  payload={s.payload * 1e3:g} g  "
            f"{s.orientation.value}  seed={s.seed}")


def plot_run(result: Result, path: pathlib.Path) -> None:
    """Desired and actual angle, error, and duty against time, one PNG."""
    tr = result.trace
    deg = np.degrees
    fig, axes = plt.subplots(3, 1, figsize=(8, 7.5), sharex=True, constrained_layout=True)
    axes[0].plot(tr.time, deg(tr.desired_angle), "k--", lw=1.2, label="desired")
    axes[0].plot(tr.time, deg(tr.angle), "C0", lw=1.2, label="actual")
    axes[0].set_ylabel("angle (deg)")
    axes[1].plot(tr.time, deg(tr.desired_angle - tr.angle), "C3", lw=1.0, label="true")
    preset = result.scenario.preset
    if preset.metrics_on_sensor:  # the metrics score the Hall reading, as the thesis's experiments did
        reading = result.scored_angle
        axes[0].plot(tr.time, deg(reading), "C1", lw=0.8, alpha=0.8, label="Hall reading")
        axes[1].plot(tr.time, deg(tr.desired_angle - reading), "C1", lw=0.8, alpha=0.8, label="reading (scored)")
        axes[1].legend(loc="best", fontsize=8)
    axes[0].legend(loc="best")
    axes[1].axhline(0.0, color="0.6", lw=0.6)
    axes[1].set_ylabel("error (deg)")
    m = result.metrics
    sse = "–" if math.isnan(m.sse) else f"{math.degrees(m.sse):.2f} deg"
    axes[1].set_title(f"RMSE {math.degrees(m.rmse):.2f} deg   SSE {sse}   "
                      f"max |e| {math.degrees(m.max_error):.2f} deg", fontsize=9)
    axes[2].step(tr.time, tr.duty, "C2", lw=1.0, where="post")
    axes[2].set_ylabel("duty (%)")
    axes[2].set_xlabel("time (s)")
    axes[2].set_ylim(-105, 105)
    fig.suptitle(title(result), fontsize=10)
    fig.savefig(path, dpi=90)
    plt.close(fig)
