"""The SQLite experience store: every observed outcome appended and committed before `append` returns.

The file is WAL-mode SQLite with synchronous=FULL, so a run killed at any point (even by SIGKILL or power loss)
keeps every outcome whose `append` returned. Several robot processes may share one file: writers take turns
(BEGIN IMMEDIATE with a 30 s busy timeout) and an outcome_id stored twice keeps one row. Any number of them may
also open or create the same file at once: the decision "new, empty-and-foreign, or ours" and the creation of the
schema happen under an exclusive lock on the file's folder (flock), so no robot sees another's half-made file. A file that is not ours
(another SQLite database, or not SQLite at all) or that fails SQLite's integrity check raises
ExperienceStoreError and is left untouched.

Schema 1 files (before robot ids) still open: they are upgraded to schema 2 in one transaction, after a
byte-for-byte backup beside them (`<name>.v1-backup<suffix>`), and `notice` says so. The upgrade only adds
columns (robot_id and arm from each row's context "robot", profile from "profile", outcome_id "v1-<row id>");
no existing value changes.

A row that cannot be read (context that is not a JSON object, a malformed execution context, a value of the wrong
type: damage made outside scone-bt, e.g. by hand-editing) is quarantined, never used and never changed: reads
skip it, `quarantined` says which rows and why, and a one-line warning on stderr names each row id the first time
it is met. The other rows are read as usual, so months of outcomes still rebuild κ̂. A schema 1 upgrade names
such rows in its `notice`.
"""

from __future__ import annotations

import contextlib
import fcntl
import json
import math
import os
import shutil
import sqlite3
import stat
import sys
import threading
from collections.abc import Callable, Iterable, Iterator, Sequence
from pathlib import Path
from typing import Any

from scone_bt.errors import ExperienceStoreError, SconeError
from scone_bt.experience.base import (
    COLUMNS,
    EXECUTION_KEY,
    SCHEMA_VERSION,
    OutcomeStore,
    context_json,
    note_attempt,
    where_clause,
)
from scone_bt.experience.types import ExecutionContext, Outcome

__all__ = [
    "APPLICATION_ID",
    "SCHEMA_VERSION",
    "ExperienceStore",
    "decode_row",
    "rows_named",
    "sift_rows",
    "warn_unreadable",
]

APPLICATION_ID = 0x5C0E0B7  # "SCONE-BT": marks the file as ours (PRAGMA application_id)
_SQLITE_MAGIC = b"SQLite format 3\x00"
_SCHEMA_V1 = """
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
# v1 -> v2 adds columns only; a new file is made as v1 + this, so new and upgraded files have the same shape.
_UPGRADE_V2 = """
ALTER TABLE outcomes ADD COLUMN outcome_id TEXT;
ALTER TABLE outcomes ADD COLUMN robot_id TEXT NOT NULL DEFAULT '';
ALTER TABLE outcomes ADD COLUMN arm TEXT NOT NULL DEFAULT '';
ALTER TABLE outcomes ADD COLUMN profile TEXT NOT NULL DEFAULT '';
"""
_INDEXES_V2 = """
CREATE UNIQUE INDEX outcomes_outcome_id ON outcomes (outcome_id);
CREATE INDEX outcomes_robot ON outcomes (robot_id);
CREATE INDEX outcomes_arm ON outcomes (arm);
"""


def _remove_new_store(path: Path) -> None:
    """Remove a store this process began and could not finish creating (with its WAL files): nothing was in it."""
    for p in (path, path.with_name(path.name + "-wal"), path.with_name(path.name + "-shm")):
        with contextlib.suppress(OSError):
            p.unlink()


def _statements(script: str) -> list[str]:
    return [s for s in (p.strip() for p in script.split(";")) if s]


@contextlib.contextmanager
def _transaction(conn: sqlite3.Connection) -> Iterator[None]:
    """BEGIN IMMEDIATE … COMMIT (the connection has isolation_level None): all or nothing. On any exception,
    a Ctrl-C included, it rolls back and re-raises, but only while a transaction is open: a Ctrl-C raised as
    COMMIT returns finds it committed, and a ROLLBACK then fails ("no transaction is active") and would replace
    the interrupt with a "store unusable" error."""
    conn.execute("BEGIN IMMEDIATE")
    try:
        yield
        conn.execute("COMMIT")
    except BaseException:
        with contextlib.suppress(sqlite3.Error):  # the first error is the one to report
            if conn.in_transaction:
                conn.execute("ROLLBACK")
        raise


MIN_FREE_BYTES = 1 << 20
"""Free space the store needs at open (an outcome is about 1 kB; SQLite's journal needs a few pages)."""


def _check_writable(path: Path, existing: bool) -> None:
    """A read-only file, folder or mount, or a full disk, as ExperienceStoreError (the file is not touched)."""
    if existing and not os.access(path, os.W_OK):
        raise ExperienceStoreError(
            f"experience store {path} is read-only: outcomes could not be stored; give a writable path"
        )
    if not os.access(path.parent, os.W_OK | os.X_OK):
        raise ExperienceStoreError(
            f"experience store {path}: its folder is read-only (SQLite writes {path.name}-wal beside it); "
            "give a writable path"
        )
    free = shutil.disk_usage(path.parent).free
    if free < MIN_FREE_BYTES:
        raise ExperienceStoreError(
            f"experience store {path}: disk full ({free} bytes free, at least {MIN_FREE_BYTES} needed)"
        )


@contextlib.contextmanager
def _creation_lock(folder: Path) -> Iterator[None]:
    """Exclusive among processes opening a store in `folder` (flock on the folder itself: no lock file is left).

    Where the folder cannot be locked (no read permission, a file system without flock) the opening goes on
    unlocked: such a folder is refused as unwritable anyway, and a lone robot needs no lock.
    """
    try:
        fd = os.open(folder, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0) | getattr(os, "O_CLOEXEC", 0))
    except OSError:
        yield
        return
    try:
        with contextlib.suppress(OSError):
            fcntl.flock(fd, fcntl.LOCK_EX)  # released on close, and by the kernel if the process dies
        yield
    finally:
        os.close(fd)


