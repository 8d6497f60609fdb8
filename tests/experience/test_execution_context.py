"""Outcomes keep their execution context in both stores; rows stored without one (older rows) still load."""

from __future__ import annotations

import csv
import json
import math
import sqlite3

import pytest

from scone_bt.errors import ExperienceStoreError, SconeError
from scone_bt.experience import ExperienceStore, Outcome, open_store
from scone_bt.experience.types import CONTEXT_FIELDS, ExecutionContext

CONTEXT = ExecutionContext(
    shelf_tier=2,
    clearance_m=0.0374,
    neighbours=1,
    detected=True,
    detected_width_m=0.059,
    detected_height_m=0.04,
)


def _outcome(i: int, execution: ExecutionContext | None) -> Outcome:
    return Outcome(
        time=1000.0 + i,
        action="Put parmesan on table",
        object_name="parmesan",
        embedder="minilm",
        success=i % 2 == 0,
        failure_stage=None if i % 2 == 0 else "planning",
        context={"episode": i, "sim_time": 1.5 * i},
        robot_id="panda-1",
        arm="panda",
        outcome_id=f"panda-1:{i}",
        execution=execution,
    )


def _check_round_trip(store) -> None:
    partial = ExecutionContext(shelf_tier=0, detected=True)  # no size measured: the rest stays unknown
    written = [_outcome(0, CONTEXT), _outcome(1, None), _outcome(2, partial)]
    for o in written:
        store.append(o)
    got = store.outcomes()
    assert got == written
    assert [o.execution for o in got] == [CONTEXT, None, partial]
    # The free-form context comes back as it was given: the execution context is not mixed into it.
    assert got[0].context == {"episode": 0, "sim_time": 0.0}


def test_sqlite_round_trip_with_and_without_context(tmp_path) -> None:
    path = tmp_path / "exp.sqlite"
    with ExperienceStore(path) as store:
        _check_round_trip(store)
        rows = list(csv.DictReader(store.export_csv(tmp_path / "out.csv").open()))
    assert json.loads(rows[0]["context"])["execution"]["clearance_m"] == 0.0374
    assert "execution" not in json.loads(rows[1]["context"])
    with ExperienceStore(path) as reopened:  # a restarted robot reads the same contexts
        assert [o.execution for o in reopened.outcomes()][:2] == [CONTEXT, None]


def test_postgres_round_trip_with_and_without_context(pg_url) -> None:
    with open_store(pg_url) as store:
        _check_round_trip(store)
    with open_store(pg_url) as reopened:
        assert reopened.outcomes()[0].execution == CONTEXT


def test_rows_stored_before_contexts_load_without_one(tmp_path) -> None:
    """A row as the store wrote it before outcomes had an execution context: same schema, no "execution" key."""
    path = tmp_path / "old.sqlite"
    with ExperienceStore(path) as store:
        store.append(_outcome(0, None))
    with sqlite3.connect(path) as conn:  # what an older scone-bt wrote: its context JSON as it was
        conn.execute("UPDATE outcomes SET context = ?", (json.dumps({"robot": "panda", "sim_time": 3.0}),))
    conn.close()
    with ExperienceStore(path) as store:
        (old,) = store.outcomes()
        assert old.execution is None and old.context == {"robot": "panda", "sim_time": 3.0}
        assert store.notice is None  # no migration: nothing was rewritten
        assert all(math.isnan(v) for v in ExecutionContext().vector()) and len(CONTEXT_FIELDS) == 12


def test_a_damaged_stored_context_is_quarantined_with_a_warning_and_left_alone(tmp_path, capsys) -> None:
    path = tmp_path / "bad.sqlite"
    with ExperienceStore(path) as store:
        store.append(_outcome(0, CONTEXT))
        store.append(_outcome(1, CONTEXT))
    bad = json.dumps({"episode": 0, "execution": {"shelf_tier": "top"}})
    with sqlite3.connect(path) as conn:
        conn.execute("UPDATE outcomes SET context = ? WHERE id = 1", (bad,))
    conn.close()
    with ExperienceStore(path) as store:
        assert [o.execution for o in store.outcomes()] == [CONTEXT]
    warning = capsys.readouterr().err
    assert (
        warning.count("\n") == 1 and "row 1 (context execution: shelf_tier must be int, got 'top')" in warning
    )
    with sqlite3.connect(path) as conn:
        assert conn.execute("SELECT context FROM outcomes WHERE id = 1").fetchone()[0] == bad
    conn.close()


def test_the_execution_key_is_reserved(tmp_path) -> None:
    clash = Outcome(0.0, "a", "a", "minilm", True, context={"execution": 1})
    with ExperienceStore(tmp_path / "e.sqlite") as store:
        with pytest.raises(ExperienceStoreError, match="reserved"):
            store.append(clash)
        assert len(store) == 0


def test_context_json_round_trip_drops_unknowns_and_checks_types() -> None:
    assert ExecutionContext.from_json(CONTEXT.to_json()) == CONTEXT
    assert ExecutionContext(clearance_m=math.nan).to_json() == {}
    assert ExecutionContext.from_json({"neighbours": 2.0}).neighbours == 2
    for bad in ({"neighbours": 1.5}, {"clearance_m": True}, {"colour": "red"}):
        with pytest.raises(SconeError):
            ExecutionContext.from_json(bad)
