"""``twin validate --out DIR``: how far to trust the twin (:mod:`twin.experiments.validate`)."""

from __future__ import annotations

from twin.experiments import arguments


def add_parser(sub) -> None:
    from twin.cli.experiments import run_experiment
    from twin.experiments.validate import EXPERIMENT

    one = sub.add_parser("validate", help="every published comparison, and the blind T3 prediction with its band")
    one.add_argument("--out", type=arguments.out_dir, required=True, metavar="DIR", help="output folder (created)")
    EXPERIMENT.add_arguments(one)
    one.set_defaults(func=lambda args: run_experiment(EXPERIMENT, args))