_TEXT_COLUMNS = ("outcome_id", "action", "object_name", "embedder", "robot_id", "arm", "profile")
_NAMED = 5
"""Quarantined rows a warning or notice names one by one (the rest are counted)."""


def _shown(value: object) -> str:
    """A stored value for a message: short, on one line, with its SQLite type."""
    kind = {str: "text", bytes: "blob", int: "integer", float: "real"}.get(type(value), "NULL")
    text = " ".join(repr(value).split())
    return f"{text[:40]}{'...' if len(text) > 40 else ''} ({kind})"


def _context_of(text: object) -> tuple[dict[str, Any] | None, str]:
    """A stored context decoded, or None and why it cannot be."""
    if not isinstance(text, str):
        return None, f"context is {_shown(text)}, not JSON text"
    try:
        ctx = json.loads(text)
    except (ValueError, RecursionError):
        return None, "context is not JSON"
    if not isinstance(ctx, dict):
        return None, f"context is a JSON {type(ctx).__name__}, not an object"
    return ctx, ""


def decode_row(row: tuple[Any, ...]) -> tuple[tuple[Any, ...] | None, str]:
    """A row in COLUMNS order checked, with its context decoded; or None and why it cannot be read (one line).

    The decoded row is what `outcome_from_row` takes; every value has the type an Outcome needs.
    """
    oid, t, a, o, e, s, f, c, r, arm, p = row
    for name, value in zip(_TEXT_COLUMNS, (oid, a, o, e, r, arm, p), strict=True):
        if not isinstance(value, str):
            return None, f"{name} is {_shown(value)}, not text"
    if not isinstance(t, int | float) or not math.isfinite(t):
        return None, f"time is {_shown(t)}, not a finite number"
    if type(s) is not int or s not in (0, 1):
        return None, f"success is {_shown(s)}, not 0 or 1"
    if f is not None and not isinstance(f, str):
        return None, f"failure_stage is {_shown(f)}, not text"
    ctx, why = _context_of(c)
    if ctx is None:
        return None, why
    if ctx.get(EXECUTION_KEY) is not None:
        try:
            ExecutionContext.from_json(ctx[EXECUTION_KEY], f"context {EXECUTION_KEY}")
        except SconeError as exc:
            return None, str(exc)
    return (oid, t, a, o, e, s, f, ctx, r, arm, p), ""


