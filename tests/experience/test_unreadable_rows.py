"""Rows that cannot be read (damage made outside scone-bt) are quarantined: named once on stderr, skipped, and
left in the file as they are; the other rows still rebuild κ̂."""

from __future__ import annotations

import hashlib
import json
import sqlite3

import pytest

from scone_bt.confidence import make_estimator, rebuild_estimator
from scone_bt.embedding.onehot import OneHotEmbedder
from scone_bt.experience import APPLICATION_ID, ExperienceStore, Outcome
from scone_bt.experience.open import count_stored
from scone_bt.experience.types import ExecutionContext
from tests.experience.test_migration import _V1

SALT, SUGAR = "Put salt on table", "Put sugar on table"
ROOMY = ExecutionContext(0, 0.30, 0, True, 0.05, 0.12)


def _digest(path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _store_with_damage(path) -> dict[int, str]:
    """Eight good outcomes, then damage to rows 2, 4, 5, 7 and 8 as a hand-edit would make it; the expected why."""
    with ExperienceStore(path) as store:
        for i in range(8):
            text = SALT if i % 2 else SUGAR
            store.append(Outcome(float(i), text, "x", "minilm", i % 2 == 1, robot_id="r1", execution=ROOMY))
    damage = {
        2: ("context = 'not json'", "context is not JSON"),
        4: ("time = 'yesterday'", "time is 'yesterday' (text), not a finite number"),
        5: ("context = '[1, 2]'", "context is a JSON list, not an object"),
        7: (
            """context = '{"execution": {"shelf_tier": "two"}}'""",
            "context execution: shelf_tier must be int, got 'two'",
        ),
        8: ("action = x'00ff'", "action is b'\\x00\\xff' (blob), not text"),
    }
    with sqlite3.connect(path) as conn:
        for row_id, (assignment, _) in damage.items():
            conn.execute(f"UPDATE outcomes SET {assignment} WHERE id = ?", (row_id,))
    conn.close()
    return {row_id: why for row_id, (_, why) in damage.items()}


def test_unreadable_rows_are_named_once_skipped_and_left_as_they_are(tmp_path, capsys):
    path = tmp_path / "exp.sqlite"
    expected = _store_with_damage(path)
    before = _digest(path)
    with sqlite3.connect(path) as conn:
        raw_before = conn.execute("SELECT * FROM outcomes ORDER BY id").fetchall()
        ids = [r[0] for r in conn.execute("SELECT outcome_id FROM outcomes")]
    conn.close()

    with ExperienceStore(path) as store:
        est = make_estimator("grounded-knn")
        # Rows 1, 3 and 6 are whole: κ̂ learns from them alone.
        assert rebuild_estimator(est, store, OneHotEmbedder([SALT, SUGAR]), robot_id="r1") == 3
        assert est.n_observations == 3
        warning = capsys.readouterr().err
        assert warning.count("\n") == 1 and warning.startswith(f"warning: experience store {path}: 5 rows, ")
        for row_id, why in expected.items():
            assert f"row {row_id} ({why}" in warning
        assert "left in the file as they are, not learnt from" in warning
        assert set(store.quarantined) == set(expected)
        assert [o.time for o in store.outcomes()] == [0.0, 2.0, 5.0]
        assert capsys.readouterr().err == ""  # named once per store
        assert len(store) == 8  # still in the file
    assert count_stored(path, ids) == 8  # the read-only path sees them too
    assert _digest(path) == before
    with sqlite3.connect(path) as conn:
        assert conn.execute("SELECT * FROM outcomes ORDER BY id").fetchall() == raw_before
    conn.close()


def test_one_unreadable_row_is_named_with_its_id(tmp_path, capsys):
    path = tmp_path / "exp.sqlite"
    with ExperienceStore(path) as store:
        for i in range(3):
            store.append(Outcome(float(i), SALT, "salt", "minilm", True))
    with sqlite3.connect(path) as conn:
        conn.execute("UPDATE outcomes SET success = 2 - 1, context = '{' WHERE id = 2")
    conn.close()
    with ExperienceStore(path) as store:
        assert [o.time for o in store.outcomes()] == [0.0, 2.0]
    assert capsys.readouterr().err == (
        f"warning: experience store {path}: row 2 (context is not JSON): cannot be read; "
        "left in the file as it is, not learnt from\n"
    )


def _v1_file_with_a_corrupt_row(path) -> None:
    conn = sqlite3.connect(path)
    conn.executescript(_V1)
    conn.execute(f"PRAGMA application_id = {APPLICATION_ID}")
    conn.execute("PRAGMA user_version = 1")
    for i in range(6):
        ctx = "{'robot': 'panda', oops" if i == 2 else json.dumps({"robot": "panda", "seed": i})
        conn.execute(
            "INSERT INTO outcomes (time, action, object_name, embedder, success, failure_stage, context) "
            "VALUES (?, ?, 'salt', 'minilm', ?, NULL, ?)",
            (float(i), SALT if i % 2 else SUGAR, i % 2, ctx),
        )
    conn.commit()
    conn.close()


def test_a_v1_store_with_a_corrupt_row_is_upgraded_naming_it_and_learns_from_the_rest(tmp_path, capsys):
    path = tmp_path / "old.db"
    _v1_file_with_a_corrupt_row(path)
    original = path.read_bytes()
    with ExperienceStore(path) as store:
        assert store.notice is not None and "schema 1" in store.notice
        assert "row 3 (context is not JSON) cannot be read" in store.notice
        assert "kept in the file as they are" in store.notice and "\n" not in store.notice
        est = make_estimator("knn")
        assert rebuild_estimator(est, store, OneHotEmbedder([SALT, SUGAR])) == 5
        assert store.quarantined == {3: "context is not JSON"}
    assert "row 3 (context is not JSON)" in capsys.readouterr().err
    assert (tmp_path / "old.v1-backup.db").read_bytes() == original
    with sqlite3.connect(
        path
    ) as conn:  # the upgrade added its columns; the row's own values are as they were
        row = conn.execute(
            "SELECT time, action, context, outcome_id, robot_id FROM outcomes WHERE id = 3"
        ).fetchone()
    conn.close()
    assert row == (2.0, SUGAR, "{'robot': 'panda', oops", "v1-3", "")


def test_a_v1_store_with_a_wrong_typed_row_names_it_in_the_notice_and_never_uses_it(tmp_path, capsys):
    path = tmp_path / "old.db"
    _v1_file_with_a_corrupt_row(path)
    with sqlite3.connect(path) as conn:  # a second kind of damage: a column of the wrong type, context intact
        conn.execute("UPDATE outcomes SET time = 'noon' WHERE id = 5")
        raw_before = conn.execute("SELECT * FROM outcomes WHERE id = 5").fetchone()
    conn.close()
    original = path.read_bytes()
    with ExperienceStore(path) as store:
        assert store.notice is not None
        assert (
            "row 3 (context is not JSON), row 5 (time is 'noon' (text), not a finite number)" in store.notice
        )
        assert [o.time for o in store.outcomes()] == [0.0, 1.0, 3.0, 5.0]
        assert store.quarantined == {
            3: "context is not JSON",
            5: "time is 'noon' (text), not a finite number",
        }
    warning = capsys.readouterr().err
    assert (
        warning.count("\n") == 1 and "2 rows, row 3 (context is not JSON), row 5 (time is 'noon'" in warning
    )
    assert (tmp_path / "old.v1-backup.db").read_bytes() == original  # the input, byte for byte
    with sqlite3.connect(path) as conn:  # the upgrade only added columns: the row's own values are unchanged
        assert conn.execute("SELECT * FROM outcomes WHERE id = 5").fetchone()[: len(raw_before)] == raw_before
    conn.close()


@pytest.mark.parametrize(
    ("assignment", "why"),
    [
        ("context = x'7b7d'", "context is b'{}' (blob), not JSON text"),
        ("outcome_id = NULL", "outcome_id is None (NULL), not text"),
        ("failure_stage = x'01'", "failure_stage is b'\\x01' (blob), not text"),
        ("time = 9e999", "time is inf (real), not a finite number"),
    ],
)
def test_wrong_types_are_quarantined_not_a_traceback(tmp_path, capsys, assignment, why):
    path = tmp_path / "exp.sqlite"
    with ExperienceStore(path) as store:
        store.append(Outcome(0.0, SALT, "salt", "minilm", True))
        store.append(Outcome(1.0, SALT, "salt", "minilm", False))
    with sqlite3.connect(path) as conn:
        conn.execute(f"UPDATE outcomes SET {assignment} WHERE id = 1")
    conn.close()
    before = _digest(path)
    with ExperienceStore(path) as store:
        assert [o.time for o in store.outcomes()] == [1.0]
        assert store.quarantined == {1: why}
    assert f"row 1 ({why})" in capsys.readouterr().err
    assert _digest(path) == before
