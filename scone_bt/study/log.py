"""The study log: sessions, timestamped events and questionnaire answers in one SQLite file.

Every event is committed on its own (WAL journal, synchronous=FULL), the same rule as the experience store: a crash
loses nothing that was recorded. The file is never overwritten; a file that is not a study log is refused.
Simulated studies are labelled in the file (meta `simulated`) and on every session row.
"""

from __future__ import annotations

import json
import os
import sqlite3
import threading
import time
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from scone_bt.errors import SconeError
from scone_bt.events import (
    EVENT_TYPES,
    INTERVENTION_CAUSES,
    Event,
    EventSink,
    Intervention,
    from_json,
    is_legacy_takeover,
)
from scone_bt.study.design import SessionPlan
from scone_bt.study.questionnaires import get_questionnaire, validate_answers

__all__ = [
    "UNRECORDED_CAUSE",
    "StudyLog",
    "StudyLogError",
    "SessionRow",
    "EventRow",
    "ResponseRow",
    "SCHEMA_VERSION",
    "EXPORT_FILES",
]

SCHEMA_VERSION = 1
_SQLITE_MAGIC = b"SQLite format 3\x00"
EXPORT_FILES = ("sessions.csv", "events.csv", "responses.csv", "scores.csv")
"""What `export_csv` writes into its folder."""
_SESSION_KEY = ("data", "session_id", "participant", "group", "session_index", "condition")
_CAUSE_COLUMNS = tuple(f"interventions_{cause.replace('-', '_')}" for cause in INTERVENTION_CAUSES)
_SESSION_COLUMNS = (*_SESSION_KEY, "started", "ended", "interventions", *_CAUSE_COLUMNS, "summary")
UNRECORDED_CAUSE = "unrecorded"
"""The cause under which an intervention of a log written before causes were stored is counted."""
_RESPONSE_COLUMNS = ("data", "session_id", "questionnaire", "item", "item_index", "value", "time")
_SCORE_COLUMNS = (*_SESSION_KEY, "questionnaire", "score", "subscales")

_SCHEMA = """
CREATE TABLE IF NOT EXISTS meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE IF NOT EXISTS sessions (
    id INTEGER PRIMARY KEY AUTOINCREMENT,
    participant TEXT NOT NULL,
    grp TEXT NOT NULL,
    session_index INTEGER NOT NULL,
    condition TEXT NOT NULL,
    simulated INTEGER NOT NULL,
    started REAL NOT NULL,
    ended REAL,
    info TEXT NOT NULL DEFAULT '{}',
    summary TEXT
);
CREATE TABLE IF NOT EXISTS events (
    id INTEGER PRIMARY KEY AUTOINCREMENT,
    session_id INTEGER NOT NULL REFERENCES sessions(id),
    time REAL NOT NULL,
    kind TEXT NOT NULL,
    data TEXT NOT NULL
);
CREATE TABLE IF NOT EXISTS responses (
    id INTEGER PRIMARY KEY AUTOINCREMENT,
    session_id INTEGER NOT NULL REFERENCES sessions(id),
    time REAL NOT NULL,
    questionnaire TEXT NOT NULL,
    item TEXT NOT NULL,
    item_index INTEGER NOT NULL,
    value REAL,
    UNIQUE (session_id, questionnaire, item)
);
CREATE INDEX IF NOT EXISTS events_session ON events(session_id);
"""


def _session_key(label: str, s: SessionRow) -> dict[str, Any]:
    """The columns every per-session CSV row starts with (`_SESSION_KEY`)."""
    return dict(
        zip(_SESSION_KEY, (label, s.id, s.participant, s.group, s.session_index, s.condition), strict=True)
    )


def _readonly_uri(path: Path) -> str:
    """An SQLite URI that reads without creating or changing any file.

    mode=ro alone still creates `-wal` and `-shm` files beside a WAL database (and leaves them, since a read-only
    connection cannot remove them) or fails on a read-only mount. Without a `-wal` file there is nothing
    uncommitted to read, so the file is opened immutable: no journal files, no locks. With one (a live writer, or
    a crash), mode=ro reads it through the existing files.
    """
    path = path.absolute()
    uri = f"{path.as_uri()}?mode=ro"
    wal = path.with_name(path.name + "-wal")
    return uri + ("&immutable=1" if not wal.exists() or not os.access(path.parent, os.W_OK) else "")


