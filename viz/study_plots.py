"""Plots of ``twin study``: RMSE against payload (robustness), the open-loop responses, the as-built ablation."""

from __future__ import annotations

import math
import pathlib
from collections.abc import Sequence

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter  # noqa: E402

from twin.experiments.demo import LABELS  # noqa: E402
from twin.experiments.studies import SOFT_LIMITS, OpenLoopStudy  # noqa: E402
from twin.plants import plant  # noqa: E402

ORIENTATION_STYLES = {"horizontal": "-", "vertical": "--"}


def robustness_figure(runs: Sequence[dict]) -> plt.Figure:
    """RMSE against tip payload: every finished run a dot, the median of each cell a line; one panel per
    trajectory (its title counts the failed runs, which are not drawn), colour per controller, line style
    per orientation. Log scale, so that a stalled run (tens of degrees) shows as the outlier it is
    instead of flattening the others."""
    if not runs:
        raise ValueError("no robustness runs to plot")
    finished = [r for r in runs if r["status"] != "failed" and r["rmse_deg"] is not None]
    trajectories = sorted({r["trajectory"] for r in runs})
    fig, axes = plt.subplots(1, len(trajectories), figsize=(5.5 * len(trajectories), 4.5), squeeze=False,
                             sharey=True, constrained_layout=True)
    controllers = sorted({r["controller"] for r in runs})
    lines = [(c, o) for c in controllers for o in ORIENTATION_STYLES]
    for ax, trajectory in zip(axes[0], trajectories, strict=True):
        for line_index, (controller, orientation) in enumerate(lines):
            members = [r for r in finished if (r["trajectory"], r["controller"], r["orientation"])
                       == (trajectory, controller, orientation)]
            if not members:
                continue
            color = f"C{controllers.index(controller)}"
            payloads = sorted({r["payload_g"] for r in members})
            offset = 0.15 * (line_index - (len(lines) - 1) / 2)  # side by side, so the dots do not hide
            median = [float(np.median([r["rmse_deg"] for r in members if r["payload_g"] == g])) for g in payloads]
            ax.plot([g + offset for g in payloads], median, ls=ORIENTATION_STYLES[orientation], color=color,
                    label=f"{LABELS[controller]}, {orientation}")
            ax.plot([r["payload_g"] + offset for r in members], [r["rmse_deg"] for r in members], ls="none",
                    marker="o", ms=3.5, alpha=0.6, color=color)
        ax.set_yscale("log")
        ax.yaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
        ax.yaxis.set_major_formatter(FuncFormatter(lambda value, _: f"{value:g}"))
        ax.yaxis.set_minor_formatter(NullFormatter())
        failed = sum(r["trajectory"] == trajectory for r in runs) - sum(r["trajectory"] == trajectory
                                                                         for r in finished)
        ax.set_title(f"T{trajectory} ({runs[0]['plant']} plant)" + (f", {failed} failed runs not shown" if failed else ""))
        ax.set_xlabel("payload at the link tip (g)")
        ax.grid(alpha=0.3, which="both")
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=8, handlelength=3.5)  # long enough to show the dashes
    axes[0][0].set_ylabel("RMSE (deg): runs (dots), median (line)")
    return fig


def plot_robustness(runs: Sequence[dict], path: pathlib.Path) -> None:
    """:func:`robustness_figure`, written to ``path``."""
    fig = robustness_figure(runs)
    fig.savefig(path, dpi=90)
    plt.close(fig)


def plot_openloop(study: OpenLoopStudy, path: pathlib.Path) -> None:
    """Angle and duty against time for both plants, soft limits dotted, each reversal of the commanded
    duty marked, so the lag between the plants at each reversal shows."""
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(9, 6.5), sharex=True, height_ratios=(2, 1),
                                      constrained_layout=True)
    for index, run in enumerate(study.runs):
        color = f"C{index}"
        top.plot(run.time, np.degrees(run.angle), color=color, label=f"{run.plant}")
        bottom.step(run.time, run.duty, where="post", color=color, label=f"{run.plant}")
        for r in run.reversals:
            top.axvline(r.time, color=color, lw=0.6, ls=":")
            if not math.isnan(r.lag):
                top.annotate(f"{r.lag * 1e3:.0f} ms", (r.time + r.lag, np.degrees(np.interp(r.time + r.lag, run.time,
                                                                                              run.angle))),
                             xytext=(4, -12 if index else 6), textcoords="offset points", fontsize=7, color=color)
    radius = plant(study.runs[0].plant).params.gears.spur_radius
    for y in SOFT_LIMITS:
        top.axhline(math.degrees(y / radius), color="0.5", ls="--", lw=0.8)
    top.set_ylabel("output angle (deg)")
    top.set_title("open-loop validation (SPEC §4.6); dotted: reversals of the duty's sign, "
                  "dashed: soft limits; labels: lag", fontsize=9)
    bottom.set_ylabel("duty (%)")
    bottom.set_xlabel("time (s)")
    for ax in (top, bottom):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.savefig(path, dpi=90)
    plt.close(fig)


def plot_ablation(rows: Sequence[dict], path: pathlib.Path) -> None:
    """Twin / experiment RMSE per variant (rows) x experimental cell (columns), on a log colour scale
    centred on 1; cells within the 20 % bar are boxed."""
    variants = list(dict.fromkeys(r["variant"] for r in rows))
    cells = list(dict.fromkeys((r["controller"], r["trajectory"]) for r in rows))
    ratio = np.array([[r["ratio"] for r in rows if r["variant"] == v] for v in variants])
    within = np.array([[r["within_tolerance"] for r in rows if r["variant"] == v] for v in variants])
    fig, ax = plt.subplots(figsize=(1.0 * len(cells) + 3, 0.45 * len(variants) + 1.5), constrained_layout=True)
    image = ax.imshow(np.log2(ratio), cmap="RdBu_r", vmin=-2, vmax=2, aspect="auto")
    for i in range(len(variants)):
        for j in range(len(cells)):
            ax.text(j, i, f"{ratio[i, j]:.2f}", ha="center", va="center", fontsize=8,
                    fontweight="bold" if within[i, j] else "normal")
            if within[i, j]:
                ax.add_patch(plt.Rectangle((j - 0.5, i - 0.5), 1, 1, fill=False, lw=1.5, ec="k"))
    ax.set_xticks(range(len(cells)), [f"{LABELS.get(c, c)}\nT{t}" for c, t in cells], fontsize=7)
    ax.set_yticks(range(len(variants)), variants, fontsize=8)
    colorbar = fig.colorbar(image, ax=ax, ticks=[-2, -1, 0, 1, 2])
    colorbar.ax.set_yticklabels(["1/4", "1/2", "1", "2", "4"])
    colorbar.set_label("twin / experiment RMSE")
    ax.set_title("as-built with one effect off (boxed: within 20 % of the experiment)")
    fig.savefig(path, dpi=110)
    plt.close(fig)