def rows_named(ids: list[int], why: dict[int, str] | None = None) -> str:
    """'row 3 (why), row 7 (why)', the first few by id, then how many more."""
    named = [f"row {i}" + (f" ({why[i]})" if why else "") for i in ids[:_NAMED]]
    more = f" and {len(ids) - _NAMED} more" if len(ids) > _NAMED else ""
    return ", ".join(named) + more


def sift_rows(
    rows: Iterable[Sequence[Any]],
    quarantined: dict[int, str],
    prepare: Callable[[list[Any]], tuple[Any, ...]] = tuple,
    name_outcome: bool = False,
) -> tuple[list[tuple[Any, ...]], list[int]]:
    """The readable rows of ``rows`` (row id, then COLUMNS), decoded, and the ids of those newly found unreadable.

    Rows already in ``quarantined`` are skipped; new unreadable ones are added to it with why (after their outcome
    id when ``name_outcome``). ``prepare`` turns a row's COLUMNS into what `decode_row` checks.
    """
    readable: list[tuple[Any, ...]] = []
    new: list[int] = []
    for row_id, *row in rows:
        if row_id in quarantined:
            continue
        decoded, why = decode_row(prepare(row))
        if decoded is None:
            quarantined[row_id] = f"outcome {row[0]}: {why}" if name_outcome else why
            new.append(row_id)
        else:
            readable.append(decoded)
    return readable, new


def warn_unreadable(location: str, new: list[int], quarantined: dict[int, str], kept_in: str) -> None:
    """The one-line stderr warning naming rows found unreadable (``kept_in``: where they stay, e.g. "the file")."""
    if not new:
        return
    rows, kept = ("", "it is") if len(new) == 1 else (f"{len(new)} rows, ", "they are")
    print(
        f"warning: experience store {location}: {rows}{rows_named(new, quarantined)}: cannot be read; left in "
        f"{kept_in} as {kept}, not learnt from",
        file=sys.stderr,
        flush=True,
    )


