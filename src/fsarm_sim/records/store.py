"""Embedded results store of sweeps: one SQLite file (stdlib ``sqlite3``, WAL journal).

Every finished point is committed on its own, at once, so an interrupted sweep (Ctrl-C, kill -9,
a lost machine) keeps everything it finished; running the same command again computes only the
points whose key is missing. The key is the SHA-256 of the point's canonical JSON (sorted keys,
no whitespace, floats as Python writes them), i.e. of its exact inputs; a UNIQUE constraint on it
makes a second insert of the same point a no-op, never a duplicate row.

Each row keeps the exact inputs (the canonical JSON itself), the outputs (JSON), the project
version that computed it (``fsarm_sim.__version__``), where and how long it ran, and its status
(``ok`` or ``error`` with the message). Only the process that runs the sweep writes; workers
return results to it.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import socket
import sqlite3
import time
from collections.abc import Iterable, Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from fsarm_sim._version import __version__
from fsarm_sim.errors import FsarmError
from fsarm_sim.paths import checked_path, named_os_errors, regular_file

SCHEMA_VERSION = 1
_SCHEMA = """
CREATE TABLE IF NOT EXISTS meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS points (
    id INTEGER PRIMARY KEY AUTOINCREMENT,
    key TEXT NOT NULL UNIQUE,          -- sha256 of inputs_json
    sweep TEXT NOT NULL,               -- name of the sweep that computed it
    inputs_json TEXT NOT NULL,         -- canonical JSON of the point (exact inputs)
    outputs_json TEXT,                 -- JSON of the results (NULL on error)
    status TEXT NOT NULL CHECK (status IN ('ok', 'error')),
    error TEXT,
    version TEXT NOT NULL,             -- fsarm_sim.__version__ that computed it
    host TEXT NOT NULL,
    wall_s REAL NOT NULL,
    finished_unix REAL NOT NULL
);
"""


class StoreError(FsarmError, RuntimeError):
    """The results store cannot be opened, is not an fsarm store, or a value cannot be stored."""


class ForeignStoreError(StoreError):
    """The file given as a results store is not one fsarm created (another program's SQLite
    database, or not SQLite at all); it is left untouched."""


SQLITE_HEADER = b"SQLite format 3\x00"


def check_store_file(path: Path) -> None:
    """Refuse, without writing a byte, a file that is not an fsarm results store.

    Allowed: no file, an empty file, an SQLite database without tables, or an fsarm store
    (tables ``meta`` and ``points``, ``meta`` holding ``schema_version``). Everything else raises
    :class:`ForeignStoreError`. The check opens the database read-only.
    """
    checked_path(path, "results store", StoreError)  # loops, long names ...
    if os.path.lexists(path):  # a device or a pipe would never answer SQLite
        regular_file(path, "results store", StoreError)
    with named_os_errors("results store", path, StoreError):
        if not path.exists() or path.stat().st_size == 0:
            return
    try:
        with path.open("rb") as f:
            head = f.read(len(SQLITE_HEADER))
    except OSError as exc:
        raise StoreError(f"results store {path} cannot be read ({exc.strerror})") from exc
    if head != SQLITE_HEADER:
        raise ForeignStoreError(
            f"{path} is not a usable SQLite results store: it is not an SQLite file (left "
            "untouched); give a new file name or an existing fsarm store"
        )
    try:
        real = checked_path(path, "results store", StoreError)
        db = sqlite3.connect(f"{real.as_uri()}?mode=ro", uri=True, timeout=30.0)
        try:
            tables = {r[0] for r in db.execute("SELECT name FROM sqlite_master WHERE type='table'")}
            marker = (
                db.execute("SELECT value FROM meta WHERE key = 'schema_version'").fetchone()
                if "meta" in tables
                else None
            )
        finally:
            db.close()
    except sqlite3.DatabaseError as exc:
        raise ForeignStoreError(
            f"{path} is not a usable SQLite results store ({exc}); it was left untouched"
        ) from exc
    if tables and ({"meta", "points"} - tables or marker is None):
        shown = ", ".join(sorted(tables)[:5]) + (", ..." if len(tables) > 5 else "")
        raise ForeignStoreError(
            f"{path} is an SQLite database that fsarm did not create (tables: {shown}; an fsarm "
            "store has 'meta' with a schema_version and 'points'); it was left untouched - give "
            "a new file name for the results store"
        )


def _finite(value: Any, where: str) -> Any:
    """Reject NaN/inf anywhere in a JSON-able value (canonical JSON has no NaN)."""
    if isinstance(value, float) and not math.isfinite(value):
        raise StoreError(f"{where} is {value!r}: inputs must be finite numbers")
    if isinstance(value, Mapping):
        for k, v in value.items():
            if not isinstance(k, str):
                raise StoreError(f"{where}: keys must be strings, got {k!r}")
            _finite(v, f"{where}.{k}")
    elif isinstance(value, list | tuple):
        for i, v in enumerate(value):
            _finite(v, f"{where}[{i}]")
    return value


def canonical_json(point: Mapping[str, Any]) -> str:
    """The one text of a point: sorted keys, no whitespace, no NaN, ints of float fields kept."""
    _finite(point, "point")
    return json.dumps(point, sort_keys=True, separators=(",", ":"), allow_nan=False)


def point_key(point: Mapping[str, Any]) -> str:
    """SHA-256 (hex) of the canonical JSON: the store's unique key of a point."""
    return hashlib.sha256(canonical_json(point).encode("utf-8")).hexdigest()


