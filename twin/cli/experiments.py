"""``twin whatif NAME`` and ``twin study NAME``: every experiment driven the same way
(:class:`twin.experiments.base.Experiment`): check the input, run, write, plot, answer."""

from __future__ import annotations

import argparse
import sys

from twin.batch.store import StoreNotMade
from twin.cli.common import EXIT_INTERRUPTED, Parser, output_folder
from twin.experiments import arguments
from twin.experiments.base import Experiment, refuse_folders_in_the_way, tell_undrawn
from twin.experiments.studies import STUDIES
from twin.experiments.whatifs import WHATIFS


def run_experiment(experiment: Experiment, args: argparse.Namespace) -> int:
    """Exit 0, or 1 when some run failed or a figure could not be drawn (its tables are written), or 130
    when interrupted (SIGTERM too; a resumable one keeps its runs). A folder this command made is removed
    again, while it still holds the folder's lock, when it stops without its results, unless the
    experiment is resumable (its store may hold finished runs, whatever stopped it)."""
    experiment.check(args)  # bad input: a one-line error before anything is written
    refuse_folders_in_the_way(args.out, experiment.file_names())  # staged() checks what it wrote again
    with output_folder(args.out, keep_on_failure=experiment.resumable) as folder:
        try:
            outcome = experiment.run(args, args.out)
        except StoreNotMade:  # no run finished: a folder made here goes, as for refused input
            folder.keep = False
            raise
        except KeyboardInterrupt:
            if not experiment.resumable:
                raise
            print(f"interrupted: finished runs are kept in {experiment.store(args.out)}; "
                  "run the same command again to finish the rest", file=sys.stderr)
            return EXIT_INTERRUPTED
        paths, undrawn = experiment.publish(outcome, args.out)  # every table, or none
    print(outcome.answer)
    print(f"wrote {', '.join(str(p) for p in paths)}")
    tell_undrawn(undrawn)
    return 1 if outcome.failed or undrawn else 0


def _group(sub, command: str, help_text: str, experiments: dict[str, Experiment]) -> None:
    parser = sub.add_parser(command, help=help_text)
    names = parser.add_subparsers(dest="experiment", required=True, parser_class=Parser, metavar="NAME")
    for name, experiment in experiments.items():
        one = names.add_parser(name, help=experiment.help)
        one.add_argument("--out", type=arguments.out_dir, required=True, metavar="DIR", help="output folder (created)")
        experiment.add_arguments(one)
        one.set_defaults(func=lambda args, experiment=experiment: run_experiment(experiment, args))


def add_parser(sub) -> None:
    # Named from the registries, so a new what-if or study is listed without another edit here.
    _group(sub, "whatif", f"what-if questions: {', '.join(WHATIFS)}", WHATIFS)
    _group(sub, "study", f"the thesis's studies replayed: {', '.join(STUDIES)}", STUDIES)
