"""The PostgreSQL experience store, for a fleet of robots sharing what they learn (the only psycopg importer).

Same schema and guarantees as the SQLite store: each `append` is one autocommitted INSERT, so it is durable
(synchronous_commit) before it returns; robots insert concurrently without waiting on each other (row inserts
take no table lock); the UNIQUE outcome_id makes a retried or replayed append a no-op, so a robot whose
connection dropped mid-append reconnects and appends again without risk of a duplicate.

Tables: scone_meta (application, schema_version) and scone_outcomes. A database whose scone_outcomes table has
no scone_meta, or a newer schema, is refused and left untouched.

A row that cannot be read (a context that is not a JSON object, a malformed execution context: damage made
outside scone-bt) is quarantined as the SQLite store does it: reads skip it, `quarantined` says which rows and why,
a one-line warning on stderr names each row the first time this store meets it, and the robots go on learning
from the other rows. The row stays in the database as it is.
"""

from __future__ import annotations

import contextlib
import json
import re
import threading
from typing import Any

from scone_bt.errors import ExperienceStoreError
from scone_bt.experience.base import (
    COLUMNS,
    SCHEMA_VERSION,
    OutcomeStore,
    context_json,
    note_attempt,
    where_clause,
)
from scone_bt.experience.types import Outcome

__all__ = ["CONNECT_TIMEOUT_S", "PostgresExperienceStore", "is_postgres_url", "redact_url"]

CONNECT_TIMEOUT_S = 10
"""Deadline for reaching the PostgreSQL server, TCP and login included (seconds; libpq's connect_timeout): a server
that accepts connections and never answers is a one-line error after this long, before the robot acts."""

_APPLICATION = "scone-bt"
_LOCK_KEY = 0x5C0E0B7  # advisory lock serialising schema creation by robots starting together
_SCHEMA = [
    "CREATE TABLE IF NOT EXISTS scone_meta (key TEXT PRIMARY KEY, value TEXT NOT NULL)",
    """CREATE TABLE IF NOT EXISTS scone_outcomes (
        id BIGSERIAL PRIMARY KEY,
        outcome_id TEXT NOT NULL UNIQUE,
        "time" DOUBLE PRECISION NOT NULL,
        action TEXT NOT NULL,
        object_name TEXT NOT NULL,
        embedder TEXT NOT NULL,
        success BOOLEAN NOT NULL,
        failure_stage TEXT,
        context JSONB NOT NULL,
        robot_id TEXT NOT NULL DEFAULT '',
        arm TEXT NOT NULL DEFAULT '',
        profile TEXT NOT NULL DEFAULT ''
    )""",
    "CREATE INDEX IF NOT EXISTS scone_outcomes_embedder ON scone_outcomes (embedder)",
    "CREATE INDEX IF NOT EXISTS scone_outcomes_robot ON scone_outcomes (robot_id)",
    "CREATE INDEX IF NOT EXISTS scone_outcomes_arm ON scone_outcomes (arm)",
]
_SELECT_COLUMNS = ", ".join(f'"{c}"' if c == "time" else c for c in COLUMNS)


def is_postgres_url(spec: object) -> bool:
    """True for postgresql://… and postgres://… strings."""
    return isinstance(spec, str) and spec.startswith(("postgresql://", "postgres://"))


def redact_url(url: str) -> str:
    """The URL with its password replaced by ***, for messages."""
    return re.sub(r"(://[^:/@]+:)[^@]*@", r"\1***@", url)


