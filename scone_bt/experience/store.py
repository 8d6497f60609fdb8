"""The experience store: every observed outcome appended to SQLite and committed before `append` returns.

The file is WAL-mode SQLite with synchronous=FULL, so a run killed at any point (even by SIGKILL or power loss)
keeps every outcome whose `append` returned. A file that is not ours (another SQLite database, or not SQLite at
all) or that fails SQLite's integrity check raises ExperienceStoreError and is left untouched.
"""

from __future__ import annotations

import csv
import json
import sqlite3
import threading
from collections.abc import Callable
from pathlib import Path

from scone_bt.errors import ExperienceStoreError
from scone_bt.experience.types import Outcome

__all__ = ["APPLICATION_ID", "SCHEMA_VERSION", "ExperienceStore"]

APPLICATION_ID = 0x5C0E0B7  # "SCONE-BT": marks the file as ours (PRAGMA application_id)
SCHEMA_VERSION = 1
_SQLITE_MAGIC = b"SQLite format 3\x00"
_COLUMNS = ("time", "action", "object_name", "embedder", "success", "failure_stage", "context")
_SCHEMA = """
CREATE TABLE outcomes (
    id INTEGER PRIMARY KEY AUTOINCREMENT,
    time REAL NOT NULL,
    action TEXT NOT NULL,
    object_name TEXT NOT NULL,
    embedder TEXT NOT NULL,
    success INTEGER NOT NULL CHECK (success IN (0, 1)),
    failure_stage TEXT,
    context TEXT NOT NULL
);
CREATE INDEX outcomes_embedder ON outcomes (embedder);
"""