class StudyLogError(SconeError):
    """A study log that is not one, is from a newer version, or mixes simulated and real data."""


@dataclass(frozen=True)
class SessionRow:
    """One session as stored. Times are Unix seconds; `ended` is None for a session that did not finish."""

    id: int
    participant: str
    group: str
    session_index: int
    condition: str
    simulated: bool
    started: float
    ended: float | None
    info: dict[str, Any]
    summary: dict[str, Any] | None


@dataclass(frozen=True)
class EventRow:
    """One stored event: its kind (`scone_bt.events.EVENT_TYPES`) and its JSON payload (`typed_events` reads
    them back as typed events)."""

    id: int
    session_id: int
    time: float
    kind: str
    data: dict[str, Any]


@dataclass(frozen=True)
class ResponseRow:
    """One questionnaire answer; value None is "does not fit"."""

    session_id: int
    questionnaire: str
    item: str
    item_index: int
    value: float | None
    time: float


class StudyLog:
    """Append-only study database. Thread-safe: the tablet's web thread and the episode loop share one.

    Args:
        path: SQLite file (created with its folder if missing).
        simulated: Label for a new file; an existing file must carry the same label.
    """

    def __init__(self, path: str | Path, simulated: bool = False, readonly: bool = False) -> None:
        self.path = Path(path)
        self.readonly = readonly
        self._lock = threading.Lock()
        existing = self.path.exists()
        if existing and not readonly and not os.access(self.path, os.W_OK):
            raise StudyLogError(
                f"{self.path} is read-only; sessions cannot be recorded in it (it was left as it is)"
            )
        if existing:
            meta = self._inspect()  # read-only: a file that is not ours is refused unchanged
        elif readonly:
            raise StudyLogError(f"study log not found: {self.path}")
        else:
            meta = {}
        self._db = self._connect(existing)
        if not meta and not readonly:
            meta = {"schema_version": str(SCHEMA_VERSION), "simulated": "1" if simulated else "0"}
            with self._lock:
                try:  # one transaction: a crash leaves no half-made schema
                    self._db.executescript(
                        "BEGIN IMMEDIATE;"
                        + _SCHEMA
                        + f"INSERT INTO meta VALUES ('schema_version', '{meta['schema_version']}');"
                        + f"INSERT INTO meta VALUES ('simulated', '{meta['simulated']}');"
                        + "COMMIT;"
                    )
                except sqlite3.Error as exc:
                    self._db.close()
                    raise StudyLogError(f"cannot create study log {self.path}: {exc}") from None
        self.simulated = meta.get("simulated") == "1"
        if self.simulated != simulated and not readonly:
            self._db.close()
            kind = "SIMULATED" if self.simulated else "real"
            raise StudyLogError(
                f"{self.path} holds {kind} data; use another file rather than mixing real and simulated sessions"
            )

    def _inspect(self) -> dict[str, str]:
        """Check an existing file without writing to it; its meta table, or StudyLogError saying what it is."""
        path = self.path
        if path.is_dir():
            raise StudyLogError(f"{path} is a folder; give a study log file")
        try:
            with path.open("rb") as fh:
                head = fh.read(16)
        except OSError as exc:
            raise StudyLogError(f"cannot read {path}: {exc.strerror or exc}") from None
        if not head:
            raise StudyLogError(
                f"{path} is an empty file, not a study log; it was left as it is (give a new path)"
            )
        if head != _SQLITE_MAGIC:
            raise StudyLogError(f"{path} is not an SQLite study log; it was left as it is")
        try:
            db = sqlite3.connect(_readonly_uri(path), uri=True)
        except sqlite3.Error as exc:
            raise StudyLogError(f"cannot open {path}: {exc}") from None
        try:
            tables = {r[0] for r in db.execute("SELECT name FROM sqlite_master WHERE type='table'")}
            if not {"meta", "sessions", "events", "responses"} <= tables:
                raise StudyLogError(
                    f"{path} is an SQLite file but not a study log (tables: {', '.join(sorted(tables)) or 'none'}); "
                    "it was left as it is"
                )
            check = db.execute("PRAGMA quick_check").fetchone()[0]
            if check != "ok":
                raise StudyLogError(
                    f"{path} is corrupt (quick_check: {' '.join(str(check).split())[:200]}); it was left as it is"
                )
            meta = {str(k): str(v) for k, v in db.execute("SELECT key, value FROM meta").fetchall()}
        except sqlite3.DatabaseError as exc:
            raise StudyLogError(
                f"{path} is corrupt or not a study log ({exc}); it was left as it is"
            ) from None
        finally:
            db.close()
        version = meta.get("schema_version", "")
        if not version.isdigit() or "simulated" not in meta:
            raise StudyLogError(f"{path} has no valid schema_version/simulated entries; it was left as it is")
        if int(version) > SCHEMA_VERSION:
            raise StudyLogError(f"{path} has schema {version}; this version reads up to {SCHEMA_VERSION}")
        return meta

    def _connect(self, existing: bool) -> sqlite3.Connection:
        path = self.path
        if self.readonly:
            try:
                return sqlite3.connect(
                    _readonly_uri(path),
                    uri=True,
                    check_same_thread=False,
                    isolation_level=None,
                )
            except sqlite3.Error as exc:
                raise StudyLogError(f"cannot open {path}: {exc}") from None
        if existing and not os.access(path, os.W_OK):
            raise StudyLogError(
                f"{path} is read-only; sessions cannot be recorded in it (it was left as it is)"
            )
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise StudyLogError(f"cannot create a folder for {path}: {exc.strerror or exc}") from None
        if not os.access(path.parent, os.W_OK | os.X_OK):
            raise StudyLogError(f"{path.parent} is read-only; the study log needs to write its journal there")
        try:
            db = sqlite3.connect(path, check_same_thread=False, isolation_level=None, timeout=30.0)
            db.execute("PRAGMA journal_mode=WAL")
            db.execute("PRAGMA synchronous=FULL")
        except sqlite3.OperationalError as exc:
            raise StudyLogError(f"cannot write study log {path} ({exc}); read-only or disk full?") from None
        except sqlite3.DatabaseError as exc:
            raise StudyLogError(f"{path} is not a usable study log ({exc})") from None
        return db

    # ----------------------------------------------------------------------------------------- writing
    def _writable(self) -> None:
        if self.readonly:
            raise StudyLogError(f"{self.path} was opened read-only")

    def _write(self, sql: str, args: tuple[Any, ...]) -> int:
        with self._lock:
            self._writable()
            try:
                cur = self._db.execute(sql, args)  # autocommit: one durable transaction per statement
            except sqlite3.Error as exc:
                raise StudyLogError(f"cannot write to study log {self.path}: {exc}") from None
            return int(cur.lastrowid or 0)

    def _read(self, sql: str, args: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
        with self._lock:
            try:
                return self._db.execute(sql, args).fetchall()
            except sqlite3.DatabaseError as exc:
                raise StudyLogError(
                    f"cannot read study log {self.path} ({exc}); it was left as it is"
                ) from None

    @contextmanager
    def batch(self) -> Iterator[None]:
        """Group writes into one transaction (for simulated sessions, which a seed regenerates; never for real ones)."""
        with self._lock:
            self._db.execute("BEGIN")
        try:
            yield
        except BaseException:
            with self._lock:
                if self._db.in_transaction:  # an interrupt as COMMIT returned: nothing left to roll back
                    self._db.execute("ROLLBACK")
            raise
        with self._lock:
            self._db.execute("COMMIT")

    def start_session(self, plan: SessionPlan, info: Mapping[str, Any] | None = None) -> int:
        """A new session row; returns its id."""
        return self._write(
            "INSERT INTO sessions (participant, grp, session_index, condition, simulated, started, info) VALUES (?,?,?,?,?,?,?)",
            (
                plan.participant,
                plan.group.value,
                plan.session_index,
                plan.condition.value,
                int(self.simulated),
                time.time(),
                json.dumps(dict(info or {}), default=str),
            ),
        )

    def record_event(
        self, session_id: int, kind: str, data: Mapping[str, Any], at: float | None = None
    ) -> int:
        """Store one event, committed before returning."""
        return self._write(
            "INSERT INTO events (session_id, time, kind, data) VALUES (?,?,?,?)",
            (session_id, time.time() if at is None else at, kind, json.dumps(dict(data), default=str)),
        )

    def record(self, session_id: int, event: Event) -> int:
        """Store one typed event (its kind and `to_json()`), committed before returning."""
        return self.record_event(session_id, event.kind, event.to_json())

    def event_sink(self, session_id: int) -> EventSink:
        """An `on_event` sink for run_episode that logs each event into this session."""

        def sink(event: Event) -> None:
            self.record(session_id, event)

        return sink

    def record_responses(
        self, session_id: int, questionnaire: str, answers: Mapping[str, float | None]
    ) -> None:
        """Store a complete questionnaire (validated against its scale) in one transaction."""
        q = get_questionnaire(questionnaire)
        checked = validate_answers(q, answers)
        now = time.time()
        order = {it.key: i for i, it in enumerate(q.items)}
        with self._lock:
            self._writable()
            own = not self._db.in_transaction
            if own:
                self._db.execute("BEGIN IMMEDIATE")
            try:
                for key, value in checked.items():
                    self._db.execute(
                        "INSERT INTO responses (session_id, time, questionnaire, item, item_index, value) VALUES (?,?,?,?,?,?)",
                        (session_id, now, q.name, key, order[key], value),
                    )
                if own:
                    self._db.execute("COMMIT")
            except sqlite3.IntegrityError:
                if own:
                    self._db.execute("ROLLBACK")
                raise StudyLogError(
                    f"{self.path}: questionnaire {q.name!r} of session {session_id} is stored already; "
                    "answers are never replaced"
                ) from None
            except sqlite3.Error as exc:
                if own and self._db.in_transaction:
                    self._db.execute("ROLLBACK")
                raise StudyLogError(f"cannot write to study log {self.path}: {exc}") from None
            except BaseException:
                if own and self._db.in_transaction:
                    self._db.execute("ROLLBACK")
                raise

    def end_session(self, session_id: int, summary: Mapping[str, Any] | None = None) -> None:
        self._write(
            "UPDATE sessions SET ended = ?, summary = ? WHERE id = ?",
            (
                time.time(),
                json.dumps(dict(summary), default=str) if summary is not None else None,
                session_id,
            ),
        )

    # ----------------------------------------------------------------------------------------- reading
    def sessions(self) -> list[SessionRow]:
        rows = self._read(
            "SELECT id, participant, grp, session_index, condition, simulated, started, ended, info, summary FROM sessions ORDER BY id"
        )
        return [
            SessionRow(
                r[0],
                r[1],
                r[2],
                r[3],
                r[4],
                bool(r[5]),
                r[6],
                r[7],
                self._json(r[8], f"session {r[0]} info"),
                self._json(r[9], f"session {r[0]} summary") if r[9] else None,
            )
            for r in rows
        ]

    def events(self, session_id: int | None = None) -> list[EventRow]:
        sql = "SELECT id, session_id, time, kind, data FROM events"
        args: tuple[Any, ...] = ()
        if session_id is not None:
            sql, args = sql + " WHERE session_id = ?", (session_id,)
        rows = self._read(sql + " ORDER BY id", args)
        return [EventRow(r[0], r[1], r[2], r[3], self._json(r[4], f"event {r[0]}")) for r in rows]

    def _json(self, text: Any, what: str) -> Any:
        try:
            return json.loads(text)
        except (TypeError, ValueError, RecursionError):
            raise StudyLogError(f"{self.path}: {what} is not valid JSON; the file is damaged") from None

    def responses(self) -> list[ResponseRow]:
        rows = self._read(
            "SELECT session_id, questionnaire, item, item_index, value, time FROM responses ORDER BY session_id, questionnaire, item_index"
        )
        return [ResponseRow(*r) for r in rows]

    def typed_events(self, session_id: int | None = None) -> list[Event]:
        """The stored events read back as typed events (`scone_bt.events.from_json`); kinds this version does
        not know are left out."""
        out = []
        for row in self.events(session_id):
            if row.kind in EVENT_TYPES or row.kind == "intervention":
                out.append(from_json(row.kind, row.data))
        return out

    def intervention_causes(self, session_id: int) -> dict[str, int]:
        """The session's interventions by cause (`scone_bt.events.INTERVENTION_CAUSES`; every cause listed, 0
        where none), plus `UNRECORDED_CAUSE` for those of an older log that stored no cause."""
        counts = dict.fromkeys(INTERVENTION_CAUSES, 0)
        for e in self.events(session_id):
            if e.kind != Intervention.kind or is_legacy_takeover(e.kind, e.data):
                continue
            cause = str(e.data.get("cause") or UNRECORDED_CAUSE)
            counts[cause] = counts.get(cause, 0) + 1
        return counts

    def interventions(self, session_id: int) -> int:
        """The session's interventions, summed over their causes (`intervention_causes`): what the participant
        did that the robot did not ask for, as the episode summary counts them."""
        return sum(self.intervention_causes(session_id).values())

    # ----------------------------------------------------------------------------------------- export
    def export_csv(self, folder: str | Path) -> dict[str, Path]:
        """sessions.csv, events.csv, responses.csv (per item) and scores.csv (published scores) in `folder`."""
        import pandas as pd

        out = Path(folder)
        try:
            out.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise StudyLogError(f"cannot create the export folder {out}: {exc.strerror or exc}") from None
        clash = [name for name in EXPORT_FILES if (out / name).exists()]
        if clash:
            raise StudyLogError(
                f"{out}: {', '.join(clash)} {'exists' if len(clash) == 1 else 'exist'} already and {'is' if len(clash) == 1 else 'are'} never overwritten"
            )
        label = "SIMULATED" if self.simulated else "real"
        sessions = self.sessions()
        responses = self.responses()
        tables = {
            "sessions": pd.DataFrame(
                [
                    {
                        **_session_key(label, s),
                        "started": s.started,
                        "ended": s.ended,
                        **self._cause_columns(s.id),
                        "summary": json.dumps(s.summary),
                    }
                    for s in sessions
                ],
                columns=_SESSION_COLUMNS,
            ),
            "events": pd.DataFrame(
                [
                    {
                        "data": label,
                        "event_id": e.id,
                        "session_id": e.session_id,
                        "time": e.time,
                        "kind": e.kind,
                        "data_json": json.dumps(e.data),
                    }
                    for e in self.events()
                ],
                columns=("data", "event_id", "session_id", "time", "kind", "data_json"),
            ),
            "responses": pd.DataFrame(
                [{"data": label, **{k: getattr(r, k) for k in _RESPONSE_COLUMNS[1:]}} for r in responses],
                columns=_RESPONSE_COLUMNS,
            ),
            "scores": pd.DataFrame(self._score_rows(label, sessions, responses), columns=_SCORE_COLUMNS),
        }
        paths = {name: out / f"{name}.csv" for name in tables}
        for name, table in tables.items():
            try:  # mode "x": an existing file is never overwritten
                table.to_csv(paths[name], index=False, mode="x", encoding="utf-8")
            except FileExistsError:
                raise StudyLogError(f"{paths[name]} exists already; export into a new folder") from None
            except OSError as exc:
                raise StudyLogError(f"cannot write {paths[name]}: {exc.strerror or exc}") from None
        return paths

    def _cause_columns(self, session_id: int) -> dict[str, int]:
        """sessions.csv's count columns: the total and one per cause (the total includes unrecorded causes)."""
        causes = self.intervention_causes(session_id)
        out = {"interventions": sum(causes.values())}
        out.update({column: causes[c] for column, c in zip(_CAUSE_COLUMNS, INTERVENTION_CAUSES, strict=True)})
        return out

    @staticmethod
    def _score_rows(
        label: str, sessions: list[SessionRow], responses: list[ResponseRow]
    ) -> list[dict[str, Any]]:
        rows = []
        for s in sessions:
            mine = [r for r in responses if r.session_id == s.id]
            for name in sorted({r.questionnaire for r in mine}):
                q = get_questionnaire(name)
                answers = {r.item: r.value for r in mine if r.questionnaire == name}
                rows.append(
                    {
                        **_session_key(label, s),
                        "questionnaire": name,
                        "score": q.score(answers),
                        "subscales": json.dumps(q.subscale_scores(answers)),
                    }
                )
        return rows

    def close(self) -> None:
        with self._lock:
            self._db.close()

    def __enter__(self) -> StudyLog:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
