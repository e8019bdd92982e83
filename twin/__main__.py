"""``twin`` and ``python -m twin``: the command line (:mod:`twin.cli`), loaded inside the Ctrl-C guard so an
interrupt while it loads is one line too, not a traceback."""

import os
import sys

EXIT_INTERRUPTED = 130  # twin.cli.common's, not imported: this must not load the command line first


def entry() -> int:
    for name in ("stdout", "stderr"):  # started with one closed (``2>&-``): progress and messages go nowhere
        if getattr(sys, name) is None:
            setattr(sys, name, open(os.devnull, "w"))  # open for the life of the process
    try:
        from twin.cli import EXIT_BROKEN_PIPE, main
    except KeyboardInterrupt:
        print("twin: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    code = main()
    if code == EXIT_BROKEN_PIPE:  # the reader of stdout went away: the exit's flush must not fail again
        try:
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, sys.stdout.fileno())
            os.close(devnull)
        except (OSError, ValueError):
            pass
    return code


if __name__ == "__main__":
    sys.exit(entry())
