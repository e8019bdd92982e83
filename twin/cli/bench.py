"""``twin bench``: cost per simulated second, as ratios to bare ``mj_step``."""

from __future__ import annotations

import argparse
import sys

from twin.experiments import arguments


def _cmd_bench(args: argparse.Namespace) -> int:
    from twin.experiments.bench import measure

    def progress(stage: str) -> None:
        print(f"bench: {stage} ...", file=sys.stderr, flush=True)

    for line in measure(batch_size=args.batch, workers=args.workers, progress=progress).lines():
        print(line)
    return 0


def add_parser(sub) -> None:
    bench = sub.add_parser("bench", help="cost per simulated second, as ratios to bare mj_step")
    bench.add_argument("--batch", type=arguments.positive_int, default=100, help="runs in the batched case (default 100)")
    bench.add_argument("--workers", type=arguments.positive_int, default=None, help="sweep workers (default: all cores)")
    bench.set_defaults(func=_cmd_bench)
