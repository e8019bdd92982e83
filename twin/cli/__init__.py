"""Command line of the hydraulic joint twin.

    twin demo                      reproduce the thesis's controller comparison
    twin run --controller ffpva --trajectory 1 --json      one scenario
    twin bench                     cost per simulated second
    twin view --controller smc --trajectory 4              the joint live in a browser
    twin whatif payload --out DIR                          tracking against payload; `twin whatif -h` lists the rest
    twin study robustness --out DIR                        the thesis's Chapter 6 protocol
    twin study ablation --out DIR                          each as-built effect off in turn, against SPEC §8
    twin validate --out DIR                                every published comparison and the blind T3 prediction
    twin score --measured FILE --out DIR                   that prediction against measured T3 cells

Degrees, grams and kPa here; SI inside. Bad input gets a one-line error and
exit code 2, and nothing is written. One module per command; each adds its own
parser (``add_parser``).
"""

from __future__ import annotations

import argparse
import sys

from twin.cli import bench, calibrate, demo, experiments, run, score, sweep, validate, view
from twin.cli.common import EXIT_INTERRUPTED, EXIT_USAGE, Parser, sigterm_as_interrupt
from twin.exceptions import TwinError

EXIT_BROKEN_PIPE = 141  # 128 + SIGPIPE, as a shell reports a reader that went away
COMMANDS = (demo, bench, sweep, experiments, run, calibrate, validate, score, view)


class _Version(argparse.Action):
    """``twin --version``: the package's and MuJoCo's versions, imported only when asked (a probe, 2026-12-08)."""

    def __init__(self, option_strings, dest, **kwargs):
        super().__init__(option_strings, dest, nargs=0, default=argparse.SUPPRESS,
                         help="print the twin's and MuJoCo's versions and exit")

    def __call__(self, parser, namespace, values, option_string=None):
        import mujoco

        from twin.batch.sweep import package_version

        print(f"twin {package_version()} (mujoco {mujoco.__version__})")  # stdout, as argparse's own version
        parser.exit(0)


def build_parser() -> argparse.ArgumentParser:
    parser = Parser(prog="twin", description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--version", action=_Version)
    sub = parser.add_subparsers(dest="command", required=True, parser_class=Parser)
    for command in COMMANDS:
        command.add_parser(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    try:
        parser = build_parser()
        args, extra = parser.parse_known_args(argv)
        if extra:  # named after the command they were given to, as every other parse error is
            command = " ".join(filter(None, (args.command, getattr(args, "experiment", None))))
            parser.exit(EXIT_USAGE, f"twin: error: {command}: unrecognized arguments: {' '.join(extra)}\n")
        with sigterm_as_interrupt():  # every command: a kill or a closed terminal cleans up as Ctrl-C does
            return args.func(args)
    except BrokenPipeError:  # whoever read our output has gone (``| head``): what was written is whole; the
        return EXIT_BROKEN_PIPE  # process's entry point (twin.__main__) keeps its exit from a second error
    except KeyboardInterrupt:  # Ctrl-C where a command has nothing of its own to say: one line, no traceback
        print("twin: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except TwinError as error:
        print(f"twin: error: {error}", file=sys.stderr)
        return EXIT_USAGE
    except OSError as error:  # an output that passed the checks but still cannot be written, or the system
        said = (f"cannot write {error.filename}: {error.strerror}" if error.filename else
                str(error).splitlines()[0] if str(error) else type(error).__name__)
        print(f"twin: error: {said}", file=sys.stderr)
        return EXIT_USAGE


__all__ = ["EXIT_BROKEN_PIPE", "build_parser", "main"]
