"""The as-built calibration: twin against experiment per cell (SPEC §8)."""

from __future__ import annotations

import pathlib
from collections.abc import Sequence

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def plot_calibration(rows: Sequence[dict], history: Sequence[dict], path: pathlib.Path,
                     ensemble_rows: Sequence[dict], ensemble_size: int, check_size: int) -> None:
    """Bars of RMSE (twin with its std over seeds, experiment with its std) per cell, each cell's 20 % bar,
    the twin's mean over a larger ensemble of seeds as a marker where given, and the cost per evaluation."""
    fig, (bars, trace) = plt.subplots(1, 2, figsize=(12, 4.5), gridspec_kw={"width_ratios": [3, 1]})
    x = np.arange(len(rows))
    labels = [f"{r['controller']}\nT{r['trajectory']}" for r in rows]
    bars.bar(x - 0.2, [r["experiment_rmse_deg"] for r in rows], 0.4, yerr=[r["experiment_std_deg"] for r in rows],
             label="experiment (thesis §8)", color="0.6", capsize=3)
    bars.bar(x + 0.2, [r["twin_rmse_deg"] for r in rows], 0.4, yerr=[r["twin_std_deg"] for r in rows],
             label=f"as-built twin, mean of {check_size} seeds", color="tab:blue", capsize=3)
    for xi, r in zip(x, rows, strict=True):
        target = r["experiment_rmse_deg"]
        bars.fill_between([xi, xi + 0.4], 0.8 * target, 1.2 * target, color="tab:green", alpha=0.25, lw=0,
                          label="experiment ± 20 % (the issue's bar)" if xi == 0 else None)
        bars.annotate(f"{100 * (r['ratio'] - 1):+.0f}%", (xi + 0.2, r["twin_rmse_deg"] + r["twin_std_deg"]),
                      ha="center", va="bottom", fontsize=7, xytext=(0, 3), textcoords="offset points")
    if ensemble_rows:
        bars.plot(x + 0.2, [r["twin_rmse_deg"] for r in ensemble_rows], "kD", ms=4,
                  label=f"as-built twin, mean of {ensemble_size} seeds")
    bars.set_xticks(x, labels, fontsize=8)
    bars.set_ylabel("RMSE (deg)")
    bars.legend(fontsize=8)
    bars.set_title("as-built calibration: RMSE per cell")
    trace.plot(np.arange(1, len(history) + 1), [h["cost"] for h in history], ".-", lw=0.8)
    trace.set_xlabel("evaluation")
    trace.set_ylabel("cost")
    trace.set_yscale("log")
    trace.set_title("Nelder-Mead")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
