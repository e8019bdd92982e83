"""What every figure of the twin shares: a headless matplotlib and one way to finish a plot."""

from __future__ import annotations

import pathlib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

__all__ = ["finish", "finish_panels", "plt"]


def finish(fig, ax, path: pathlib.Path, *, xlabel: str, ylabel: str, legend_at: dict | None = None) -> None:
    """Label, grid and legend ``ax``, write ``fig`` to ``path`` and close it (``legend_at``: where the legend
    goes, as ``Axes.legend``'s ``loc`` and ``bbox_to_anchor``; matplotlib's best place by default)."""
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    finish_panels(fig, [ax], path, legend_at=legend_at)


def finish_panels(fig, axes, path: pathlib.Path, *, legend_size: float = 8, legend_at: dict | None = None) -> None:
    """Grid and legend every panel of ``axes``, write ``fig`` to ``path`` and close it."""
    for ax in axes:
        ax.grid(alpha=0.3)
        ax.legend(fontsize=legend_size, **(legend_at or {}))
    fig.savefig(path, dpi=90)
    plt.close(fig)
