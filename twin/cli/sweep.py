"""``twin sweep``: a grid of scenarios on all cores (or Ray), resumable."""

from __future__ import annotations

import argparse
import importlib.util
import os
import sys
import time

from twin.cli.common import EXIT_INTERRUPTED, check_out_folder, output_folder
from twin.exceptions import InvalidScenario
from twin.experiments import arguments
from twin.experiments.base import staged, tell_undrawn


def _cmd_sweep(args: argparse.Namespace) -> int:
    from twin.batch import grid

    axes = grid.read_toml(args.config) if args.config else {}
    for name in grid.AXES:
        value = getattr(args, name)
        if value is not None:
            axes[name] = grid.parse_axis(name, value)
    if not axes:
        raise InvalidScenario("the sweep names no axes: give at least one, e.g. --seed 0-4 (or --config GRID.toml)")
    points = grid.expand(axes)
    if args.backend == "local" and args.workers is not None and args.workers > arguments.MAX_WORKERS:
        # with Ray, --workers counts the cluster's CPUs, which this machine's cores do not bound
        raise InvalidScenario(f"--workers: at most {arguments.MAX_WORKERS} local processes (four per core), got "
                              f"{args.workers}")
    if args.backend == "ray" and importlib.util.find_spec("ray") is None:
        raise InvalidScenario("--backend ray: Ray is not installed here (pip install 'ray[default]'), "
                              "or use --backend local")
    if args.ray_address is not None and args.backend != "ray":
        raise InvalidScenario("--ray-address: only with --backend ray (this sweep would run locally)")
    address = args.ray_address or os.environ.get("RAY_ADDRESS")
    if args.backend == "ray" and address:
        check_ray_address(address, "--ray-address" if args.ray_address else "RAY_ADDRESS")
    check_out_folder(args.out, "sweep", OUTPUTS)  # now, not once the grid has run
    # one writer per folder (a second sweep into it is refused, naming this one); SIGTERM stops it as Ctrl-C
    # does; the folder stays whatever stops the sweep once its store is open: the store keeps the finished
    # scenarios (a store that cannot be made, on a full disk, leaves no folder made here)
    with output_folder(args.out, keep_on_failure=True) as folder:
        from twin.batch.store import StoreNotMade
        from twin.batch.sweep import ClusterNotStarted

        try:
            return _sweep(args, points)
        except (ClusterNotStarted, StoreNotMade):
            folder.keep = False  # no scenario ran: a folder made here goes again, as for any refused input
            raise


RAY_CONNECT_TIMEOUT = 5.0  # s to reach a cluster's head before the sweep is refused (Ray itself retries for minutes)
HTTP2_PREFACE = b"PRI * HTTP/2.0\r\n\r\nSM\r\n\r\n" + bytes(3) + b"\x04" + bytes(5)  # and an empty SETTINGS frame
HTTP2_SETTINGS = 4  # frame type: a gRPC server's first frame (RFC 9113 3.4)


def check_ray_address(address: str, source: str = "--ray-address") -> None:
    """``--ray-address`` ``HOST:PORT`` (or ``ray://HOST:PORT``) must answer a TCP connection within
    :data:`RAY_CONNECT_TIMEOUT`, else a one-line error before anything is written: Ray's own connect retries
    for minutes with no error (found by probing, 2026-11-27). It must also answer as gRPC does, which Ray's
    head (its GCS) and its client server speak: an HTTP/2 preface gets a SETTINGS frame back. Something else
    on the port (Ray's dashboard, a web server) left the sweep at 0 of 1 for minutes and slow to stop
    (found by a helper's probing, 2026-12-08; Ray 2.60's GCS checked by hand to answer so). A cluster on TLS
    (``RAY_USE_TLS``, which Ray reads too) wants a TLS handshake first: there only the connection is checked.
    The reply is waited for :data:`RAY_CONNECT_TIMEOUT` in all. ``auto`` and ``local`` are left to Ray."""
    import socket

    if address in ("auto", "local"):
        return
    host, _, port = address.removeprefix("ray://").rpartition(":")
    if not host or not port.isdigit() or not 0 < int(port) < 65536:
        raise InvalidScenario(f"{source}: HOST:PORT, ray://HOST:PORT, auto or local, got {address!r}")
    try:
        connection = socket.create_connection((host.strip("[]"), int(port)), timeout=RAY_CONNECT_TIMEOUT)
    except OSError as error:
        raise InvalidScenario(f"{source}: cannot reach a Ray cluster at {address} ({error.strerror or error})") from None
    with connection:
        if os.environ.get("RAY_USE_TLS", "0").lower() in ("1", "true"):
            return
        reply, deadline = b"", time.monotonic() + RAY_CONNECT_TIMEOUT
        try:
            connection.sendall(HTTP2_PREFACE)
            while len(reply) < 9:
                connection.settimeout(max(1e-3, deadline - time.monotonic()))  # one budget, not one per recv
                if not (chunk := connection.recv(9 - len(reply))):
                    break
                reply += chunk
        except OSError:  # no reply in time, or the connection dropped
            pass
    if len(reply) < 9 or reply[3] != HTTP2_SETTINGS:
        raise InvalidScenario(f"{source}: {address} answers, but not as a Ray cluster does (no gRPC reply); a "
                              "head's address is its GCS port (6379 unless set), not its dashboard's; on TLS, set RAY_USE_TLS=1")