class ExperienceStore:
    """Durable, append-only log of outcomes.

    Args:
        path: SQLite file; created (with its folder) if missing, opened if it is an experience store.

    Raises:
        ExperienceStoreError: the file is corrupt, belongs to something else, has a newer schema, or cannot be
            created; the message names the file and what is wrong, and the file is never modified.
    """

    def __init__(self, path: Path | str) -> None:
        self.path = Path(path)
        self._lock = threading.Lock()
        self._conn = self._open()

    # ----- opening -----------------------------------------------------------------------------------------
    def _open(self) -> sqlite3.Connection:
        path = self.path
        existing = path.exists() and path.stat().st_size > 0
        if path.is_dir():
            raise ExperienceStoreError(f"experience store {path} is a directory; give a file path")
        if existing:
            with path.open("rb") as f:
                if f.read(16) != _SQLITE_MAGIC:
                    raise ExperienceStoreError(f"{path} is not an SQLite file; refusing to touch it")
        else:
            try:
                path.parent.mkdir(parents=True, exist_ok=True)
            except OSError as exc:
                raise ExperienceStoreError(f"cannot create a folder for {path}: {exc.strerror}") from None
        try:
            # isolation_level=None: we issue BEGIN/COMMIT ourselves, so each append is exactly one transaction
            conn = sqlite3.connect(path, timeout=30.0, isolation_level=None, check_same_thread=False)
        except sqlite3.Error as exc:
            raise ExperienceStoreError(f"cannot open experience store {path}: {exc}") from None
        try:
            if existing:
                self._check(conn)
            conn.execute("PRAGMA journal_mode=WAL")
            conn.execute("PRAGMA synchronous=FULL")
            if not existing:
                self._create(conn)
        except sqlite3.DatabaseError as exc:
            conn.close()
            raise ExperienceStoreError(f"experience store {path} is unusable: {exc}") from None
        return conn

    def _check(self, conn: sqlite3.Connection) -> None:
        path = self.path
        try:
            app_id = conn.execute("PRAGMA application_id").fetchone()[0]
            version = conn.execute("PRAGMA user_version").fetchone()[0]
            tables = {r[0] for r in conn.execute("SELECT name FROM sqlite_master WHERE type = 'table'")}
        except sqlite3.DatabaseError as exc:
            conn.close()
            raise ExperienceStoreError(f"{path} is corrupt ({exc}); it was left as it is") from None
        if app_id == 0 and not tables:
            self._create(conn)  # an empty SQLite database (e.g. made by `sqlite3 file ''`): nothing to lose
            return
        if app_id != APPLICATION_ID or "outcomes" not in tables:
            conn.close()
            raise ExperienceStoreError(
                f"{path} is an SQLite database of something else (tables: {', '.join(sorted(tables)) or 'none'}); "
                "give a new file path"
            )
        if version > SCHEMA_VERSION:
            conn.close()
            raise ExperienceStoreError(
                f"{path} has schema version {version}; this scone-bt reads up to {SCHEMA_VERSION}; upgrade scone-bt"
            )
        check = conn.execute("PRAGMA quick_check").fetchone()[0]
        if check != "ok":
            conn.close()
            raise ExperienceStoreError(f"{path} is corrupt (quick_check: {check}); it was left as it is")

    @staticmethod
    def _create(conn: sqlite3.Connection) -> None:
        conn.execute("BEGIN IMMEDIATE")
        try:
            for stmt in filter(str.strip, _SCHEMA.split(";")):
                conn.execute(stmt)
            conn.execute(f"PRAGMA application_id = {APPLICATION_ID}")
            conn.execute(f"PRAGMA user_version = {SCHEMA_VERSION}")
            conn.execute("COMMIT")
        except BaseException:
            conn.execute("ROLLBACK")
            raise

    # ----- writing -----------------------------------------------------------------------------------------
    def append(self, outcome: Outcome) -> int:
        """Store one outcome; it is committed to disk before this returns. Returns its row id."""
        try:
            context = json.dumps(outcome.context, sort_keys=True, allow_nan=False)
        except (TypeError, ValueError) as exc:
            raise ExperienceStoreError(f"outcome context must be JSON-serialisable: {exc}") from None
        row = (
            float(outcome.time),
            outcome.action,
            outcome.object_name,
            outcome.embedder,
            int(bool(outcome.success)),
            outcome.failure_stage,
            context,
        )
        with self._lock:
            conn = self._connection()
            try:
                conn.execute("BEGIN IMMEDIATE")
                cur = conn.execute(
                    f"INSERT INTO outcomes ({', '.join(_COLUMNS)}) VALUES (?, ?, ?, ?, ?, ?, ?)", row
                )
                conn.execute("COMMIT")
            except sqlite3.Error as exc:
                if conn.in_transaction:
                    conn.execute("ROLLBACK")
                raise ExperienceStoreError(f"cannot write to experience store {self.path}: {exc}") from None
            return int(cur.lastrowid)

    # ----- reading -----------------------------------------------------------------------------------------
    def outcomes(
        self, embedder: str | None = None, where: Callable[[Outcome], bool] | None = None
    ) -> list[Outcome]:
        """Stored outcomes in the order they were observed, optionally only those of one embedder / predicate."""
        sql = f"SELECT {', '.join(_COLUMNS)} FROM outcomes"
        args: tuple = ()
        if embedder is not None:
            sql += " WHERE embedder = ?"
            args = (embedder,)
        with self._lock:
            rows = self._connection().execute(sql + " ORDER BY id", args).fetchall()
        out = [
            Outcome(
                time=t,
                action=a,
                object_name=o,
                embedder=e,
                success=bool(s),
                failure_stage=f,
                context=json.loads(c),
            )
            for t, a, o, e, s, f, c in rows
        ]
        return [o for o in out if where(o)] if where is not None else out

    def __len__(self) -> int:
        with self._lock:
            return int(self._connection().execute("SELECT COUNT(*) FROM outcomes").fetchone()[0])

    def export_csv(self, path: Path | str) -> Path:
        """Write every outcome to a CSV file (context as a JSON column); returns the path."""
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        with path.open("w", newline="") as f:
            writer = csv.writer(f)
            writer.writerow(_COLUMNS)
            for o in self.outcomes():
                writer.writerow(
                    [
                        repr(o.time),
                        o.action,
                        o.object_name,
                        o.embedder,
                        int(o.success),
                        o.failure_stage or "",
                        json.dumps(o.context, sort_keys=True),
                    ]
                )
        return path

    # ----- lifetime ----------------------------------------------------------------------------------------
    def _connection(self) -> sqlite3.Connection:
        if self._conn is None:
            raise ExperienceStoreError(f"experience store {self.path} is closed")
        return self._conn

    def close(self) -> None:
        """Close the file (everything appended is already on disk)."""
        with self._lock:
            if self._conn is not None:
                self._conn.close()
                self._conn = None

    def __enter__(self) -> ExperienceStore:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __repr__(self) -> str:
        return f"ExperienceStore({str(self.path)!r})"
