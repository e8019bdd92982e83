"""Sweep tables: per-scenario rows to CSV and Parquet, and a summary grouped
like the thesis's tables (mean, std and range over seeds)."""

from __future__ import annotations

import csv
import math
import pathlib
from collections.abc import Sequence

import numpy as np

from twin.batch.store import COLUMNS
from twin.sim.metrics import spread

GROUP_BY = ("controller", "trajectory", "payload_g", "orientation", "plant", "supply_kpa", "pwm_period_ms")
SUMMARY_COLUMNS = GROUP_BY + ("runs", "failed", "rmse_mean_deg", "rmse_std_deg", "rmse_min_deg", "rmse_max_deg",
                              "sse_mean_deg", "sse_min_deg", "sse_max_deg", "max_error_deg")


def _cell(value):
    """One CSV cell: lists joined with ';', booleans as true / false (as in the JSON), no "-0", and floats
    without binary noise in the last digits (6.000000000000001 -> 6.0; 12 significant digits)."""
    if isinstance(value, list | tuple):
        return ";".join(str(v) for v in value)
    if isinstance(value, bool | np.bool_):
        return "true" if value else "false"
    if isinstance(value, float | np.floating) and math.isfinite(value):
        return float(f"{float(value):.12g}") + 0.0
    return value


def write_csv(rows: Sequence[dict], columns: Sequence[str], path: pathlib.Path) -> None:
    """``rows`` as CSV with ``columns`` (lists joined with ';', None empty), written whole or not at all."""
    tmp = path.with_suffix(path.suffix + ".tmp")
    try:
        with open(tmp, "w", newline="") as handle:
            writer = csv.DictWriter(handle, fieldnames=list(columns), extrasaction="ignore")
            writer.writeheader()
            for row in rows:
                writer.writerow({c: _cell(row[c]) for c in columns})
        tmp.replace(path)  # never a half-written file
    except BaseException:
        tmp.unlink(missing_ok=True)  # nor its temporary (a full disk, an interrupt)
        raise


def write_results(rows: Sequence[dict], out: pathlib.Path) -> None:
    """``results.csv`` and ``results.parquet``, one row per scenario."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    write_csv(rows, COLUMNS, out / "results.csv")
    table = pa.table({c: [(";".join(r[c]) if c == "warnings" else r[c]) for r in rows] for c in COLUMNS})
    pq.write_table(table, out / "results.parquet.tmp")
    (out / "results.parquet.tmp").replace(out / "results.parquet")


def summarise(rows: Sequence[dict]) -> list[dict]:
    groups: dict[tuple, list[dict]] = {}
    for row in rows:
        groups.setdefault(tuple(row[c] for c in GROUP_BY), []).append(row)
    summary = []
    for key, members in groups.items():
        ok = [r for r in members if r["status"] == "ok"]
        rmse = spread([r["rmse_deg"] for r in ok] if ok else [math.nan])
        sse = spread([math.nan if r["sse_deg"] is None else r["sse_deg"] for r in ok] if ok else [math.nan])
        summary.append({
            **dict(zip(GROUP_BY, key, strict=True)), "runs": len(members), "failed": len(members) - len(ok),
            "rmse_mean_deg": rmse.mean, "rmse_std_deg": rmse.std, "rmse_min_deg": rmse.min, "rmse_max_deg": rmse.max,
            "sse_mean_deg": sse.mean, "sse_min_deg": sse.min, "sse_max_deg": sse.max,
            "max_error_deg": float(max((r["max_error_deg"] for r in ok), default=math.nan)),
        })
    return summary


def write_summary(summary: Sequence[dict], out: pathlib.Path) -> None:
    write_csv(summary, SUMMARY_COLUMNS, out / "summary.csv")


def sweep_mark(out: pathlib.Path) -> str | None:
    """The file that shows a sweep has written ``out``: its store (``results.sqlite``, from its first finished
    batch, so a stopped sweep's folder too), or a ``summary.csv`` grouped as a sweep's (by its first columns,
    so an older sweep's with fewer columns too); None if neither."""
    if (out / "results.sqlite").exists():
        return "results.sqlite"
    first_words = ",".join(GROUP_BY)
    try:
        with open(out / "summary.csv", errors="replace") as handle:
            return "summary.csv" if handle.read(len(first_words)) == first_words else None
    except OSError:  # none, or unreadable: not taken for a sweep's
        return None


def signed(value: float, width: int = 0) -> str:
    """Signed to 0.01, with a value that rounds to zero shown as +0.00, not -0.00."""
    return f"{round(value, 2) + 0.0:+{width}.2f}"


def counted(n: int, noun: str) -> str:
    """``n`` and ``noun``, plural unless one: "1 seed", "3 seeds"."""
    return f"{n} {noun}{'' if n == 1 else 's'}"


def format_summary(summary: Sequence[dict], limit: int = 40) -> str:
    shown = summary[:limit]
    kpa = ["-" if s["supply_kpa"] is None else format(s["supply_kpa"], "g") for s in shown]
    pwm = ["-" if s["pwm_period_ms"] is None else format(s["pwm_period_ms"], "g") for s in shown]
    # the free-text columns at least as wide as before and as their longest entry (a long plant name, a supply)
    wp, wk, wm = (max([least, *map(len, column)]) for least, column in
                  ((8, [s["plant"] for s in shown]), (5, kpa), (6, pwm)))
    lines = [f"{'controller':10} {'T':>2} {'payload g':>9} {'orient':>10} {'plant':>{wp}} {'kPa':>{wk}} "
             f"{'PWM ms':>{wm}} {'runs':>4} {'fail':>4} {'RMSE mean±std':>14} {'SSE range':>16}"]
    for s, k, m in zip(shown, kpa, pwm, strict=True):
        sse_range = ("   - (ends moving)" if math.isnan(s["sse_min_deg"])
                     else f"[{signed(s['sse_min_deg'], 6)},{signed(s['sse_max_deg'], 6)}]")
        lines.append(
            f"{s['controller']:10} {s['trajectory']:>2} {s['payload_g']:>9g} {s['orientation']:>10} "
            f"{s['plant']:>{wp}} {k:>{wk}} {m:>{wm}} {s['runs']:>4} {s['failed']:>4} "
            f"{s['rmse_mean_deg']:>7.2f}±{s['rmse_std_deg']:<6.2f} {sse_range}")
    if len(summary) > limit:
        lines.append(f"... {len(summary) - limit} more groups in summary.csv")
    return "\n".join(lines)
