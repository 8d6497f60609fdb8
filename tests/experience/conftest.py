"""A real PostgreSQL server for the experience-store tests, started once per session in a temporary folder."""

from __future__ import annotations

import itertools

import pytest

from scone_bt.experience.pg_server import TemporaryPostgres, find_postgres_bin

_names = itertools.count()


@pytest.fixture(scope="session")
def postgres_server():
    if find_postgres_bin() is None:
        pytest.skip(
            "PostgreSQL server binaries (initdb, pg_ctl) are not installed: apt-get install postgresql"
        )
    with TemporaryPostgres() as server:
        yield server


@pytest.fixture
def pg_url(postgres_server) -> str:
    """URL of a fresh, empty database on the session's server."""
    return postgres_server.create_database(f"t{next(_names)}")
