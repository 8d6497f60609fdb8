"""What every experience store guarantees, and the parts the SQLite and PostgreSQL backends share.

Guarantees: `append` returns only after the outcome is committed durably; appending an outcome whose
`outcome_id` is already stored is a no-op that returns the existing row id (so a retry never duplicates); rows
come back in the order they were committed; filters select by embedder, robot id, arm model or a predicate.

An outcome's execution context (`Outcome.execution`, what a grounded κ̂ learns from) is stored inside the context
JSON under the reserved key EXECUTION_KEY, so both backends keep it without a schema change: rows stored before
it existed load with `execution=None` (a grounded κ̂ imputes the missing values), and an older scone-bt reading a
newer row sees one more context key.
"""

from __future__ import annotations

import csv
import json
import threading
from abc import ABC, abstractmethod
from collections.abc import Callable
from pathlib import Path
from typing import Any

from scone_bt.errors import ExperienceStoreError, SconeError
from scone_bt.experience.types import ExecutionContext, Outcome

__all__ = [
    "COLUMNS",
    "EXECUTION_KEY",
    "SCHEMA_VERSION",
    "OutcomeStore",
    "attempted_outcome_ids",
    "note_attempt",
    "outcome_from_row",
    "where_clause",
]

EXECUTION_KEY = "execution"
"""Context JSON key that holds Outcome.execution (reserved: a free-form context may not use it)."""

SCHEMA_VERSION = 2
"""1: the first SQLite schema; 2: adds outcome_id (unique), robot_id, arm and profile."""

COLUMNS = (
    "outcome_id",
    "time",
    "action",
    "object_name",
    "embedder",
    "success",
    "failure_stage",
    "context",
    "robot_id",
    "arm",
    "profile",
)


_ATTEMPTED: dict[str, list[str]] = {}
_ATTEMPTED_LOCK = threading.Lock()


def note_attempt(location: str, outcome_id: str) -> None:
    """Remember that this process began to store `outcome_id` in the store at `location`.

    Noted before the write starts, so that after an interrupt at any point the store can be asked exactly which
    of them it holds (a count kept after the commit could miss one that committed just before the interrupt).
    """
    with _ATTEMPTED_LOCK:
        _ATTEMPTED.setdefault(location, []).append(outcome_id)


def attempted_outcome_ids(location: str) -> tuple[str, ...]:
    """The outcome ids this process began to store at `location`, in order (see note_attempt)."""
    with _ATTEMPTED_LOCK:
        return tuple(_ATTEMPTED.get(location, ()))


def stored_context(outcome: Outcome) -> dict[str, Any]:
    """The context as stored: the free-form fields plus the execution context under EXECUTION_KEY."""
    if EXECUTION_KEY in outcome.context:
        raise ExperienceStoreError(
            f"outcome context key {EXECUTION_KEY!r} is reserved for Outcome.execution; rename it"
        )
    if outcome.execution is None:
        return dict(outcome.context)
    return {**outcome.context, EXECUTION_KEY: outcome.execution.to_json()}


def context_json(outcome: Outcome) -> str:
    """The outcome's stored context as canonical JSON (one-line error if it is not serialisable)."""
    try:
        return json.dumps(stored_context(outcome), sort_keys=True, allow_nan=False)
    except (TypeError, ValueError) as exc:
        raise ExperienceStoreError(f"outcome context must be JSON-serialisable: {exc}") from None


def where_clause(placeholder: str, **filters: str | None) -> tuple[str, list[str]]:
    """ " WHERE a = ? AND b = ?" (with the backend's placeholder) and its arguments, for the filters that are set."""
    conditions, args = [], []
    for column, value in filters.items():
        if value is not None:
            conditions.append(f"{column} = {placeholder}")
            args.append(value)
    return (" WHERE " + " AND ".join(conditions) if conditions else ""), args


def outcome_from_row(row: tuple[Any, ...]) -> Outcome:
    """An Outcome from a row in COLUMNS order (context as JSON text or an already decoded dict)."""
    oid, t, a, o, e, s, f, c, r, arm, p = row
    if isinstance(c, str):
        try:
            c = json.loads(c)
        except (ValueError, RecursionError):
            c = None
    # Checked after decoding either way: a PostgreSQL jsonb column hands back a list or a number as it is.
    if not isinstance(c, dict):
        raise ExperienceStoreError(
            f"stored outcome {oid}: its context is not a JSON object; the store is damaged (it was left as it is)"
        )
    c = dict(c)
    raw_execution = c.pop(EXECUTION_KEY, None)
    try:
        execution = (
            None
            if raw_execution is None
            else ExecutionContext.from_json(raw_execution, f"stored outcome {oid}: {EXECUTION_KEY}")
        )
    except SconeError as exc:
        raise ExperienceStoreError(f"{exc}; the store is damaged (it was left as it is)") from None
    return Outcome(
        time=float(t),
        action=a,
        object_name=o,
        embedder=e,
        success=bool(s),
        failure_stage=f,
        context=c,
        robot_id=r,
        arm=arm,
        profile=p,
        outcome_id=oid,
        execution=execution,
    )


class OutcomeStore(ABC):
    """Durable, append-only log of outcomes (SQLite file or PostgreSQL database)."""

    #: Where the store lives, for messages (a path, or a URL without its password).
    location: str
    #: One line to show the user when opening changed something (a schema upgrade), else None.
    notice: str | None

    @abstractmethod
    def append(self, outcome: Outcome) -> int:
        """Store one outcome, committed before this returns (a no-op if its outcome_id is stored); its row id."""

    @abstractmethod
    def _select(
        self, embedder: str | None, robot_id: str | None, arm: str | None, profile: str | None
    ) -> list[tuple[Any, ...]]:
        """Rows in COLUMNS order, in commit order, with the given equality filters."""

    @abstractmethod
    def __len__(self) -> int: ...

    @abstractmethod
    def close(self) -> None:
        """Release the connection (everything appended is already durable)."""

    def outcomes(
        self,
        embedder: str | None = None,
        where: Callable[[Outcome], bool] | None = None,
        *,
        robot_id: str | None = None,
        arm: str | None = None,
        profile: str | None = None,
    ) -> list[Outcome]:
        """Stored outcomes in commit order, optionally of one embedder / robot / arm / profile / predicate."""
        out = [outcome_from_row(r) for r in self._select(embedder, robot_id, arm, profile)]
        return [o for o in out if where(o)] if where is not None else out

    def outcome_ids(self) -> set[str]:
        """Every stored idempotency key."""
        return {o.outcome_id for o in self.outcomes()}

    def export_csv(self, path: Path | str) -> Path:
        """Write every outcome to a CSV file (context as a JSON column); returns the path."""
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        with path.open("w", newline="") as f:
            writer = csv.writer(f)
            writer.writerow(COLUMNS)
            for o in self.outcomes():
                writer.writerow(
                    [
                        o.outcome_id,
                        repr(o.time),
                        o.action,
                        o.object_name,
                        o.embedder,
                        int(o.success),
                        o.failure_stage or "",
                        json.dumps(stored_context(o), sort_keys=True),
                        o.robot_id,
                        o.arm,
                        o.profile,
                    ]
                )
        return path

    def __enter__(self) -> OutcomeStore:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
