"""The report's figures."""

from __future__ import annotations

import math
import pathlib
from collections.abc import Sequence

import numpy as np

from twin.experiments.validate.common import (
    PREDICTION_CELLS,
    RMSE_TOLERANCE,
    SEEDS,
    SIMULATION_TOLERANCE_DEG,
    SSE_TOLERANCE_DEG,
)
from twin.experiments.validate.motion import opening_starts
from twin.experiments.validate.run import Validation
from twin.experiments.validate.text import _effect_name, _tick
from twin.sim.scenario import CONTROLLER_LABELS
from viz.figures import plt


def figure_validation(rows: Sequence[dict], path: pathlib.Path) -> None:
    """Twin / measured per closed-loop cell, with each tolerance band."""
    closed = [r for r in rows if r["controller"] and "SSE" not in r["source"]]
    fig, ax = plt.subplots(figsize=(13, 4.6), constrained_layout=True)
    x = np.arange(len(closed))
    colours = {"chapter 5 simulation": "tab:gray", "chapter 5 experiment": "tab:blue", "chapter 6 T1": "tab:orange"}
    for xi, r in zip(x, closed, strict=True):
        ax.bar(xi, r["ratio"] or 0.0, color=colours.get(r["source"], "tab:purple"),
               label=r["source"] if r["source"] not in [c["source"] for c in closed[:xi]] else None)
    ax.axhspan(1 - RMSE_TOLERANCE, 1 + RMSE_TOLERANCE, color="tab:green", alpha=0.2, lw=0,
               label=f"±{RMSE_TOLERANCE:.0%} (measured cells; the simulations' tolerance is ±{SIMULATION_TOLERANCE_DEG} deg)")
    ax.axhline(1.0, color="k", lw=0.8)
    ax.set_xticks(x, [_tick(r) for r in closed], fontsize=6.5)
    ax.set_ylabel("twin / measured (RMSE)")
    ax.legend(fontsize=8)
    ax.set_title("twin against the thesis: mean RMSE of five runs")
    fig.savefig(path, dpi=110)
    plt.close(fig)


def figure_seeds(v: Validation, path: pathlib.Path) -> None:
    """Per measured cell: each five-run group's twin / measured, seeds 0-4's and the whole mean's; below,
    the T1 steady-error range of each group against the measured one."""
    rows = v.seeds or []
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(13, 7.0), constrained_layout=True,
                                      gridspec_kw={"height_ratios": [3, 2]})
    for ax, what, band, label in ((top, "ratio", (1 - RMSE_TOLERANCE, 1 + RMSE_TOLERANCE), "twin / measured (RMSE)"),
                                  (bottom, "sse", (-SSE_TOLERANCE_DEG, SSE_TOLERANCE_DEG),
                                   "twin - measured (deg), T1 SSE range")):
        shown = [r for r in rows if what == "ratio" or r["sse_twin"] is not None]
        for x, r in enumerate(shown):
            if what == "ratio":
                groups, whole = np.array(r["group_means"]) / r["measured"], r["ratio"]
                five = None if r["five_run_mean"] is None else r["five_run_mean"] / r["measured"]
            else:
                groups = np.array(r["sse_group_ranges"]) - r["sse_measured"]
                five = None if r["sse_five_run"] is None else r["sse_five_run"] - r["sse_measured"]
                whole = r["sse_twin"] - r["sse_measured"]
            ax.plot(np.full(len(groups), x), groups, "o", color="tab:blue", alpha=0.45, ms=4,
                    label="a five-run group" if x == 0 else None)
            if five is not None:
                ax.plot(x, five, "x", color="k", ms=7, mew=1.5, label="seeds 0-4" if x == 0 else None)
            ax.plot(x, whole, "D", color="tab:red", ms=5, label=f"seeds {r['seeds']}'s mean" if x == 0 else None)
        ax.axhspan(*band, color="tab:green", alpha=0.2, lw=0, label="tolerance")
        ax.axhline(1.0 if what == "ratio" else 0.0, color="k", lw=0.8)
        ax.set_xticks(range(len(shown)), [_tick(r) for r in shown], fontsize=7)
        ax.set_ylabel(label)
        ax.grid(alpha=0.3, axis="y")
        ax.legend(fontsize=7, ncol=4)
    top.set_title(f"the measured cells on seeds {rows[0]['seeds'] if rows else ''}, five runs at a time", fontsize=10)
    fig.savefig(path, dpi=100)
    plt.close(fig)


