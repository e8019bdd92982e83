"""``twin view``: the joint live in a browser."""

from __future__ import annotations

import argparse
import sys

from twin.batch.stops import raise_if_stopped
from twin.cli.common import (
    EXIT_INTERRUPTED,
    add_scenario_arguments,
    all_or_nothing,
    compare_of,
    compare_settings,
    scenario_from,
    sigterm_as_interrupt,
)
from twin.experiments import arguments
from twin.experiments.base import naming


def _cmd_view(args: argparse.Namespace) -> int:
    from viz.live_server import LiveSession, LiveViewer

    compare = compare_of(args, args.compare) if args.compare else None
    session = LiveSession(scenario_from(args), record=args.html is not None, compare=compare)
    viewer = LiveViewer(session, host=args.host, port=args.port, speed=args.speed)
    if args.host not in ("127.0.0.1", "localhost", "::1"):
        print(f"warning: serving on {args.host}: anyone who can reach it can drive the twin", file=sys.stderr)
    print(f"twin view: open {viewer.url}  (Ctrl-C to stop)", flush=True)
    raise_if_stopped()  # one swallowed while the model was built: stop before serving (serving takes a stop itself)
    with sigterm_as_interrupt():  # stop (and write --html) on SIGTERM too
        try:
            viewer.start(stop_after=args.duration)
        except KeyboardInterrupt:
            viewer.stop()
        print("twin view: stopped", flush=True)
        if args.html is not None:
            print(f"writing {args.html} ...", flush=True)
            try:
                with all_or_nothing([args.html]) as (staged,), naming(staged):  # a full disk leaves none of it
                    session.write_html(staged)
            except KeyboardInterrupt:
                print("twin view: interrupted; no recording written", file=sys.stderr)
                return EXIT_INTERRUPTED
            print(f"wrote {args.html}", flush=True)
    return 1 if viewer.failure else 0


def add_parser(sub) -> None:
    view = sub.add_parser("view", help="the joint live in a browser (3D view and control panel)")
    add_scenario_arguments(view)
    view.add_argument("--host", type=arguments.host, default="127.0.0.1", help="address to listen on (default 127.0.0.1 only)")
    view.add_argument("--port", type=arguments.port, default=7000, help="TCP port (default 7000; 0: any free port)")
    view.add_argument("--speed", type=arguments.speed, default=1.0, help="simulated seconds per second (default 1)")
    view.add_argument("--duration", type=arguments.seconds, default=None, metavar="SECONDS",
                      help="stop after this many seconds of wall time (default: run until Ctrl-C)")
    view.add_argument("--compare", type=compare_settings, default=None, metavar="KEY=VALUE[,KEY=VALUE]",
                      help="a second joint beside the first, with these scenario flags changed (controller, plant, "
                           "payload, orientation, seed, noise=on|off, supply-kpa, without=EFFECT[+EFFECT]); "
                           "same targets and replays")
    view.add_argument("--html", type=arguments.writable_file(".html"), metavar="FILE.html",
                      help="on stopping, write a recording of the last model's run (up to 10 min)")
    view.set_defaults(func=_cmd_view)
