"""Schema 1 SQLite files (before robot ids) still open: upgraded in place after a byte-exact backup."""

from __future__ import annotations

import json
import sqlite3

import pytest

from scone_bt.errors import ExperienceStoreError, UnknownNameError
from scone_bt.experience import APPLICATION_ID, ExperienceStore, LearnFrom, Outcome

# The schema that scone-bt wrote before robot ids (schema 1), verbatim.
_V1 = """
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


def _v1_file(path, n=5):
    conn = sqlite3.connect(path)
    conn.executescript(_V1)
    conn.execute(f"PRAGMA application_id = {APPLICATION_ID}")
    conn.execute("PRAGMA user_version = 1")
    for i in range(n):
        ctx = {"robot": "panda" if i < 3 else "iiwa7", "seed": i}
        conn.execute(
            "INSERT INTO outcomes (time, action, object_name, embedder, success, failure_stage, context) "
            "VALUES (?, ?, ?, 'minilm', ?, ?, ?)",
            (100.0 + i, f"Put o{i} on table", f"o{i}", i % 2, None if i % 2 else "grasp", json.dumps(ctx)),
        )
    conn.commit()
    conn.close()


def test_v1_file_opens_upgraded_with_a_byte_exact_backup(tmp_path):
    path = tmp_path / "panda.db"
    _v1_file(path)
    original = path.read_bytes()
    with ExperienceStore(path) as store:
        assert store.notice is not None and "schema 1" in store.notice
        rows = store.outcomes()
        assert [(o.time, o.action, o.success, o.failure_stage, o.context["seed"]) for o in rows] == [
            (100.0 + i, f"Put o{i} on table", bool(i % 2), None if i % 2 else "grasp", i) for i in range(5)
        ]
        assert [o.robot_id for o in rows] == ["panda"] * 3 + ["iiwa7"] * 2
        assert [o.arm for o in store.outcomes(robot_id="iiwa7")] == ["iiwa7", "iiwa7"]
        assert store.append(Outcome(200.0, "Put x on table", "x", "minilm", True, robot_id="panda")) == 6
    backup = tmp_path / "panda.v1-backup.db"
    assert backup.read_bytes() == original
    with ExperienceStore(path) as again:  # upgraded once: no second backup, nothing changed
        assert again.notice is None and len(again) == 6
    assert sorted(p.name for p in tmp_path.iterdir() if "backup" in p.name) == ["panda.v1-backup.db"]


def test_failed_upgrade_leaves_the_file_as_it_was(tmp_path):
    path = tmp_path / "old.db"
    _v1_file(path)
    conn = sqlite3.connect(path)
    conn.execute(
        "ALTER TABLE outcomes ADD COLUMN arm TEXT"
    )  # a hand-edited file: the upgrade must fail whole
    conn.commit()
    conn.close()
    before = path.read_bytes()
    with pytest.raises(ExperienceStoreError, match="unusable"):
        ExperienceStore(path)
    conn = sqlite3.connect(path)
    assert conn.execute("PRAGMA user_version").fetchone()[0] == 1
    assert "outcome_id" not in [r[1] for r in conn.execute("PRAGMA table_info(outcomes)")]
    conn.close()
    assert path.read_bytes() == before
    assert not list(tmp_path.glob("*backup*"))


def test_sqlite_replay_is_idempotent_and_filters(tmp_path):
    with ExperienceStore(tmp_path / "e.sqlite") as store:
        a = Outcome(1.0, "Put a on table", "a", "minilm", True, robot_id="r1", arm="panda", outcome_id="k1")
        b = Outcome(2.0, "Put b on table", "b", "minilm", False, robot_id="r2", arm="iiwa7", outcome_id="k2")
        assert store.append(a) == 1 and store.append(b) == 2 and store.append(a) == 1
        assert len(store) == 2
        assert store.outcomes(**LearnFrom.SELF.filters("r1", "panda")) == [a]
        assert store.outcomes(**LearnFrom.SAME_MODEL.filters("r9", "iiwa7")) == [b]  # profile "" both
        assert store.outcomes(**LearnFrom.FLEET.filters("r1", "panda")) == [a, b]
        assert store.outcome_ids() == {"k1", "k2"}


def test_learn_from_names_the_valid_values():
    assert LearnFrom.parse("same-model") is LearnFrom.SAME_MODEL
    with pytest.raises(UnknownNameError, match="fleet, same-model, self"):
        LearnFrom.parse("everyone")
