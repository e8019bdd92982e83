"""``twin`` and ``python -m twin``: the command line (:mod:`twin.cli`), loaded inside the Ctrl-C guard so an
interrupt while it loads is one line too, not a traceback."""

import sys

EXIT_INTERRUPTED = 130  # twin.cli.common's, not imported: this must not load the command line first


def entry() -> int:
    try:
        from twin.cli import main
    except KeyboardInterrupt:
        print("twin: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    return main()


if __name__ == "__main__":
    sys.exit(entry())
