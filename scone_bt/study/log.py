"""The study log: sessions, timestamped events and questionnaire answers in one SQLite file.

Every event is committed on its own (WAL journal, synchronous=FULL), the same rule as the experience store: a crash
loses nothing that was recorded. The file is never overwritten; a file that is not a study log is refused.
Simulated studies are labelled in the file (meta `simulated`) and on every session row.
"""

from __future__ import annotations

import csv
import json
import sqlite3
import threading
import time
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from scone_bt.errors import SconeError
from scone_bt.study.design import SessionPlan
from scone_bt.study.questionnaires import get_questionnaire, validate_answers

__all__ = ["StudyLog", "StudyLogError", "SessionRow", "EventRow", "ResponseRow", "SCHEMA_VERSION"]

SCHEMA_VERSION = 1

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
    """One event: kind (decision, act, outcome, help_request, intervention, help, fetching, step_done, ...)."""

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

    def __init__(self, path: str | Path, simulated: bool = False) -> None:
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._lock = threading.Lock()
        try:
            self._db = sqlite3.connect(self.path, check_same_thread=False, isolation_level=None)
            self._db.execute("PRAGMA journal_mode=WAL")
            self._db.execute("PRAGMA synchronous=FULL")
            tables = {r[0] for r in self._db.execute("SELECT name FROM sqlite_master WHERE type='table'")}
        except sqlite3.DatabaseError as exc:
            raise StudyLogError(f"{self.path} is not an SQLite study log ({exc})") from None
        if tables and "sessions" not in tables:
            self._db.close()
            raise StudyLogError(
                f"{self.path} is an SQLite file but not a study log (tables: {', '.join(sorted(tables))})"
            )
        with self._lock:
            self._db.executescript(_SCHEMA)
            meta = dict(self._db.execute("SELECT key, value FROM meta").fetchall())
            if not meta:
                self._db.execute("INSERT INTO meta VALUES ('schema_version', ?)", (str(SCHEMA_VERSION),))
                self._db.execute("INSERT INTO meta VALUES ('simulated', ?)", ("1" if simulated else "0",))
                meta = {"schema_version": str(SCHEMA_VERSION), "simulated": "1" if simulated else "0"}
        if int(meta["schema_version"]) > SCHEMA_VERSION:
            raise StudyLogError(
                f"{self.path} has schema {meta['schema_version']}; this version reads up to {SCHEMA_VERSION}"
            )
        self.simulated = meta["simulated"] == "1"
        if self.simulated != simulated:
            kind = "SIMULATED" if self.simulated else "real"
            raise StudyLogError(
                f"{self.path} holds {kind} data; use another file rather than mixing real and simulated sessions"
            )

    # ----------------------------------------------------------------------------------------- writing
    def _write(self, sql: str, args: tuple[Any, ...]) -> int:
        with self._lock:
            cur = self._db.execute(sql, args)  # autocommit: one durable transaction per statement
            return int(cur.lastrowid or 0)

    @contextmanager
    def batch(self) -> Iterator[None]:
        """Group writes into one transaction (for simulated sessions, which a seed regenerates; never for real ones)."""
        with self._lock:
            self._db.execute("BEGIN")
        try:
            yield
        except BaseException:
            with self._lock:
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

    def event_sink(self, session_id: int):  # -> Callable[[str, dict], None]
        """An `on_event(kind, data)` callable for run_episode that logs into this session."""

        def sink(kind: str, data: dict[str, Any]) -> None:
            self.record_event(session_id, kind, data)

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
            own = not self._db.in_transaction
            if own:
                self._db.execute("BEGIN")
            try:
                for key, value in checked.items():
                    self._db.execute(
                        "INSERT OR REPLACE INTO responses (session_id, time, questionnaire, item, item_index, value) VALUES (?,?,?,?,?,?)",
                        (session_id, now, q.name, key, order[key], value),
                    )
                if own:
                    self._db.execute("COMMIT")
            except BaseException:
                if own:
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
        with self._lock:
            rows = self._db.execute(
                "SELECT id, participant, grp, session_index, condition, simulated, started, ended, info, summary FROM sessions ORDER BY id"
            ).fetchall()
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
                json.loads(r[8]),
                json.loads(r[9]) if r[9] else None,
            )
            for r in rows
        ]

    def events(self, session_id: int | None = None) -> list[EventRow]:
        sql = "SELECT id, session_id, time, kind, data FROM events"
        args: tuple[Any, ...] = ()
        if session_id is not None:
            sql, args = sql + " WHERE session_id = ?", (session_id,)
        with self._lock:
            rows = self._db.execute(sql + " ORDER BY id", args).fetchall()
        return [EventRow(r[0], r[1], r[2], r[3], json.loads(r[4])) for r in rows]

    def responses(self) -> list[ResponseRow]:
        with self._lock:
            rows = self._db.execute(
                "SELECT session_id, questionnaire, item, item_index, value, time FROM responses ORDER BY session_id, questionnaire, item_index"
            ).fetchall()
        return [ResponseRow(*r) for r in rows]

    def interventions(self, session_id: int) -> int:
        """Objects the participant fetched as an intervention (take-over or clean-up), as EpisodeSummary counts them."""
        return sum(1 for e in self.events(session_id) if e.kind == "intervention" and "detail" in e.data)

    # ----------------------------------------------------------------------------------------- export
    def export_csv(self, folder: str | Path) -> dict[str, Path]:
        """sessions.csv, events.csv, responses.csv (per item) and scores.csv (published scores) in `folder`."""
        out = Path(folder)
        out.mkdir(parents=True, exist_ok=True)
        label = "SIMULATED" if self.simulated else "real"
        sessions = self.sessions()
        paths = {name: out / f"{name}.csv" for name in ("sessions", "events", "responses", "scores")}
        with _csv(paths["sessions"]) as w:
            w.writerow(
                [
                    "data",
                    "session_id",
                    "participant",
                    "group",
                    "session_index",
                    "condition",
                    "started",
                    "ended",
                    "interventions",
                    "summary",
                ]
            )
            for s in sessions:
                w.writerow(
                    [
                        label,
                        s.id,
                        s.participant,
                        s.group,
                        s.session_index,
                        s.condition,
                        s.started,
                        s.ended,
                        self.interventions(s.id),
                        json.dumps(s.summary),
                    ]
                )
        with _csv(paths["events"]) as w:
            w.writerow(["data", "event_id", "session_id", "time", "kind", "data_json"])
            for e in self.events():
                w.writerow([label, e.id, e.session_id, e.time, e.kind, json.dumps(e.data)])
        responses = self.responses()
        with _csv(paths["responses"]) as w:
            w.writerow(["data", "session_id", "questionnaire", "item", "item_index", "value", "time"])
            for r in responses:
                w.writerow(
                    [
                        label,
                        r.session_id,
                        r.questionnaire,
                        r.item,
                        r.item_index,
                        "" if r.value is None else r.value,
                        r.time,
                    ]
                )
        with _csv(paths["scores"]) as w:
            w.writerow(
                [
                    "data",
                    "session_id",
                    "participant",
                    "group",
                    "session_index",
                    "condition",
                    "questionnaire",
                    "score",
                    "subscales",
                ]
            )
            for s in sessions:
                for name in sorted({r.questionnaire for r in responses if r.session_id == s.id}):
                    q = get_questionnaire(name)
                    answers = {
                        r.item: r.value for r in responses if r.session_id == s.id and r.questionnaire == name
                    }
                    w.writerow(
                        [
                            label,
                            s.id,
                            s.participant,
                            s.group,
                            s.session_index,
                            s.condition,
                            name,
                            q.score(answers),
                            json.dumps(q.subscale_scores(answers)),
                        ]
                    )
        return paths

    def close(self) -> None:
        with self._lock:
            self._db.close()

    def __enter__(self) -> StudyLog:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class _csv:
    def __init__(self, path: Path) -> None:
        self.fh = path.open("w", newline="")

    def __enter__(self):  # -> csv writer
        return csv.writer(self.fh)

    def __exit__(self, *exc: object) -> None:
        self.fh.close()