OUTPUTS = ("results.csv", "results.parquet", "summary.csv", "rmse.png")  # the figure last


def _sweep(args: argparse.Namespace, points: list) -> int:
    from tqdm import tqdm

    from twin.batch import tables
    from twin.batch.sweep import counting, open_store, run_sweep

    open_store(args.out).close()  # refuses a store of another code version before any output
    print(f"{len(points)} scenario{'' if len(points) == 1 else 's'} -> {args.out.resolve()}", file=sys.stderr)
    bar = tqdm(total=len(points), unit="scenario", file=sys.stderr, dynamic_ncols=True, smoothing=0.1)
    try:
        outcome = run_sweep(points, out=args.out, workers=args.workers, backend=args.backend,
                            address=args.ray_address, progress=counting(bar))
    except KeyboardInterrupt:
        bar.close()
        print(f"interrupted: finished scenarios are kept in {args.out / 'results.sqlite'}; "
              "run the same command again to finish the rest", file=sys.stderr)
        return EXIT_INTERRUPTED
    finally:
        bar.close()
    from viz.sweep_plots import plot_summary

    summary = tables.summarise(outcome.records)
    # The tables and the plot are written beside the folder's files, then renamed into place one after another
    # once all are written: a stop or a full disk while they are written leaves the earlier sweep's set whole
    # (and the store keeps every finished scenario).
    with staged(args.out, "sweep") as stage:
        tables.write_results(outcome.records, stage.folder)
        tables.write_summary(summary, stage.folder)
        stage.names += list(OUTPUTS[:-1])
        stage.figure(OUTPUTS[-1], lambda path: plot_summary(summary, path))
    print(tables.format_summary(summary))
    failed = [r for r in outcome.records if r["status"] != "ok"]
    for r in failed[:20]:
        print(f"failed: {r['key']}: {r['reason']}", file=sys.stderr)
    tell_undrawn(stage.undrawn)
    print(f"{outcome.ran} run, {outcome.skipped} already done, {len(failed)} failed; "
          f"wrote {', '.join(map(str, stage.names))} in {args.out}")
    return 1 if failed or stage.undrawn else 0


def add_parser(sub) -> None:
    sweep = sub.add_parser("sweep", help="a grid of scenarios on all cores (or Ray), resumable")
    axes = {"controller": "pva, ffpva, smc", "trajectory": "1-4", "payload": "grams at the tip",
            "orientation": "horizontal, vertical", "plant": "preset names", "seed": "noise seeds; also a-b",
            "supply_kpa": "supply pressures (kPa)", "pwm_period_ms": "PWM periods (ms)"}
    for name, what in axes.items():
        numbers = "" if name in ("controller", "orientation", "plant") else "; also start:stop:step"
        sweep.add_argument("--" + name.replace("_", "-"), dest=name, metavar="LIST",
                           help=f"comma list of {what}{numbers}")
    sweep.add_argument("--config", type=arguments.named_path, metavar="GRID.toml", help="axes from a TOML file")
    sweep.add_argument("--out", type=arguments.out_dir, required=True, metavar="DIR", help="results folder (created)")
    sweep.add_argument("--workers", type=arguments.positive_int, default=None,
                       help="processes (default: all cores); with Ray, CPUs to size chunks for (default: the cluster's)")
    sweep.add_argument("--backend", choices=("local", "ray"), default="local")
    sweep.add_argument("--ray-address", type=arguments.ray_address, default=None,
                       help="Ray cluster address (default: RAY_ADDRESS or local)")
    sweep.set_defaults(func=_cmd_sweep)