def figure_effects(v: Validation, path: pathlib.Path) -> None:
    """Per controller: each Chapter 6 T1 cell's RMSE over its 0 g flat one, measured and on the twin, ± 2
    standard errors."""
    effects = v.effects
    names = list(dict.fromkeys(r["controller"] for r in effects)) or ["ffpva"]
    fig, axes = plt.subplots(1, len(names), figsize=(5.2 * len(names), 3.8), sharey=True, constrained_layout=True,
                             squeeze=False)
    for ax, c in zip(axes[0], names, strict=True):
        mine = [r for r in effects if r["controller"] == c]
        x = np.arange(len(mine))
        for shift, key, colour, label in ((-0.1, "measured", "k", "measured"), (0.1, "twin", "tab:red", "twin")):
            ax.errorbar(x + shift, [r[f"{key}_effect"] for r in mine],
                        yerr=[2 * r[f"{key}_se"] for r in mine],
                        fmt="o", color=colour, capsize=3, label=f"{label} (± 2 s.e.)")
        ax.axhline(1.0, color="0.6", lw=0.8)
        ax.set_xticks(x, [_effect_name(r) for r in mine])
        ax.set_title(f"{CONTROLLER_LABELS[c]}, T1", fontsize=10)
        ax.grid(alpha=0.3, axis="y")
        ax.legend(fontsize=8)
    axes[0, 0].set_ylabel("RMSE over 0 g flat")
    fig.savefig(path, dpi=100)
    plt.close(fig)


def figure_pulses(v: Validation, path: pathlib.Path) -> None:
    """T2's first run per controller: the error, the discharge valve's openings and the law's closed-form lag."""
    example = (v.pulses or {}).get("example") or {}
    fig, axes = plt.subplots(len(example) or 1, 1, figsize=(10, 1.0 + 1.9 * max(len(example), 1)), sharex=True,
                             sharey=True, constrained_layout=True, squeeze=False)
    for ax, (name, (time, error, opened)) in zip(axes[:, 0], example.items(), strict=False):
        ax.plot(time, error, color="tab:blue", lw=1.0, label="error (deg)")
        starts = opening_starts(opened)
        ax.vlines(time[starts], 0.0, error[starts], color="tab:red", lw=1.0, label="a discharge valve opens")
        ax.axhline(v.pulses["lag_deg"][name], color="k", ls="--", lw=0.8,
                   label=f"closed-form lag {v.pulses['lag_deg'][name]:.2f} deg")
        ax.axhline(0.0, color="0.6", lw=0.6)
        ax.set_title(f"{CONTROLLER_LABELS[name]}, T2 (seed {SEEDS[0]}): RMSE "
                     f"{math.sqrt(float(np.mean(np.square(error)))):.2f} deg", fontsize=9)
        ax.set_ylabel("deg")
        ax.legend(fontsize=7, loc="upper right", ncol=3)
        ax.grid(alpha=0.3)
    axes[-1, 0].set_xlabel("time (s)")
    fig.savefig(path, dpi=100)
    plt.close(fig)


def figure_prediction(v: Validation, path: pathlib.Path) -> None:
    """The T3 prediction: the committed preset's mean, each member's mean, the 10-90 % band."""
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2), sharey=True, constrained_layout=True)
    per_member = np.array(v.prediction_detail["per_member"])  # (members, cells)
    for ax, controller in zip(axes, ("ffpva", "smc"), strict=True):
        for orientation, style in (("horizontal", "-"), ("vertical", "--")):
            idx = [k for k, c in enumerate(PREDICTION_CELLS) if c[0] == controller and c[3] == orientation]
            g = np.array([PREDICTION_CELLS[k][2] for k in idx])
            rows = [v.prediction[k] for k in idx]
            colour = "tab:blue" if orientation == "horizontal" else "tab:red"
            ax.fill_between(g, [r["band_p10"] for r in rows], [r["band_p90"] for r in rows], color=colour, alpha=0.2,
                            lw=0, label=f"{orientation}: ensemble 10-90 %")
            ax.plot(g, [r["twin_mean"] for r in rows], style, color=colour, marker="o", label=f"{orientation}: committed")
            for member in per_member:
                ax.plot(g, member[idx], ".", color=colour, alpha=0.5)
        ax.set_xlabel("payload at the link tip (g)")
        ax.grid(alpha=0.3)
        ax.set_title(f"{CONTROLLER_LABELS[controller]}, T3 (blind)")
        ax.legend(fontsize=7)
    axes[0].set_ylabel("RMSE (deg), mean of five runs")
    fig.savefig(path, dpi=110)
    plt.close(fig)
