"""``twin validate`` as an :class:`twin.experiments.base.Experiment`: its arguments, its run and its files."""

from __future__ import annotations

import argparse
import pathlib

from twin.batch.tables import write_csv
from twin.experiments.base import Experiment, Outcome, drawn
from twin.experiments.validate.common import (
    EFFECT_COLUMNS,
    MEMBER_COLUMNS,
    PREDICTION_COLUMNS,
    PREDICTION_MEMBER_COLUMNS,
    SEED_COLUMNS,
    VALIDATION_COLUMNS,
)
from twin.experiments.validate.ensemble import member_means, prediction_member_rows
from twin.experiments.validate.figures import (
    figure_effects,
    figure_prediction,
    figure_pulses,
    figure_seeds,
    figure_validation,
)
from twin.experiments.validate.markdown import report
from twin.experiments.validate.members import member_rows
from twin.experiments.validate.readings import MISS_COLUMNS, misses
from twin.experiments.validate.run import validate
from twin.sim.scenario import CONTROLLER_LABELS


class ValidateExperiment(Experiment):
    name = "validation"
    help = "every published comparison, and the blind T3 prediction over the calibration ensemble"

    def add_arguments(self, parser: argparse.ArgumentParser) -> None:
        from twin.experiments import arguments

        parser.add_argument("--workers", type=arguments.workers, default=2, help="processes (default 2)")

    def check(self, args: argparse.Namespace) -> None:
        from twin.plants.as_built import calibrated_values, ensemble_values

        calibrated_values()  # no readable preset: a one-line error before anything is written
        ensemble_values()

    def run(self, args: argparse.Namespace, out: pathlib.Path) -> Outcome:
        import sys

        from tqdm import tqdm

        from twin.plants.as_built import ensemble_values

        total = 9 + len(ensemble_values())
        with tqdm(total=total, desc="validate", unit="stage", file=sys.stderr) as bar:
            v = validate(workers=args.workers, progress=lambda: bar.update(1))
        within = sum(r["within_tolerance"] for r in v.rows)
        stalled = sum(r["stalled_runs"] for r in v.prediction)
        answer = (f"{within} of {len(v.rows)} comparisons within tolerance (see validation.md). T3 prediction over "
                  f"{len(v.prediction_detail['members'])} ensemble members, committed [10-90 % band; lowest-highest "
                  "member]: "
                  + "; ".join(f"{CONTROLLER_LABELS[r['controller']]} {r['payload_g']:g} g {r['orientation'][0].upper()} "
                              f"{r['twin_mean']:.2f} [{r['band_p10']:.2f}-{r['band_p90']:.2f}; "
                              f"{means.min():.2f}-{means.max():.2f}]"
                              for r, means in zip(v.prediction, member_means(v.prediction_detail), strict=True))
                  + f"; {stalled} stalled runs.")
        return Outcome(rows=v.rows, answer=answer, failed=v.failed, detail=v)

    def file_names(self) -> tuple[str, ...]:
        return ("validation.csv", "prediction.csv", "validation.md", "prediction_members.csv", "validation.png",
                "prediction.png", "pulses.png", "seeds.csv", "seeds.png", "effects.csv", "effects.png", "misses.csv",
                "members.csv")

    def outputs(self, outcome: Outcome, out: pathlib.Path, undrawn: list[tuple[str, str]]) -> list[pathlib.Path]:
        """``validation.csv``, ``prediction.csv``, ``validation.md``, ``prediction_members.csv``
        (:func:`prediction_member_rows`) and the figures, ``seeds.csv``
        (:func:`seed_rows`), ``effects.csv`` (:func:`payload_effects`), ``misses.csv`` (:func:`misses`) and
        ``members.csv`` (:func:`member_rows`)
        (the CLI's :meth:`publish` makes them all or nothing; a figure that cannot be drawn is left out and
        named in ``undrawn``)."""
        v = outcome.detail
        paths = [out / "validation.csv", out / "prediction.csv", out / "validation.md",
                 out / "prediction_members.csv"]
        write_csv(v.rows, VALIDATION_COLUMNS, paths[0])
        write_csv(v.prediction, PREDICTION_COLUMNS, paths[1])
        paths[2].write_text(report(v))
        write_csv(prediction_member_rows(v.prediction, v.prediction_detail), PREDICTION_MEMBER_COLUMNS, paths[3])
        paths += drawn(lambda path: figure_validation(v.rows, path), out / "validation.png", undrawn)
        paths += drawn(lambda path: figure_prediction(v, path), out / "prediction.png", undrawn)
        paths += drawn(lambda path: figure_pulses(v, path), out / "pulses.png", undrawn)
        paths.append(out / "seeds.csv")
        write_csv(v.seeds or [], SEED_COLUMNS, paths[-1])
        paths += drawn(lambda path: figure_seeds(v, path), out / "seeds.png", undrawn)
        paths.append(out / "effects.csv")
        write_csv(v.effects, EFFECT_COLUMNS, paths[-1])
        paths += drawn(lambda path: figure_effects(v, path), out / "effects.png", undrawn)
        paths.append(out / "misses.csv")
        write_csv(misses(v), MISS_COLUMNS, paths[-1])
        paths.append(out / "members.csv")
        write_csv(member_rows(v), MEMBER_COLUMNS, paths[-1])
        return paths


EXPERIMENT = ValidateExperiment()
