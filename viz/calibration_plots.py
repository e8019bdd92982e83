"""The as-built calibration: twin against measurement per cell (SPEC §8, §9's T1 cells)."""

from __future__ import annotations

import pathlib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def _label(r: dict) -> str:
    where = "" if r.get("payload_g", 0) == 0 and r.get("orientation", "horizontal") == "horizontal" else \
        f"\n{r['payload_g']:g} g {r['orientation'][0].upper()}"
    return f"{r['controller']}\nT{r['trajectory']}{where}"


def plot_calibration(data: dict, path: pathlib.Path) -> None:
    """Left: RMSE per cell (measured with its std; twin with its std over the check seeds), each cell's
    20 % bar, the twin's mean over the fit seeds as a marker. Right: the cost of every evaluation by
    stage, the best cost and the noise band the ensemble was chosen in."""
    rows, wide = data["residuals_check_seeds"], data["residuals_fit_seeds"]
    fig, (bars, trace) = plt.subplots(1, 2, figsize=(15, 4.8), gridspec_kw={"width_ratios": [3.3, 1]})
    x = np.arange(len(rows))
    bars.bar(x - 0.2, [r["experiment_rmse_deg"] for r in rows], 0.4, yerr=[r["experiment_std_deg"] for r in rows],
             label="measured (thesis §8, §9 T1)", color="0.6", capsize=3)
    bars.bar(x + 0.2, [r["twin_rmse_deg"] for r in rows], 0.4, yerr=[r["twin_std_deg"] for r in rows],
             label=f"as-built twin, mean of {len(data['check_seeds'])} seeds", color="tab:blue", capsize=3)
    for xi, r in zip(x, rows, strict=True):
        target = r["experiment_rmse_deg"]
        bars.fill_between([xi, xi + 0.4], 0.8 * target, 1.2 * target, color="tab:green", alpha=0.25, lw=0,
                          label="measured ± 20 %" if xi == 0 else None)
        bars.annotate(f"{100 * (r['ratio'] - 1):+.0f}%", (xi + 0.2, r["twin_rmse_deg"] + r["twin_std_deg"]),
                      ha="center", va="bottom", fontsize=6.5, xytext=(0, 3), textcoords="offset points")
    bars.plot(x + 0.2, [r["twin_rmse_deg"] for r in wide], "kD", ms=3.5,
              label=f"as-built twin, mean of {len(data['noise']['seed_sets'][0])} fit seeds")
    bars.set_xticks(x, [_label(r) for r in rows], fontsize=6.5)
    bars.set_ylabel("RMSE (deg)")
    bars.legend(fontsize=8)
    bars.set_title("as-built calibration: RMSE per cell")
    history = data["history"]
    for stage, marker in (("scan", "o"), ("simplex", "."), ("profile", "s")):
        idx = [i for i, h in enumerate(history) if h["stage"] == stage]
        trace.plot([i + 1 for i in idx], [history[i]["cost"] for i in idx], marker, ls="none", ms=4, label=stage)
    best, noise = data["cost"], data["noise"]["std"]
    trace.axhspan(best, best + noise, color="tab:green", alpha=0.25, lw=0,
                  label=f"best + noise ({len(data['ensemble'])} in ensemble)")
    trace.set_xlabel("evaluation")
    trace.set_ylabel("cost")
    trace.set_yscale("log")
    trace.legend(fontsize=7)
    trace.set_title("search")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
