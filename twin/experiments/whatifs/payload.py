"""``twin whatif payload``: RMSE, SSE and max error against tip payload, both orientations, both
model-based controllers, up to where the joint can no longer follow (max |error| above
FOLLOW_LIMIT_DEG in any seed). Runs through the sweep engine, resumable from ``DIR/payload-runs``.
"""

from __future__ import annotations

import argparse
import pathlib
from collections.abc import Sequence

from twin.batch.grid import expand
from twin.batch.sweep import counting, run_sweep
from twin.batch.tables import summarise
from twin.experiments import arguments
from twin.experiments.base import Experiment, Outcome
from twin.experiments.whatifs.common import add_common_arguments, list_flag, progress_bar, refuse_oversized
from viz.sweep_plots import plot_summary

CONTROLLERS = ("ffpva", "smc")
ORIENTATIONS = ("horizontal", "vertical")
FOLLOW_LIMIT_DEG = 10.0  # max |error| beyond which the joint "no longer follows"


def payload_study(*, out: pathlib.Path, payloads_g: Sequence[float], trajectory: int = 1, seeds: int = 3,
                  plant_name: str = "thesis", workers: int | None = None, bar=None) -> Outcome:
    """``bar`` (a tqdm bar, optional) is given the number of scenarios before they run, then counts them
    (a resumed study counts the ones already in ``out`` at once)."""
    points = expand({"controller": list(CONTROLLERS), "trajectory": [trajectory], "payload": list(payloads_g),
                     "orientation": list(ORIENTATIONS), "plant": [plant_name], "seed": list(range(seeds))})
    if bar is not None:
        bar.reset(total=len(points))
    records = run_sweep(points, out=out, workers=workers, progress=None if bar is None else counting(bar)).records
    rows = summarise(records)
    failed = [r for r in records if r["status"] != "ok"]
    lines = []
    for controller in ("ffpva", "smc"):
        for orientation in ("horizontal", "vertical"):
            group = sorted((r for r in rows if r["controller"] == controller and r["orientation"] == orientation),
                           key=lambda r: r["payload_g"])
            ran = [r for r in group if not r["failed"]]  # a payload with a failed run: where it follows is unknown
            broken = [f"{r['payload_g']:g}" for r in group if r["failed"]]
            last_ok = max((r["payload_g"] for r in ran if r["max_error_deg"] <= FOLLOW_LIMIT_DEG), default=None)
            first_bad = next((r["payload_g"] for r in ran if r["max_error_deg"] > FOLLOW_LIMIT_DEG), None)
            if ran:
                reach = (f"follows T{trajectory} up to {last_ok:g} g" if last_ok is not None else "never follows")
                reach += (f", not at {first_bad:g} g" if first_bad is not None else
                          " (every payload whose runs ran)" if broken else " (the whole range)")
            else:
                reach = "where it follows is not known"
            reach += f" (runs failed at {', '.join(broken)} g)" if broken else ""
            rmse = ", ".join(f"{r['payload_g']:g} g: {r['rmse_mean_deg']:.2f}" for r in group[:: max(1, len(group) // 4)])
            lines.append(f"{controller} {orientation}: {reach}; RMSE (deg) {rmse}")
    if failed:  # a failed run is not a payload the joint cannot follow: say so, and exit 1
        lines.append(f"{len(failed)} of {len(records)} runs failed (their RMSE is nan, and where the joint "
                     f"follows is not known there); the first: {failed[0]['key']}: "
                     f"{(str(failed[0]['reason']).splitlines() or [''])[0]}")  # its first line; a reason may be empty
    return Outcome(rows, "\n".join(lines), failed=len(failed))


class PayloadWhatIf(Experiment):
    name = "payload"
    help = "tracking against tip payload, horizontal and vertical"
    default_plant = "thesis"
    resumable = True

    def add_arguments(self, parser: argparse.ArgumentParser) -> None:
        add_common_arguments(parser, self.default_plant)
        parser.add_argument("--payloads", default="0:30:2.5", metavar="LIST", help="grams (default 0:30:2.5)")
        parser.add_argument("--trajectory", type=arguments.trajectory, default=1, metavar="{1,2,3,4}")
        parser.add_argument("--workers", type=arguments.workers, default=None, help="processes (default: all cores)")

    def check(self, args: argparse.Namespace) -> None:
        args.payload_values = list_flag(args, "--payloads", "payloads", "payload")
        refuse_oversized(len(CONTROLLERS) * len(set(args.payload_values)) * len(ORIENTATIONS) * args.seeds,
                         "--payloads x --seeds")

    def run(self, args: argparse.Namespace, out: pathlib.Path) -> Outcome:
        store = self.store(out)
        store.mkdir(exist_ok=True)
        with progress_bar(self.name) as bar:
            return payload_study(out=store, payloads_g=args.payload_values, trajectory=args.trajectory,
                                 seeds=args.seeds, plant_name=args.plant, workers=args.workers, bar=bar)

    def store(self, out: pathlib.Path) -> pathlib.Path:
        return out / "payload-runs"

    def kept(self, out: pathlib.Path) -> list[pathlib.Path]:
        """The sweep store the runs are kept in (resumable)."""
        return [self.store(out)]

    def plot(self, outcome: Outcome, path: pathlib.Path) -> None:
        plot_summary(outcome.rows, path)


EXPERIMENT = PayloadWhatIf()