def _json_outputs(outputs: Mapping[str, Any]) -> str:
    """Outputs may hold NaN (e.g. no -3 dB crossing found): stored as null."""

    def clean(v: Any) -> Any:
        if isinstance(v, float) and not math.isfinite(v):
            return None
        if isinstance(v, Mapping):
            return {str(k): clean(x) for k, x in v.items()}
        if isinstance(v, list | tuple):
            return [clean(x) for x in v]
        return v

    return json.dumps(clean(dict(outputs)), sort_keys=True, allow_nan=False)


@dataclass(frozen=True)
class Row:
    key: str
    sweep: str
    inputs: dict[str, Any]
    outputs: dict[str, Any] | None
    status: str
    error: str | None
    version: str
    host: str
    wall_s: float


class ResultStore:
    """A sweep results file. Use as a context manager or call :meth:`close`."""

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        checked_path(self.path, "results store", StoreError)  # loops, long names ...
        if self.path.exists() and not self.path.is_file():
            raise StoreError(f"results store {self.path} exists and is not a file")
        check_store_file(self.path)  # before anything is written to it
        if self.path.parent and not self.path.parent.exists():
            with named_os_errors("the folder of the results store", self.path.parent, StoreError):
                self.path.parent.mkdir(parents=True, exist_ok=True)
        try:
            self._db = sqlite3.connect(str(self.path), timeout=30.0, isolation_level=None)
            self._db.execute("PRAGMA journal_mode=WAL")
            self._db.execute("PRAGMA synchronous=NORMAL")  # WAL + NORMAL: a commit survives kill -9
            # tables and marker in one transaction: a store never exists without its marker
            self._db.executescript(
                f"BEGIN; {_SCHEMA} INSERT OR IGNORE INTO meta (key, value) VALUES "
                f"('schema_version', '{SCHEMA_VERSION}'); COMMIT;"
            )
            found = self._db.execute(
                "SELECT value FROM meta WHERE key = 'schema_version'"
            ).fetchone()
        except sqlite3.DatabaseError as exc:
            raise StoreError(f"{self.path} is not a usable SQLite results store ({exc})") from exc
        if int(found[0]) != SCHEMA_VERSION:
            raise StoreError(
                f"{self.path} has store schema {found[0]}, this fsarm-sim writes {SCHEMA_VERSION}"
            )

    # -- context manager
    def __enter__(self) -> ResultStore:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        self._db.close()

    # -- writing
    def put(
        self,
        point: Mapping[str, Any],
        outputs: Mapping[str, Any] | None,
        *,
        sweep: str = "",
        wall_s: float = 0.0,
        error: str | None = None,
        host: str | None = None,
    ) -> bool:
        """Store one finished point (committed at once). Returns False if it was already there."""
        inputs = canonical_json(point)
        key = hashlib.sha256(inputs.encode("utf-8")).hexdigest()
        status = "error" if error is not None else "ok"
        cur = self._write(
            "INSERT OR IGNORE INTO points (key, sweep, inputs_json, outputs_json, status, error, "
            "version, host, wall_s, finished_unix) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
            (
                key,
                sweep,
                inputs,
                _json_outputs(outputs) if outputs is not None else None,
                status,
                error,
                __version__,
                host or socket.gethostname(),
                float(wall_s),
                time.time(),
            ),
        )
        return cur.rowcount == 1

    def set_meta(self, key: str, value: str) -> None:
        self._write("INSERT OR REPLACE INTO meta (key, value) VALUES (?, ?)", (key, value))

    def _write(self, sql: str, args: tuple[Any, ...]) -> sqlite3.Cursor:
        """One committed write; a full disk (or a file that became read-only) is a
        :class:`StoreError` that says the points stored so far are kept."""
        try:
            return self._db.execute(sql, args)
        except sqlite3.DatabaseError as exc:  # "database or disk is full", "disk I/O error" ...
            try:
                kept = f"the {self.count()} point(s) stored before are kept"
            except sqlite3.DatabaseError:
                kept = "the points stored before are kept"
            raise StoreError(
                f"results store {self.path}: cannot store more ({exc}); {kept} - free space (or "
                "make the file writable) and rerun the same command to resume"
            ) from exc

    def delete_errors(self, keys: Iterable[str] | None = None) -> int:
        """Forget failed points (all, or those keys) so the next run retries them."""
        if keys is None:
            return int(self._db.execute("DELETE FROM points WHERE status = 'error'").rowcount)
        n = 0
        for k in keys:
            n += self._db.execute(
                "DELETE FROM points WHERE status = 'error' AND key = ?", (k,)
            ).rowcount
        return n

    # -- reading
    def meta(self, key: str) -> str | None:
        row = self._db.execute("SELECT value FROM meta WHERE key = ?", (key,)).fetchone()
        return None if row is None else str(row[0])

    def keys(self) -> set[str]:
        return {r[0] for r in self._db.execute("SELECT key FROM points")}

    def errors(self) -> dict[str, str]:
        """Key -> error message of every failed point in the store."""
        return {
            r[0]: str(r[1] or "")
            for r in self._db.execute("SELECT key, error FROM points WHERE status = 'error'")
        }

    def count(self, status: str | None = None) -> int:
        if status is None:
            return int(self._db.execute("SELECT COUNT(*) FROM points").fetchone()[0])
        return int(
            self._db.execute("SELECT COUNT(*) FROM points WHERE status = ?", (status,)).fetchone()[
                0
            ]
        )

    def __contains__(self, point: Mapping[str, Any]) -> bool:
        return (
            self._db.execute("SELECT 1 FROM points WHERE key = ?", (point_key(point),)).fetchone()
            is not None
        )

    def rows(self, sweep: str | None = None, status: str | None = None) -> Iterator[Row]:
        sql = (
            "SELECT key, sweep, inputs_json, outputs_json, status, error, version, host, wall_s "
            "FROM points"
        )
        cond, args = [], []
        if sweep is not None:
            cond.append("sweep = ?")
            args.append(sweep)
        if status is not None:
            cond.append("status = ?")
            args.append(status)
        if cond:
            sql += " WHERE " + " AND ".join(cond)
        for r in self._db.execute(sql + " ORDER BY id", args):
            yield Row(
                key=r[0],
                sweep=r[1],
                inputs=json.loads(r[2]),
                outputs=None if r[3] is None else json.loads(r[3]),
                status=r[4],
                error=r[5],
                version=r[6],
                host=r[7],
                wall_s=float(r[8]),
            )

    def frame(self, sweep: str | None = None) -> Any:
        """The ``ok`` rows as a pandas DataFrame: input columns, then output columns."""
        import pandas as pd

        records = []
        for row in self.rows(sweep, status="ok"):
            rec: dict[str, Any] = {"key": row.key, "version": row.version, "wall_s": row.wall_s}
            rec.update({k: v for k, v in row.inputs.items() if not isinstance(v, list | dict)})
            for k, v in (row.outputs or {}).items():
                if not isinstance(v, list | dict):
                    rec[k] = v
            records.append(rec)
        return pd.DataFrame.from_records(records)
