"""Open the experience store a user names: an SQLite file path (the embedded default) or a PostgreSQL URL."""

from __future__ import annotations

from pathlib import Path

from scone_bt.experience.base import OutcomeStore
from scone_bt.experience.postgres import PostgresExperienceStore, is_postgres_url
from scone_bt.experience.store import ExperienceStore

__all__ = ["open_store"]


def open_store(spec: str | Path) -> OutcomeStore:
    """`postgresql://…` / `postgres://…` → PostgreSQL (a fleet's shared store); anything else → SQLite file."""
    if is_postgres_url(spec):
        return PostgresExperienceStore(str(spec))
    return ExperienceStore(spec)
