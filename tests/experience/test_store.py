"""The experience store: round trip, durability across a killed writer, and refusing foreign or corrupt files."""

from __future__ import annotations

import csv
import os
import signal
import sqlite3
import subprocess
import sys
import textwrap

import pytest

from scone_bt.errors import ExperienceStoreError
from scone_bt.experience import ExperienceStore, Outcome


def _outcome(i: int, embedder: str = "minilm") -> Outcome:
    return Outcome(
        time=1000.0 + i,
        action=f"Put item{i % 5} on table",
        object_name=f"item{i % 5}",
        embedder=embedder,
        success=i % 3 != 0,
        failure_stage=None if i % 3 else "grasp",
        context={"episode": i, "robot": "panda"},
    )


def test_round_trip_filter_and_csv(tmp_path):
    path = tmp_path / "sub" / "exp.sqlite"
    with ExperienceStore(path) as store:
        for i in range(6):
            store.append(_outcome(i, "minilm" if i < 4 else "glove"))
        assert len(store) == 6
        assert store.outcomes() == [_outcome(i, "minilm" if i < 4 else "glove") for i in range(6)]
        assert [o.context["episode"] for o in store.outcomes(embedder="glove")] == [4, 5]
        assert len(store.outcomes(where=lambda o: not o.success)) == 2
        rows = list(csv.DictReader(store.export_csv(tmp_path / "out.csv").open()))
    assert len(rows) == 6 and rows[0]["failure_stage"] == "grasp" and rows[1]["success"] == "1"
    with ExperienceStore(path) as reopened:
        assert len(reopened) == 6


def test_context_must_be_json(tmp_path):
    with ExperienceStore(tmp_path / "e.sqlite") as store:
        bad = Outcome(0.0, "a", "a", "minilm", True, context={"x": object()})
        with pytest.raises(ExperienceStoreError, match="JSON"):
            store.append(bad)
        assert len(store) == 0


_WRITER = textwrap.dedent(
    """
    import sys, time
    from scone_bt.experience import ExperienceStore, Outcome
    store = ExperienceStore(sys.argv[1])
    i = 0
    while True:
        store.append(Outcome(time.time(), f"Put item{i} on table", f"item{i}", "minilm", i % 2 == 0,
                             context={"i": i}))
        i += 1
        print(i, flush=True)  # printed only after append returned, i.e. after the commit
    """
)


def test_killed_writer_loses_no_committed_outcome(tmp_path):
    path = tmp_path / "crash.sqlite"
    proc = subprocess.Popen(
        [sys.executable, "-c", _WRITER, str(path)], stdout=subprocess.PIPE, text=True, env=dict(os.environ)
    )
    acknowledged = 0
    try:
        for line in proc.stdout:  # kill it mid-run, while it is writing
            acknowledged = int(line)
            if acknowledged >= 50:
                break
        proc.send_signal(signal.SIGKILL)
        proc.wait()
        for line in proc.stdout:  # what it acknowledged between our read and the kill
            acknowledged = int(line)
    finally:
        proc.kill()
        proc.wait()
        proc.stdout.close()
    assert acknowledged >= 50
    with ExperienceStore(path) as store:
        stored = store.outcomes()
    # every acknowledged outcome survived, plus at most the one committed but not yet printed; nothing is torn
    assert acknowledged <= len(stored) <= acknowledged + 1
    assert [o.context["i"] for o in stored] == list(range(len(stored)))
    assert all(o.success == (o.context["i"] % 2 == 0) for o in stored)


def test_foreign_and_corrupt_files_are_refused_and_left_untouched(tmp_path):
    text = tmp_path / "notes.txt"
    text.write_text("my shopping list\n")
    other = tmp_path / "other.db"
    with sqlite3.connect(other) as conn:
        conn.execute("CREATE TABLE recipes (name TEXT)")
    good = tmp_path / "good.sqlite"
    with ExperienceStore(good) as store:
        for i in range(20):
            store.append(_outcome(i))
    corrupt = tmp_path / "corrupt.sqlite"
    data = bytearray(good.read_bytes())
    data[100:] = b"\xff" * (len(data) - 100)  # keep the SQLite header, destroy every page
    corrupt.write_bytes(bytes(data))

    for path, message in [
        (text, "not an SQLite file"),
        (other, "something else"),
        (corrupt, "corrupt|unusable"),
    ]:
        before = path.read_bytes()
        with pytest.raises(ExperienceStoreError, match=message):
            ExperienceStore(path)
        assert path.read_bytes() == before, f"{path.name} was modified"
    with pytest.raises(ExperienceStoreError, match="directory"):
        ExperienceStore(tmp_path)


def test_newer_schema_is_refused(tmp_path):
    path = tmp_path / "future.sqlite"
    ExperienceStore(path).close()
    with sqlite3.connect(path) as conn:
        conn.execute("PRAGMA user_version = 99")
    with pytest.raises(ExperienceStoreError, match="schema version 99"):
        ExperienceStore(path)


def test_closed_store_says_so(tmp_path):
    store = ExperienceStore(tmp_path / "e.sqlite")
    store.close()
    with pytest.raises(ExperienceStoreError, match="closed"):
        store.append(_outcome(1))


def test_a_ctrl_c_as_the_schema_commits_stays_a_ctrl_c(tmp_path):
    """A SIGINT handled as COMMIT returns (CI saw it while four runs started): the schema is made, and the
    interrupt is what the caller gets, not "cannot rollback - no transaction is active" as a "store unusable"."""

    class InterruptedAtCommit:
        def __init__(self, conn: sqlite3.Connection) -> None:
            self.conn = conn

        def __getattr__(self, name: str) -> object:
            return getattr(self.conn, name)

        def execute(self, sql: str, *args: object) -> sqlite3.Cursor:
            cursor = self.conn.execute(sql, *args)
            if sql == "COMMIT":
                raise KeyboardInterrupt
            return cursor

    conn = sqlite3.connect(tmp_path / "store.db", isolation_level=None)
    with pytest.raises(KeyboardInterrupt):
        ExperienceStore._create(InterruptedAtCommit(conn))  # type: ignore[arg-type]
    assert not conn.in_transaction
    assert {r[0] for r in conn.execute("SELECT name FROM sqlite_master WHERE type = 'table'")} >= {"outcomes"}
    conn.close()


def test_a_store_interrupted_while_it_is_made_is_not_left_behind(tmp_path, monkeypatch) -> None:
    """A Ctrl-C between the WAL header and the schema left a database with no tables; the file is removed, and
    the next run makes the store whole."""
    path = tmp_path / "exp.sqlite"

    def interrupted(conn: object) -> None:
        raise KeyboardInterrupt

    with monkeypatch.context() as m:
        m.setattr(ExperienceStore, "_create", staticmethod(interrupted))
        with pytest.raises(KeyboardInterrupt):
            ExperienceStore(path)
    assert not path.exists() and not list(tmp_path.glob("exp.sqlite-*"))
    store = ExperienceStore(path)
    assert len(store) == 0
    store.close()
