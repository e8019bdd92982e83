"""A sweep's results on disk: one SQLite row per finished scenario, written in
a transaction as each batch completes, so a crash, Ctrl-C or kill loses at most
the scenarios in flight and a re-run skips what is done (but retries what failed).

The store records the version of the code and parameters that wrote it and
refuses to be resumed by another, so stale numbers are never mixed in.
"""

from __future__ import annotations

import json
import pathlib
import sqlite3

from twin.exceptions import TwinError

COLUMNS = ("key", "controller", "trajectory", "payload_g", "orientation", "plant", "seed", "supply_kpa",
           "pwm_period_ms", "noise", "rmse_deg", "sse_deg", "max_error_deg", "duration_s",
           "peak_spur_tooth_n", "peak_rack_tooth_n", "status", "reason", "warnings")


class StaleStore(TwinError):
    """A results store written by another version of the code or parameters."""


class StoreUnwritable(TwinError):
    """The results store cannot be created or written where asked."""


class StoreNotMade(StoreUnwritable):
    """The results store could not even be opened or made: it holds no finished run."""


class ResultStore:
    def __init__(self, path: pathlib.Path, *, version: str):
        self.path = path
        self._db: sqlite3.Connection | None = None
        try:
            self._db = sqlite3.connect(path)
            foreign = self._foreign_tables()
            if foreign:
                raise StaleStore(f"{path} is not a results store of this twin (it holds a table {foreign!r} that "
                                 "this store does not make): use a new --out folder")
            self._db.execute("PRAGMA journal_mode=WAL")
            with self._db:
                self._db.execute(f"CREATE TABLE IF NOT EXISTS results ({', '.join(COLUMNS)}, PRIMARY KEY (key))")
                self._db.execute("CREATE TABLE IF NOT EXISTS meta (name TEXT PRIMARY KEY, value TEXT)")
            self._claim(version)
        except (sqlite3.Error, StaleStore) as error:  # closed: a store refused holds no file open
            if self._db is not None:
                self._db.close()
            if isinstance(error, StaleStore):
                raise
            # a folder that exists but cannot be written, a full disk, a broken file
            raise StoreNotMade(f"cannot write the results store {path}: {error}") from None

    def _foreign_tables(self) -> str | None:
        """The first table the file holds that this store would not make (another name, or ``results`` or
        ``meta`` with other columns): an SQLite file of something else, found before anything is written."""
        expected = {"results": list(COLUMNS), "meta": ["name", "value"]}
        for (table,) in self._db.execute("SELECT name FROM sqlite_master WHERE type = 'table' AND name NOT LIKE "
                                         "'sqlite!_%' ESCAPE '!' ORDER BY name"):  # not SQLite's own (ANALYZE's)
            found = [row[0] for row in self._db.execute("SELECT name FROM pragma_table_info(?)", (table,))]
            if found != expected.get(table):
                return table
        return None

    def _claim(self, version: str) -> None:
        """Record ``version`` in a new store; refuse a store that holds another's results."""
        row = self._db.execute("SELECT value FROM meta WHERE name = 'version'").fetchone()
        if row is None and self._db.execute("SELECT COUNT(*) FROM results").fetchone()[0] == 0:
            with self._db:
                self._db.execute("INSERT INTO meta VALUES ('version', ?)", (version,))
        elif row is None or row[0] != version:
            written_by = "an older twin that did not record its version" if row is None else row[0]
            raise StaleStore(f"{self.path} holds results of another version of the code or parameters "
                             f"({written_by}; this is {version}): use a new --out folder")

    def done(self) -> set[str]:
        """Keys of the scenarios that finished ok (a failed one is run again)."""
        return {row[0] for row in self._db.execute("SELECT key FROM results WHERE status = 'ok'")}

    def add(self, records: list[dict]) -> None:
        """Persist finished scenarios atomically (all of them or none)."""
        rows = [tuple(json.dumps(r[c]) if c == "warnings" else r[c] for c in COLUMNS) for r in records]
        try:
            with self._db:
                self._db.executemany(f"INSERT OR REPLACE INTO results VALUES ({', '.join('?' * len(COLUMNS))})",
                                     rows)
        except sqlite3.Error as error:  # a full disk, a folder made read-only meanwhile: rolled back
            raise StoreUnwritable(f"cannot write the results store {self.path}: {error}") from None

    def records(self, keys: list[str]) -> list[dict]:
        """The stored rows for ``keys``, in that order (missing keys skipped)."""
        found = {}
        for row in self._db.execute(f"SELECT {', '.join(COLUMNS)} FROM results"):
            record = dict(zip(COLUMNS, row, strict=True))
            record["warnings"] = json.loads(record["warnings"])
            record["noise"] = bool(record["noise"])  # SQLite keeps booleans as 0 / 1
            found[record["key"]] = record
        return [found[k] for k in keys if k in found]

    def close(self) -> None:
        self._db.close()
