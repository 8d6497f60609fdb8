"""Open the experience store a user names: an SQLite file path (the embedded default) or a PostgreSQL URL."""

from __future__ import annotations

import sqlite3
from collections.abc import Sequence
from pathlib import Path
from typing import Any
from urllib.parse import quote

from scone_bt.experience.base import OutcomeStore
from scone_bt.experience.postgres import PostgresExperienceStore, is_postgres_url
from scone_bt.experience.store import ExperienceStore

__all__ = ["open_store", "count_stored", "check_store_spec", "store_location"]

_CHUNK = 500  # ids per query: under SQLite's default limit of bound parameters


def check_store_spec(spec: str | Path) -> None:
    """Refuse a URL of another scheme (``postgresq://…``, ``sqlite:///…``), which would otherwise name an SQLite
    file of that odd path, and store a fleet's outcomes where no robot of the fleet looks."""
    import re

    from scone_bt.errors import ExperienceStoreError

    if isinstance(spec, Path) or is_postgres_url(spec):
        return
    scheme = re.match(r"^([A-Za-z][A-Za-z0-9+.-]*)://", spec)
    if scheme is not None:
        raise ExperienceStoreError(
            f"experience store {spec!r}: unknown URL scheme {scheme.group(1)!r}; valid: postgresql://… or "
            "postgres://… (PostgreSQL), or a file path (SQLite)"
        )


def store_location(spec: str) -> Path | str:
    """What a user's ``--experience`` names: a PostgreSQL URL as given, an SQLite file's path, or
    ExperienceStoreError for a URL of another scheme (`check_store_spec`)."""
    if is_postgres_url(spec):
        return spec
    check_store_spec(spec)
    return Path(spec)


def open_store(spec: str | Path) -> OutcomeStore:
    """`postgresql://…` / `postgres://…` → PostgreSQL (a fleet's shared store); a file path → SQLite file; another
    URL scheme → ExperienceStoreError (`check_store_spec`)."""
    check_store_spec(spec)
    if is_postgres_url(spec):
        from scone_bt.extras import require

        require("fleet", "a PostgreSQL experience store", ("psycopg",))
        return PostgresExperienceStore(str(spec))
    return ExperienceStore(spec)


def count_stored(spec: str | Path, outcome_ids: Sequence[str], timeout_s: float = 5.0) -> int | None:
    """How many of `outcome_ids` the store named by `spec` holds; None if it cannot be asked.

    Read through a fresh read-only connection, so it answers after an interrupt whatever state the run's own
    connection was left in (an unfinished transaction is invisible here and rolled back when it closes).
    """
    ids = list(dict.fromkeys(outcome_ids))
    if not ids:
        return 0
    if is_postgres_url(spec):
        try:
            import psycopg

            with psycopg.connect(str(spec), connect_timeout=max(1, int(timeout_s))) as conn:
                return sum(
                    _count(
                        conn.execute(
                            "SELECT COUNT(*) FROM scone_outcomes WHERE outcome_id = ANY(%s)",
                            (ids[i : i + _CHUNK],),
                        ).fetchone()
                    )
                    for i in range(0, len(ids), _CHUNK)
                )
        except Exception:  # noqa: BLE001 - any failure means "cannot say"; the caller words it
            return None
    path = Path(spec)
    if not path.is_file():
        return 0
    try:
        db = sqlite3.connect(f"file:{quote(str(path.resolve()))}?mode=ro", uri=True, timeout=timeout_s)
    except sqlite3.Error:
        return None
    try:
        total = 0
        for i in range(0, len(ids), _CHUNK):
            chunk = ids[i : i + _CHUNK]
            total += _count(
                db.execute(
                    f"SELECT COUNT(*) FROM outcomes WHERE outcome_id IN ({', '.join('?' * len(chunk))})",
                    chunk,
                ).fetchone()
            )
        return total
    except sqlite3.Error:
        return None
    finally:
        db.close()


def _count(row: tuple[Any, ...] | None) -> int:
    """The value of a ``SELECT COUNT(*)`` row (such a query always returns one row)."""
    if row is None:
        raise sqlite3.DatabaseError("COUNT(*) returned no row")
    return int(row[0])
