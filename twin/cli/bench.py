"""``twin bench``: cost per simulated second, as ratios to bare ``mj_step``."""

from __future__ import annotations

import argparse
import sys

from twin.experiments import arguments

MAX_BATCH = 2_000  # runs in bench's one batch, each kept whole (about 1.2 MB a run): 20 times the default


def _cmd_bench(args: argparse.Namespace) -> int:
    from tqdm import tqdm

    from twin.experiments.bench import measure, planned_seconds

    # the bar counts simulated scenario-seconds out of those planned; its label names the stage
    total = planned_seconds(batch_size=args.batch, workers=args.workers)
    with tqdm(total=total, desc="bench", unit=" simulated s", unit_scale=True, file=sys.stderr,
              dynamic_ncols=True) as bar:
        bench = measure(batch_size=args.batch, workers=args.workers, bar=bar)
    for line in bench.lines():
        print(line)
    return 0


def add_parser(sub) -> None:
    bench = sub.add_parser("bench", help="cost per simulated second, as ratios to bare mj_step")
    bench.add_argument("--batch", type=arguments.checked(int, lambda v: 1 <= v <= MAX_BATCH,
                                                         f"runs in the batch must be an integer from 1 to {MAX_BATCH:,}"),
                       default=100, help=f"runs in the batched case (default 100, at most {MAX_BATCH:,})")
    bench.add_argument("--workers", type=arguments.workers, default=None, help="sweep workers (default: all cores)")
    bench.set_defaults(func=_cmd_bench)
