"""Plots of a sweep's summary: RMSE against payload (or against every group)."""

from __future__ import annotations

import pathlib
from collections.abc import Sequence

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def plot_summary(summary: Sequence[dict], path: pathlib.Path) -> None:
    """RMSE (mean, min-max band) against payload per controller, trajectory and orientation when the
    sweep has several payloads; otherwise one bar per group."""
    payloads = sorted({s["payload_g"] for s in summary})
    fig, ax = plt.subplots(figsize=(8, 5), constrained_layout=True)
    if len(payloads) > 1:
        lines: dict[tuple, list[dict]] = {}
        for s in summary:
            lines.setdefault((s["controller"], s["trajectory"], s["orientation"], s["plant"]), []).append(s)
        for (controller, trajectory, orientation, plant), members in sorted(lines.items()):
            members.sort(key=lambda s: s["payload_g"])
            x = [s["payload_g"] for s in members]
            label = f"{controller} T{trajectory} {orientation}" + ("" if plant == "thesis" else f" {plant}")
            style = "-" if orientation == "horizontal" else "--"
            (line,) = ax.plot(x, [s["rmse_mean_deg"] for s in members], style, marker="o", label=label)
            ax.fill_between(x, [s["rmse_min_deg"] for s in members], [s["rmse_max_deg"] for s in members],
                            color=line.get_color(), alpha=0.15)
        ax.set_xlabel("payload at the link tip (g)")
    else:
        labels = [f"{s['controller']} T{s['trajectory']} {s['orientation'][0]}" for s in summary]
        ax.bar(range(len(summary)), [s["rmse_mean_deg"] for s in summary],
               yerr=[s["rmse_std_deg"] for s in summary], color="C0")
        ax.set_xticks(range(len(summary)), labels, rotation=60, ha="right", fontsize=7)
    ax.set_ylabel("RMSE (deg)")
    ax.grid(alpha=0.3)
    if len(payloads) > 1:
        ax.legend(fontsize=7, ncol=2)
    fig.savefig(path, dpi=90)
    plt.close(fig)
