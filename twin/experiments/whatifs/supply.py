"""``twin whatif supply``: tracking on the as-built plant with its air-over-water supply line,
with a gas accumulator at the valve block instead (SPEC §10, future work 1), and with an ideal
constant supply: how much the sagging, ringing supply costs, and how much an accumulator buys back.
"""

from __future__ import annotations

import argparse
import dataclasses
import pathlib
from collections.abc import Sequence

import numpy as np

from twin.batch.tables import counted, signed, summarise
from twin.exceptions import InvalidScenario
from twin.experiments.base import Experiment, Outcome
from twin.experiments.whatifs.common import add_common_arguments, progress_bar, simulate_in_parts
from twin.physics.params import NOMINAL_PARAMS
from twin.plants import Plant, plant
from twin.sim import report
from twin.sim.scenario import MODEL_BASED_CONTROLLERS, Scenario
from viz.figures import finish, plt

SUPPLY_MODELS = ("line", "accumulator", "constant")  # SupplyLineParams.model, the plant's own first


def supply_variants(base: Plant) -> dict[str, Plant]:
    """``base`` with each supply model of :data:`SUPPLY_MODELS`, named after it."""
    if not base.params.chambers.compressible:
        raise InvalidScenario(f"the supply study needs a plant whose supply can sag (compressible chambers, as "
                              f"as-built): {base.name!r} holds its supply constant")
    return {model: dataclasses.replace(base, name=f"{base.name}, {model} supply", params=dataclasses.replace(
        base.params, supply_line=dataclasses.replace(base.params.supply_line, model=model)))
        for model in SUPPLY_MODELS}


def supply_study(*, trajectories: Sequence[int] = (1, 3), seeds: int = 3, plant_name: str = "as-built",
                 bar=None) -> Outcome:
    """FF + PVA and sliding mode on ``trajectories`` with each supply model, ``seeds`` runs each, in parts;
    ``bar`` (a tqdm bar, optional) is given the number of scenarios before they run, then counts them."""
    from twin.envs.runner import thesis_controllers

    variants = supply_variants(plant(plant_name))
    cases = [(Scenario(c, t, plant=variants[m], seed=s), m)
             for m in SUPPLY_MODELS for c in MODEL_BASED_CONTROLLERS for t in trajectories for s in range(seeds)]
    if bar is not None:
        bar.reset(total=len(cases))
    scenarios = [s for s, _ in cases]
    records = simulate_in_parts(scenarios, thesis_controllers(scenarios), lambda r: {
        **report.summary(r), "pwm_period_ms": None, "status": "failed" if r.warnings else "ok"}, bar)
    model_of = {variant.name: model for model, variant in variants.items()}
    rows = [{"supply_model": model_of[row["plant"]], **row} for row in summarise(records)]
    line = variants["line"].params.supply_line
    lines = [f"{plant_name} plant, supply through a hose ringing at {line.natural_frequency:g} Hz (line), the same with "
             f"a {line.accumulator_compliance:.0e} m^3/Pa gas accumulator at the valve block (accumulator), and a "
             f"constant {NOMINAL_PARAMS.supply.pressure / 1e3:g} kPa (constant); mean RMSE over {counted(seeds, 'seed')}:"]
    for controller in MODEL_BASED_CONTROLLERS:
        for t in trajectories:
            by_model = {r["supply_model"]: r for r in rows if r["controller"] == controller and r["trajectory"] == t}
            line_rmse = by_model["line"]["rmse_mean_deg"]
            lines.append(f"{controller} T{t}: " + ", ".join(
                f"{m} {by_model[m]['rmse_mean_deg']:.2f} deg ({by_model[m]['rmse_mean_deg'] / line_rmse - 1:+.0%}"
                + ("" if np.isnan(by_model[m]["sse_mean_deg"]) else f", SSE {signed(by_model[m]['sse_mean_deg'])}")
                + ")" for m in SUPPLY_MODELS))
    return Outcome(rows, "\n".join(lines))


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
    finish(fig, ax, path, xlabel="controller and trajectory", ylabel="RMSE (deg)")


class SupplyWhatIf(Experiment):
    name = "supply"
    help = "supply line against an accumulator and a constant supply (as-built)"
    default_plant = "as-built"

    def add_arguments(self, parser: argparse.ArgumentParser) -> None:
        add_common_arguments(parser, self.default_plant)

    def check(self, args: argparse.Namespace) -> None:
        supply_variants(plant(args.plant))  # a plant whose supply cannot sag is refused

    def run(self, args: argparse.Namespace, out: pathlib.Path) -> Outcome:
        with progress_bar(self.name) as bar:
            return supply_study(seeds=args.seeds, plant_name=args.plant, bar=bar)

    def plot(self, outcome: Outcome, path: pathlib.Path) -> None:
        plot_supply(outcome.rows, path)


EXPERIMENT = SupplyWhatIf()
