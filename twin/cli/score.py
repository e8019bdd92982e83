"""``twin score --measured FILE --out DIR``: the blind T3 prediction against measured T3 cells
(:mod:`twin.experiments.score`)."""

from __future__ import annotations

from twin.experiments import arguments


def add_parser(sub) -> None:
    from twin.cli.experiments import run_experiment
    from twin.experiments.score import EXPERIMENT

    one = sub.add_parser("score", help=EXPERIMENT.help)
    one.add_argument("--out", type=arguments.out_dir, required=True, metavar="DIR", help="output folder (created)")
    EXPERIMENT.add_arguments(one)
    one.set_defaults(func=lambda args: run_experiment(EXPERIMENT, args))
