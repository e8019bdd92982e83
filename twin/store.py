"""A sweep's results on disk: one SQLite row per finished scenario, written in
a transaction as each batch completes, so a crash, Ctrl-C or kill loses at most
the scenarios in flight and a re-run skips what is done.
"""

from __future__ import annotations

import json
import pathlib
import sqlite3

COLUMNS = ("key", "controller", "trajectory", "payload_g", "orientation", "plant", "seed", "supply_kpa",
           "pwm_period_ms", "noise", "rmse_deg", "sse_deg", "max_error_deg", "duration_s",
           "peak_spur_tooth_n", "peak_rack_tooth_n", "status", "reason", "warnings")


class ResultStore:
    def __init__(self, path: pathlib.Path):
        self.path = path
        self._db = sqlite3.connect(path)
        self._db.execute("PRAGMA journal_mode=WAL")
        self._db.execute(f"CREATE TABLE IF NOT EXISTS results ({', '.join(COLUMNS)}, PRIMARY KEY (key))")
        self._db.commit()

    def done(self) -> set[str]:
        return {row[0] for row in self._db.execute("SELECT key FROM results")}

    def add(self, records: list[dict]) -> None:
        """Persist finished scenarios atomically (all of them or none)."""
        rows = [tuple(json.dumps(r[c]) if c == "warnings" else r[c] for c in COLUMNS) for r in records]
        with self._db:
            self._db.executemany(f"INSERT OR REPLACE INTO results VALUES ({', '.join('?' * len(COLUMNS))})", rows)

    def records(self, keys: list[str]) -> list[dict]:
        """The stored rows for ``keys``, in that order (missing keys skipped)."""
        found = {}
        for row in self._db.execute(f"SELECT {', '.join(COLUMNS)} FROM results"):
            record = dict(zip(COLUMNS, row, strict=True))
            record["warnings"] = json.loads(record["warnings"])
            found[record["key"]] = record
        return [found[k] for k in keys if k in found]

    def close(self) -> None:
        self._db.close()
