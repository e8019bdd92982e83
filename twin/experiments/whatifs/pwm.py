"""``twin whatif pwm``: tracking against the valves' PWM period alone (SPEC §10), on the
time-resolved valve (``thesis-pwm``); the controllers keep the thesis's update rates, so only the
valves change.
"""

from __future__ import annotations

import argparse
import pathlib
from collections.abc import Sequence

from twin.batch.tables import summarise
from twin.exceptions import InvalidScenario
from twin.experiments.base import Experiment, Outcome
from twin.experiments.whatifs.common import (
    add_common_arguments,
    list_flag,
    progress_bar,
    refuse_oversized,
    simulate_in_parts,
)
from twin.physics.valves import ValveModel
from twin.plants import Plant, plant
from twin.sim import report
from twin.sim.scenario import MODEL_BASED_CONTROLLERS, Scenario
from viz.figures import finish, plt

TRAJECTORIES = (1, 3)  # the robustness study's pair: a point-to-point move and the sine


def _pwm_setup(base: Plant) -> str:
    """The answer's statement of what the PWM study varies and what it holds, for the plant ``base``."""
    valves = base.params.valves
    held = f"{valves.pwm_period * 1e3:g} ms"  # the controllers' rate: the base plant's period
    if base.valve_model is ValveModel.PWM:
        effect = (f"each discharge valve is open for the first |u| x period of every period, behind its "
                  f"{valves.opening_delay * 1e3:g}/{valves.closing_delay * 1e3:g} ms opening/closing delays")
    else:
        effect = ("the averaged valve ignores the period except for the duty resolution "
                  "(100 % / period in ticks); use --plant thesis-pwm for switching valves")
    dead_zone = (f" The {valves.dead_zone_duty:g} % dead zone stays a fraction of the period, as SPEC §3 gives "
                 "it at 16 ms." if valves.dead_zone_duty > 0 else "")
    return (f"Only the valves' PWM period varies ({base.name} plant: {effect}). The controllers keep the "
            f"thesis's update rates whatever the period: FF + PVA every {held}; sliding mode's switching term "
            f"every 1 ms, its FF + PVA part every {held}. The controller's rate is a separate question (SPEC §10: "
            f"PVA inside the PWM period) and is not mixed in here.{dead_zone}")


def pwm_study(*, periods_ms: Sequence[float], trajectories: Sequence[int] = TRAJECTORIES, seeds: int = 3,
              plant_name: str = "thesis-pwm", bar=None) -> Outcome:
    """RMSE against the valves' PWM period, with the controllers' periods fixed at the base plant's
    (16 ms): one batch, controllers shared across scenarios, built from the base plant rather than from
    each scenario (``twin.envs.runner`` would make the controllers follow the valves' period). ``bar``
    (a tqdm bar, optional) is given the number of scenarios before they run, then counts them."""
    from controllers import make_controller
    from twin.envs.runner import nominal_model

    base = plant(plant_name)
    cases = [(Scenario(c, t, plant=plant_name, seed=s, pwm_period=ms / 1e3), ms)
             for c in MODEL_BASED_CONTROLLERS for t in trajectories for s in range(seeds) for ms in periods_ms]
    controllers = {c: make_controller(c, nominal=nominal_model(base), gain_set=base.gain_set, tick=base.timestep)
                   for c in MODEL_BASED_CONTROLLERS}
    if bar is not None:
        bar.reset(total=len(cases))
    kept = simulate_in_parts([s for s, _ in cases], [controllers[s.controller] for s, _ in cases],
                             lambda r: (report.summary(r), bool(r.warnings)), bar)
    records = [{**summary, "pwm_period_ms": ms, "status": "failed" if failed else "ok"}
               for (summary, failed), (_, ms) in zip(kept, cases, strict=True)]
    rows = summarise(records)
    lines = [_pwm_setup(base)]
    for controller in MODEL_BASED_CONTROLLERS:
        for t in trajectories:
            group = sorted((r for r in rows if r["controller"] == controller and r["trajectory"] == t),
                           key=lambda r: r["pwm_period_ms"])
            best = min(group, key=lambda r: r["rmse_mean_deg"])
            alike = len({f"{r['rmse_mean_deg']:.2f}" for r in group}) == 1  # as the answer prints them
            lines.append(f"{controller} T{t}: "
                         + (f"the same at every period to 0.01 deg ({best['rmse_mean_deg']:.2f}); " if alike else
                            f"best {best['pwm_period_ms']:g} ms ({best['rmse_mean_deg']:.2f} deg); ")
                         + ", ".join(f"{r['pwm_period_ms']:g} ms {r['rmse_mean_deg']:.2f}" for r in group))
    return Outcome(rows, "\n".join(lines))


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
    finish(fig, ax, path, xlabel="valve PWM period (ms)", ylabel="RMSE (deg)")


class PwmWhatIf(Experiment):
    name = "pwm"
    help = "tracking against the valves' PWM period"
    default_plant = "thesis-pwm"

    def add_arguments(self, parser: argparse.ArgumentParser) -> None:
        add_common_arguments(parser, self.default_plant)
        parser.add_argument("--periods", default="8:32:4", metavar="LIST", help="valve PWM periods in ms (default 8:32:4)")

    def check(self, args: argparse.Namespace) -> None:
        args.period_values = list_flag(args, "--periods", "periods", "pwm_period_ms")
        if len(set(args.period_values)) < 2:  # one period cannot show what the period changes
            raise InvalidScenario(f"--periods: give two periods or more to compare, got {args.periods!r}")
        refuse_oversized(len(MODEL_BASED_CONTROLLERS) * len(TRAJECTORIES) * args.seeds * len(set(args.period_values)),
                         "--periods x --seeds")

    def run(self, args: argparse.Namespace, out: pathlib.Path) -> Outcome:
        with progress_bar(self.name) as bar:
            return pwm_study(periods_ms=args.period_values, seeds=args.seeds, plant_name=args.plant, bar=bar)

    def plot(self, outcome: Outcome, path: pathlib.Path) -> None:
        plot_pwm(outcome.rows, path)


EXPERIMENT = PwmWhatIf()