class PostgresExperienceStore(OutcomeStore):
    """Durable, append-only log of outcomes in a PostgreSQL database shared by a fleet.

    Args:
        url: libpq connection URL, postgresql://user[:password]@host[:port]/database.
        connect_timeout_s: Give up connecting after this long, seconds.

    Raises:
        ExperienceStoreError: the server cannot be reached, the database holds a foreign or newer
            scone_outcomes table; the message names the URL (without its password).
    """

    quarantined: dict[int, str]
    """Rows met so far that cannot be read, by row id (scone_outcomes.id): why (skipped, never changed)."""

    def __init__(self, url: str, connect_timeout_s: float = CONNECT_TIMEOUT_S) -> None:
        if not is_postgres_url(url):
            raise ExperienceStoreError(
                f"{url!r} is not a PostgreSQL URL; expected postgresql://user@host:port/db"
            )
        self.url = url
        self.location = redact_url(url)
        self.notice: str | None = None
        self.quarantined = {}
        self._timeout = connect_timeout_s
        self._lock = threading.Lock()
        self._conn: Any = None
        self._closed = False
        with self._lock:
            self._connect()
            self._ensure_schema()

    # ----- connection --------------------------------------------------------------------------------------
    def _connect(self) -> Any:
        import psycopg

        try:
            self._conn = psycopg.connect(
                self.url,
                autocommit=True,
                connect_timeout=max(1, int(self._timeout)),
                application_name="scone-bt",
            )
        except psycopg.Error as exc:
            first = (str(exc).strip().splitlines() or [type(exc).__name__])[0]
            raise ExperienceStoreError(
                f"cannot connect to experience store {self.location}: {first}"
            ) from None
        return self._conn

    def _connection(self) -> Any:
        if self._closed:
            raise ExperienceStoreError(f"experience store {self.location} is closed")
        if self._conn is None or self._conn.closed:
            self._connect()
        return self._conn

    def _ensure_schema(self) -> None:
        import psycopg

        conn = self._connection()
        try:
            with conn.transaction():
                conn.execute("SELECT pg_advisory_xact_lock(%s)", (_LOCK_KEY,))
                tables = {
                    r[0]
                    for r in conn.execute(
                        "SELECT table_name FROM information_schema.tables "
                        "WHERE table_schema = current_schema() AND table_name IN ('scone_meta', 'scone_outcomes')"
                    )
                }
                if "scone_outcomes" in tables and "scone_meta" not in tables:
                    raise ExperienceStoreError(
                        f"{self.location} has a scone_outcomes table that scone-bt did not create; "
                        "give another database"
                    )
                if "scone_meta" in tables:
                    meta = dict(conn.execute("SELECT key, value FROM scone_meta").fetchall())
                    if meta.get("application") != _APPLICATION:
                        raise ExperienceStoreError(
                            f"{self.location} has a scone_meta table of something else; give another database"
                        )
                    version = int(meta.get("schema_version", "0"))
                    if version > SCHEMA_VERSION:
                        raise ExperienceStoreError(
                            f"{self.location} has schema version {version}; this scone-bt reads up to "
                            f"{SCHEMA_VERSION}; upgrade scone-bt"
                        )
                    return
                for stmt in _SCHEMA:
                    conn.execute(stmt)
                conn.execute(
                    "INSERT INTO scone_meta (key, value) VALUES ('application', %s), ('schema_version', %s)",
                    (_APPLICATION, str(SCHEMA_VERSION)),
                )
        except psycopg.Error as exc:
            first = (str(exc).strip().splitlines() or [type(exc).__name__])[0]
            raise ExperienceStoreError(f"experience store {self.location} is unusable: {first}") from None

    # ----- writing -----------------------------------------------------------------------------------------
    def append(self, outcome: Outcome) -> int:
        """Store one outcome, committed before this returns; returns its row id (the existing one on a replay)."""
        import psycopg

        row = (
            outcome.outcome_id,
            float(outcome.time),
            outcome.action,
            outcome.object_name,
            outcome.embedder,
            bool(outcome.success),
            outcome.failure_stage,
            context_json(outcome),
            outcome.robot_id,
            outcome.arm,
            outcome.profile,
        )
        placeholders = ", ".join(["%s"] * 7 + ["%s::jsonb"] + ["%s"] * 3)
        insert = (
            f"INSERT INTO scone_outcomes ({_SELECT_COLUMNS}) VALUES ({placeholders}) "
            "ON CONFLICT (outcome_id) DO NOTHING RETURNING id"
        )
        with self._lock:
            note_attempt(self.location, outcome.outcome_id)
            for attempt in (1, 2):  # one reconnect: the key makes a second INSERT of a committed row a no-op
                try:
                    conn = self._connection()
                    got = conn.execute(insert, row).fetchone()
                    if got is None:  # already stored (a replay)
                        got = conn.execute(
                            "SELECT id FROM scone_outcomes WHERE outcome_id = %s", (outcome.outcome_id,)
                        ).fetchone()
                    return int(got[0])
                except psycopg.OperationalError as exc:
                    self._drop()
                    if attempt == 2:
                        first = (str(exc).strip().splitlines() or [type(exc).__name__])[0]
                        raise ExperienceStoreError(
                            f"cannot write to experience store {self.location}: {first}"
                        ) from None
                except psycopg.Error as exc:
                    first = (str(exc).strip().splitlines() or [type(exc).__name__])[0]
                    raise ExperienceStoreError(
                        f"cannot write to experience store {self.location}: {first}"
                    ) from None
        raise AssertionError("unreachable")

    # ----- reading -----------------------------------------------------------------------------------------
    def _select(
        self, embedder: str | None, robot_id: str | None, arm: str | None, profile: str | None
    ) -> list[tuple[Any, ...]]:
        """Readable rows (contexts decoded); unreadable ones are quarantined, and named once on stderr."""
        import psycopg

        from scone_bt.experience.store import sift_rows, warn_unreadable

        where, args = where_clause("%s", embedder=embedder, robot_id=robot_id, arm=arm, profile=profile)
        sql = f"SELECT id, {_SELECT_COLUMNS} FROM scone_outcomes"
        sql += where
        with self._lock:
            try:
                rows = self._connection().execute(sql + " ORDER BY id", args).fetchall()
            except psycopg.Error as exc:
                self._drop()
                first = (str(exc).strip().splitlines() or [type(exc).__name__])[0]
                raise ExperienceStoreError(f"cannot read experience store {self.location}: {first}") from None
            readable, new = sift_rows(rows, self.quarantined, _as_stored, name_outcome=True)
        warn_unreadable(self.location, new, self.quarantined, "the database")
        return readable

    def __len__(self) -> int:
        with self._lock:
            return int(self._connection().execute("SELECT COUNT(*) FROM scone_outcomes").fetchone()[0])

    # ----- lifetime ----------------------------------------------------------------------------------------
    def _drop(self) -> None:
        if self._conn is not None:
            with contextlib.suppress(Exception):  # a broken connection may fail to close; dropped either way
                self._conn.close()
            self._conn = None

    def close(self) -> None:
        """Close the connection (everything appended is already committed)."""
        with self._lock:
            self._drop()
            self._closed = True

    def __repr__(self) -> str:
        return f"PostgresExperienceStore({self.location!r})"


def _as_stored(row: list[Any]) -> tuple[Any, ...]:
    """A PostgreSQL row in COLUMNS order as the SQLite store holds it, for the one check both share
    (`store.decode_row`): success as 0 or 1, the context as JSON text (jsonb hands back any JSON value)."""
    oid, t, a, o, e, s, f, c, r, arm, p = row
    success = int(s) if isinstance(s, bool) else s
    context = c if isinstance(c, str) else json.dumps(c)
    return (oid, t, a, o, e, success, f, context, r, arm, p)
