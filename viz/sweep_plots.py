"""Plots of a sweep's summary: RMSE against payload (or against every group)."""

from __future__ import annotations

import pathlib
from collections.abc import Sequence

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from twin.plants import plant  # noqa: E402

# A summary row's group, in label order; controller and trajectory are always named, the rest when they vary.
GROUP_FIELDS = ("controller", "trajectory", "payload_g", "orientation", "plant", "supply_kpa", "pwm_period_ms")
ALWAYS_NAMED = ("controller", "trajectory")
LABEL_FORMATS = {"trajectory": "T{}", "payload_g": "{} g", "supply_kpa": "{} kPa", "pwm_period_ms": "PWM {} ms"}
PLANT_VALUES = {"supply_kpa": lambda params: params.supply.pressure / 1e3,
                "pwm_period_ms": lambda params: params.valves.pwm_period * 1e3}  # what None (the plant's) means


def _text(row: dict, field: str) -> str:
    value = row[field]
    if value is None and field in PLANT_VALUES:
        value = PLANT_VALUES[field](plant(row["plant"]).params)
    shown = format(value, "g") if isinstance(value, float) else str(value)
    return LABEL_FORMATS.get(field, "{}").format(shown)


def group_label(row: dict, fields: Sequence[str]) -> str:
    """``row``'s group named by ``fields``, e.g. ``smc T2 vertical 400 kPa``."""
    return " ".join(_text(row, f) for f in GROUP_FIELDS if f in fields)


def varying_fields(summary: Sequence[dict], candidates: Sequence[str] = GROUP_FIELDS) -> list[str]:
    """The fields a label needs: the always-named ones and every other that takes several values."""
    return [f for f in candidates if f in ALWAYS_NAMED or len({s[f] for s in summary}) > 1]


def _draw_lines(ax, summary: Sequence[dict]) -> None:
    """One line (mean, min-max band) against payload per group of every other field."""
    lines: dict[tuple, list[dict]] = {}
    for s in summary:
        lines.setdefault(tuple(s[f] for f in GROUP_FIELDS if f != "payload_g"), []).append(s)
    fields = varying_fields(summary, [f for f in GROUP_FIELDS if f != "payload_g"])
    for members in lines.values():
        members = sorted(members, key=lambda s: s["payload_g"])
        x = [s["payload_g"] for s in members]
        style = "-" if members[0]["orientation"] == "horizontal" else "--"
        (line,) = ax.plot(x, [s["rmse_mean_deg"] for s in members], style, marker="o",
                          label=group_label(members[0], fields))
        ax.fill_between(x, [s["rmse_min_deg"] for s in members], [s["rmse_max_deg"] for s in members],
                        color=line.get_color(), alpha=0.15)
    ax.set_xlabel("payload at the link tip (g)")
    ax.legend(fontsize=7, ncol=2)


def _draw_bars(ax, summary: Sequence[dict]) -> None:
    """One bar (mean, std error bar) per group."""
    fields = varying_fields(summary)
    ax.bar(range(len(summary)), [s["rmse_mean_deg"] for s in summary],
           yerr=[s["rmse_std_deg"] for s in summary], color="C0")
    ax.set_xticks(range(len(summary)), [group_label(s, fields) for s in summary], rotation=60, ha="right",
                  fontsize=7)


def draw_summary(ax, summary: Sequence[dict]) -> None:
    """RMSE against payload when the sweep has several payloads; otherwise one bar per group."""
    if len({s["payload_g"] for s in summary}) > 1:
        _draw_lines(ax, summary)
    else:
        _draw_bars(ax, summary)
    ax.set_ylabel("RMSE (deg)")
    ax.grid(alpha=0.3)


def plot_summary(summary: Sequence[dict], path: pathlib.Path) -> None:
    fig, ax = plt.subplots(figsize=(8, 5), constrained_layout=True)
    draw_summary(ax, summary)
    fig.savefig(path, dpi=90)
    plt.close(fig)
