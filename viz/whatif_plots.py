"""Plots of the what-if studies."""

from __future__ import annotations

import pathlib
from collections.abc import Sequence

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from twin.experiments.whatif import AVERAGING_WINDOWS, SUPPLY_MODELS, SUSTAINED_WINDOW, window_label  # noqa: E402
from viz.sweep_plots import plot_summary  # noqa: E402


def _finish(fig, ax, path: pathlib.Path, *, xlabel: str, ylabel: str) -> None:
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.savefig(path, dpi=90)
    plt.close(fig)


def plot_lift(rows: Sequence[dict], path: pathlib.Path) -> None:
    fig, ax = plt.subplots(figsize=(7, 4.5), constrained_layout=True)
    p = [r["supply_kpa"] for r in rows]
    ax.plot(p, [r["lift_closed_form_g"] for r in rows], "k-", label="torque balance with friction")
    ax.plot(p, [r["lift_simulated_g"] for r in rows], "o", color="C3", label="simulation (bisection)")
    ax.axhline(13.5, color="0.6", ls=":", label="13.5 g (thesis payload)")
    _finish(fig, ax, path, xlabel="supply pressure (kPa)", ylabel="heaviest tip payload lifted vertically (g)")


def plot_pwm(rows: Sequence[dict], path: pathlib.Path) -> None:
    fig, ax = plt.subplots(figsize=(7, 4.5), constrained_layout=True)
    lines: dict[tuple, list[dict]] = {}
    for r in rows:
        lines.setdefault((r["controller"], r["trajectory"]), []).append(r)
    for (controller, trajectory), members in sorted(lines.items()):
        members.sort(key=lambda r: r["pwm_period_ms"])
        ax.errorbar([r["pwm_period_ms"] for r in members], [r["rmse_mean_deg"] for r in members],
                    yerr=[r["rmse_std_deg"] for r in members], marker="o", capsize=3,
                    label=f"{controller} T{trajectory}")
    ax.axvline(16, color="0.6", ls=":", label="thesis: 16 ms")
    ax.set_title("valves' PWM period only; controllers at the thesis's rates", fontsize=9)
    _finish(fig, ax, path, xlabel="valve PWM period (ms)", ylabel="RMSE (deg)")


def plot_gear_load(rows: Sequence[dict], path: pathlib.Path) -> None:
    """Per run, the largest tooth force / Lewis safe load at the same tick, single ticks and sustained."""
    fig, ax = plt.subplots(figsize=(8, 4.5), constrained_layout=True)
    x = range(len(rows))
    for window, marker in ((AVERAGING_WINDOWS[0], "v"), (SUSTAINED_WINDOW, "o")):
        label = window_label(window)
        for mesh, color in (("spur", "C3"), ("pinion", "C0")):
            ax.plot(x, [r[f"{mesh}_worst_ratio_{label}"] for r in rows], marker, color=color, ls="none",
                    fillstyle="full" if window == SUSTAINED_WINDOW else "none",
                    label=f"{mesh}, {window * 1e3:g} ms " + ("average" if window == SUSTAINED_WINDOW else "tick"))
    ax.axhline(1.0, color="k", lw=0.8, label="Lewis safe load")
    ax.set_xticks(list(x), [f"{r['controller']} T{r['trajectory']} {r['payload_g']:g}g {r['supply_kpa']:g}kPa"
                            for r in rows], rotation=80, fontsize=6)
    ax.set_yscale("log")
    _finish(fig, ax, path, xlabel="run", ylabel="tooth force / Lewis safe load at that tick")


def plot_supply(rows: Sequence[dict], path: pathlib.Path) -> None:
    """RMSE (mean and std over seeds) per controller and trajectory, one bar per supply model."""
    fig, ax = plt.subplots(figsize=(7, 4.5), constrained_layout=True)
    cases = sorted({(r["controller"], r["trajectory"]) for r in rows})
    width = 0.8 / len(SUPPLY_MODELS)
    for j, model in enumerate(SUPPLY_MODELS):
        by_case = {(r["controller"], r["trajectory"]): r for r in rows if r["supply_model"] == model}
        ax.bar([i + (j - (len(SUPPLY_MODELS) - 1) / 2) * width for i in range(len(cases))],
               [by_case[c]["rmse_mean_deg"] for c in cases], width, yerr=[by_case[c]["rmse_std_deg"] for c in cases],
               capsize=3, label=f"{model} supply")
    ax.set_xticks(range(len(cases)), [f"{controller} T{trajectory}" for controller, trajectory in cases])
    ax.set_title(f"{rows[0]['plant'].split(',')[0]} plant: supply line, accumulator, ideal supply", fontsize=9)
    _finish(fig, ax, path, xlabel="controller and trajectory", ylabel="RMSE (deg)")


PLOTS = {"payload": plot_summary, "lift": plot_lift, "pwm": plot_pwm, "gear-load": plot_gear_load,
         "supply": plot_supply}