class ExperienceStore(OutcomeStore):
    """Durable, append-only log of outcomes in one SQLite file.

    Args:
        path: SQLite file; created (with its folder) if missing, opened if it is an experience store.

    Attributes:
        notice: One line to show the user when opening changed something (a schema upgrade), else None.
        quarantined: Rows met so far that cannot be read, by row id: why (they are skipped, never changed).

    Raises:
        ExperienceStoreError: the file is corrupt, belongs to something else, has a newer schema, or cannot be
            created; the message names the file and what is wrong, and the file is never modified.
    """

    def __init__(self, path: Path | str) -> None:
        self.path = Path(path)
        self.location = str(self.path)
        self.notice: str | None = None
        self.quarantined: dict[int, str] = {}
        self._lock = threading.Lock()
        self._conn: sqlite3.Connection | None = self._open()

    # ----- opening -----------------------------------------------------------------------------------------
    def _open(self) -> sqlite3.Connection:
        path = self.path
        if path.is_dir():
            raise ExperienceStoreError(f"experience store {path} is a directory; give a file path")
        with contextlib.suppress(OSError):
            if not stat.S_ISREG(
                os.stat(path).st_mode
            ):  # reading a FIFO's first bytes would wait for a writer
                raise ExperienceStoreError(
                    f"experience store {path} is a device, FIFO or socket, not a file; give a file path"
                )
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise ExperienceStoreError(f"cannot create a folder for {path}: {exc.strerror}") from None
        # Robots starting together on a new path: one creates the schema while the others wait, then find it made.
        with _creation_lock(path.parent):
            return self._open_locked()

    def _open_locked(self) -> sqlite3.Connection:
        path = self.path
        existing = path.exists() and path.stat().st_size > 0
        if path.exists() and not existing:
            raise ExperienceStoreError(
                f"{path} is an empty file, not an experience store; it was left as it is (give a new path)"
            )
        if existing:
            with path.open("rb") as f:
                if f.read(16) != _SQLITE_MAGIC:
                    raise ExperienceStoreError(f"{path} is not an SQLite file; refusing to touch it")
        _check_writable(path, existing)  # at open: before the first outcome, not after it
        try:
            # isolation_level=None: we issue BEGIN/COMMIT ourselves, so each append is exactly one transaction
            conn = sqlite3.connect(path, timeout=30.0, isolation_level=None, check_same_thread=False)
        except sqlite3.Error as exc:
            raise ExperienceStoreError(f"cannot open experience store {path}: {exc}") from None
        try:
            version = self._check(conn) if existing else 0
            conn.execute("PRAGMA synchronous=FULL")
            if (
                version == 1
            ):  # upgraded before the switch to WAL, so a failed upgrade leaves the file as it was
                self._upgrade_v1(conn, self._backup(conn))
            conn.execute("PRAGMA journal_mode=WAL")
            if version == 0:
                self._create(conn)
        except BaseException as exc:
            conn.close()
            if not existing:  # a Ctrl-C between WAL's header and the schema left a database with no tables
                _remove_new_store(path)
            if isinstance(exc, sqlite3.DatabaseError):
                raise ExperienceStoreError(f"experience store {path} is unusable: {exc}") from None
            raise
        return conn

    def _check(self, conn: sqlite3.Connection) -> int:
        """The schema version of an existing file (0: empty, create it); refuses anything not ours."""
        path = self.path
        try:
            app_id = conn.execute("PRAGMA application_id").fetchone()[0]
            version = conn.execute("PRAGMA user_version").fetchone()[0]
            tables = {r[0] for r in conn.execute("SELECT name FROM sqlite_master WHERE type = 'table'")}
        except sqlite3.DatabaseError as exc:
            raise ExperienceStoreError(f"{path} is corrupt ({exc}); it was left as it is") from None
        if app_id == 0 and not tables:
            return 0  # an empty SQLite database (e.g. made by `sqlite3 file ''`): nothing to lose
        if app_id != APPLICATION_ID or "outcomes" not in tables:
            raise ExperienceStoreError(
                f"{path} is an SQLite database of something else (tables: {', '.join(sorted(tables)) or 'none'}); "
                "give a new file path"
            )
        if version > SCHEMA_VERSION:
            raise ExperienceStoreError(
                f"{path} has schema version {version}; this scone-bt reads up to {SCHEMA_VERSION}; upgrade scone-bt"
            )
        check = conn.execute("PRAGMA quick_check").fetchone()[0]
        if check != "ok":
            raise ExperienceStoreError(
                f"{path} is corrupt (quick_check: {' '.join(str(check).split())[:200]}); it was left as it is"
            )
        return int(version)

    @staticmethod
    def _create(conn: sqlite3.Connection) -> None:
        with _transaction(conn):
            for stmt in _statements(_SCHEMA_V1) + _statements(_UPGRADE_V2) + _statements(_INDEXES_V2):
                conn.execute(stmt)
            conn.execute(f"PRAGMA application_id = {APPLICATION_ID}")
            conn.execute(f"PRAGMA user_version = {SCHEMA_VERSION}")

    def _backup_path(self) -> Path:
        p = self.path
        candidate = p.with_name(f"{p.stem}.v1-backup{p.suffix}")
        n = 1
        while candidate.exists():
            n += 1
            candidate = p.with_name(f"{p.stem}.v1-backup{n}{p.suffix}")
        return candidate

    def _backup(self, conn: sqlite3.Connection) -> Path:
        """A copy of a schema 1 file before its upgrade: byte for byte, or a snapshot if a WAL holds data."""
        backup = self._backup_path()
        wal = self.path.with_name(self.path.name + "-wal")
        try:
            if wal.exists() and wal.stat().st_size > 0:
                with sqlite3.connect(backup) as copy:
                    conn.backup(copy)  # a consistent snapshot including the WAL's pages
                copy.close()
            else:
                shutil.copyfile(self.path, backup)
        except (sqlite3.Error, OSError) as exc:
            backup.unlink(missing_ok=True)
            raise ExperienceStoreError(
                f"{self.path} has schema 1 and needs an upgrade, but its backup {backup} could not be written "
                f"({exc}); the file was left as it is"
            ) from None
        return backup

    def _upgrade_v1(self, conn: sqlite3.Connection, backup: Path | None) -> None:
        """Schema 1 → 2: add the columns in one transaction (all or nothing), after the backup was written."""
        try:
            with _transaction(conn):
                rows, unreadable = self._upgrade_rows(conn)
        except BaseException:
            if backup is not None:
                backup.unlink(missing_ok=True)  # nothing changed: the backup would only confuse
            raise
        if rows is None:  # another process upgraded it meanwhile
            if backup is not None:
                backup.unlink(missing_ok=True)
            return
        self.notice = (
            f"upgraded {self.path} from schema 1 to {SCHEMA_VERSION} ({len(rows)} outcomes kept, robot ids added); "
            f"the original is saved as {backup}"
        )
        if unreadable:
            self.notice += (
                f"; {rows_named(sorted(unreadable), unreadable)} cannot be read: "
                "kept in the file as they are, not learnt from"
            )

    @staticmethod
    def _upgrade_rows(conn: sqlite3.Connection) -> tuple[list[Any] | None, dict[int, str]]:
        """Inside the upgrade's transaction: the schema 2 columns, indexes and version; (the rows it kept, the rows
        a read will skip and why), or (None, {}) when the file no longer has schema 1."""
        if conn.execute("PRAGMA user_version").fetchone()[0] != 1:
            return None, {}
        for stmt in _statements(_UPGRADE_V2):
            conn.execute(stmt)
        rows = conn.execute("SELECT id, context FROM outcomes ORDER BY id").fetchall()
        for row_id, ctx_text in rows:
            # A row whose context cannot be read gets its columns like any other; its values stay as they
            # are and reads skip it (see decode_row below).
            ctx = _context_of(ctx_text)[0] or {}
            robot = str(ctx.get("robot", ""))
            conn.execute(
                "UPDATE outcomes SET outcome_id = ?, robot_id = ?, arm = ?, profile = ? WHERE id = ?",
                (f"v1-{row_id}", robot, robot, str(ctx.get("profile", "")), row_id),
            )
        # Every check a read makes, so the notice names each row a read will skip (a bad context or a
        # wrong-typed column alike), not only those whose context failed to parse.
        unreadable: dict[int, str] = {}
        for row_id, *row in conn.execute(f"SELECT id, {', '.join(COLUMNS)} FROM outcomes ORDER BY id"):
            why = decode_row(tuple(row))[1]
            if why:
                unreadable[row_id] = why
        for stmt in _statements(_INDEXES_V2):
            conn.execute(stmt)
        conn.execute(f"PRAGMA user_version = {SCHEMA_VERSION}")
        return rows, unreadable

    # ----- writing -----------------------------------------------------------------------------------------
    def append(self, outcome: Outcome) -> int:
        """Store one outcome; it is committed to disk before this returns. Returns its row id.

        An outcome whose outcome_id is already stored is not stored again; its existing row id is returned.
        """
        row = (
            outcome.outcome_id,
            float(outcome.time),
            outcome.action,
            outcome.object_name,
            outcome.embedder,
            int(bool(outcome.success)),
            outcome.failure_stage,
            context_json(outcome),
            outcome.robot_id,
            outcome.arm,
            outcome.profile,
        )
        with self._lock:
            conn = self._connection()
            note_attempt(self.location, outcome.outcome_id)
            try:  # an interrupt mid-write: the outcome is stored wholly or not at all (_transaction)
                with _transaction(conn):
                    conn.execute(
                        f"INSERT INTO outcomes ({', '.join(COLUMNS)}) VALUES ({', '.join('?' * len(COLUMNS))}) "
                        "ON CONFLICT (outcome_id) DO NOTHING",
                        row,
                    )
                    row_id = conn.execute(
                        "SELECT id FROM outcomes WHERE outcome_id = ?", (outcome.outcome_id,)
                    ).fetchone()[0]
            except sqlite3.Error as exc:
                raise ExperienceStoreError(f"cannot write to experience store {self.path}: {exc}") from None
            return int(row_id)

    # ----- reading -----------------------------------------------------------------------------------------
    def _select(
        self, embedder: str | None, robot_id: str | None, arm: str | None, profile: str | None
    ) -> list[tuple[Any, ...]]:
        """Readable rows (contexts decoded); unreadable ones are quarantined, and named once on stderr."""
        where, args = where_clause("?", embedder=embedder, robot_id=robot_id, arm=arm, profile=profile)
        sql = f"SELECT id, {', '.join(COLUMNS)} FROM outcomes"
        sql += where
        with self._lock:
            rows = self._connection().execute(sql + " ORDER BY id", args).fetchall()
            readable, new = sift_rows(rows, self.quarantined)
        warn_unreadable(str(self.path), new, self.quarantined, "the file")
        return readable

    def __len__(self) -> int:
        with self._lock:
            return int(self._connection().execute("SELECT COUNT(*) FROM outcomes").fetchone()[0])

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

    def __repr__(self) -> str:
        return f"ExperienceStore({str(self.path)!r})"
