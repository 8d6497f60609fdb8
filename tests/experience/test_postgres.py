"""The PostgreSQL store on a real server: same guarantees as SQLite, and a fleet writing concurrently."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap

import psycopg
import pytest

from scone_bt.errors import ExperienceStoreError
from scone_bt.experience import ExperienceStore, Outcome, PostgresExperienceStore, open_store


def _outcome(i: int, robot: str = "panda-1", arm: str = "panda") -> Outcome:
    return Outcome(
        time=1000.0 + i,
        action=f"Put item{i % 5} on table",
        object_name=f"item{i % 5}",
        embedder="minilm",
        success=i % 3 != 0,
        failure_stage=None if i % 3 else "grasp",
        context={"episode": i, "sim_time": 1.25 * i},
        robot_id=robot,
        arm=arm,
        profile="p00_nominal",
        outcome_id=f"{robot}:{i}",
    )


def test_round_trip_filters_and_replay(pg_url):
    with open_store(pg_url) as store:
        assert isinstance(store, PostgresExperienceStore)
        ids = [
            store.append(_outcome(i, *(("panda-1", "panda") if i < 4 else ("iiwa-1", "iiwa7"))))
            for i in range(6)
        ]
        assert store.append(_outcome(2)) == ids[2]  # a replayed outcome keeps its row, adds none
        assert len(store) == 6
        got = store.outcomes()
        assert [o.outcome_id for o in got] == [f"panda-1:{i}" for i in range(4)] + ["iiwa-1:4", "iiwa-1:5"]
        assert got[3] == _outcome(3) and got[3].context == {"episode": 3, "sim_time": 3.75}
        assert [o.context["episode"] for o in store.outcomes(arm="iiwa7")] == [4, 5]
        assert len(store.outcomes(robot_id="panda-1", where=lambda o: not o.success)) == 2
    with open_store(pg_url) as reopened:
        assert len(reopened) == 6


def test_foreign_and_newer_databases_are_refused(pg_url, postgres_server):
    with psycopg.connect(pg_url, autocommit=True) as conn:
        conn.execute("CREATE TABLE scone_outcomes (x INT)")
    with pytest.raises(ExperienceStoreError, match="did not create"):
        PostgresExperienceStore(pg_url)
    with psycopg.connect(pg_url, autocommit=True) as conn:  # left as it was
        assert (
            conn.execute(
                "SELECT count(*) FROM information_schema.columns WHERE table_name = 'scone_outcomes'"
            ).fetchone()[0]
            == 1
        )
    newer = postgres_server.create_database("newer")
    PostgresExperienceStore(newer).close()
    with psycopg.connect(newer, autocommit=True) as conn:
        conn.execute("UPDATE scone_meta SET value = '99' WHERE key = 'schema_version'")
    with pytest.raises(ExperienceStoreError, match="schema version 99"):
        PostgresExperienceStore(newer)


def test_unreachable_server_is_one_line_without_password(postgres_server):
    url = f"postgresql://robot:s3cret@127.0.0.1:{postgres_server.port}/no_such_db"
    with pytest.raises(ExperienceStoreError) as err:
        PostgresExperienceStore(url, connect_timeout_s=2)
    message = str(err.value)
    assert "s3cret" not in message and "***" in message and "\n" not in message


_WRITER = textwrap.dedent(
    """
    import sys
    from scone_bt.experience import Outcome, open_store
    store = open_store(sys.argv[1])
    robot, n = sys.argv[2], int(sys.argv[3])
    for i in range(n):
        store.append(Outcome(float(i), f"Put item{i % 7} on table", f"item{i % 7}", "minilm", i % 2 == 0,
                             context={"i": i}, robot_id=robot, arm="panda", outcome_id=f"{robot}:{i}"))
        print(i + 1, flush=True)  # printed only after append returned, i.e. after the commit
    """
)


def _writer(url: str, robot: str, n: int) -> subprocess.Popen:
    return subprocess.Popen(
        [sys.executable, "-c", _WRITER, url, robot, str(n)],
        stdout=subprocess.PIPE,
        text=True,
        env=dict(os.environ),
    )


@pytest.mark.parametrize("backend", ["postgresql", "sqlite"])
def test_concurrent_robots_one_killed_lose_and_duplicate_nothing(backend, request, tmp_path):
    url = request.getfixturevalue("pg_url") if backend == "postgresql" else str(tmp_path / "fleet.sqlite")
    open_store(url).close()  # create the schema once, so start-up order does not matter
    robots = [_writer(url, f"r{k}", 40) for k in range(3)]
    victim = _writer(url, "victim", 10_000)
    acknowledged = 0
    try:
        for line in victim.stdout:
            acknowledged = int(line)
            if acknowledged >= 15:
                break
        victim.send_signal(signal.SIGKILL)
        victim.wait()
        acknowledged = max([acknowledged, *(int(x) for x in victim.stdout)])
        for p in robots:
            assert p.wait(timeout=120) == 0
    finally:
        for p in [*robots, victim]:
            p.kill()
            p.wait()
            p.stdout.close()
    restarted = _writer(
        url, "victim", acknowledged
    )  # the robot restarts and replays its attempts: no duplicates
    assert restarted.wait(timeout=60) == 0
    restarted.stdout.close()
    with open_store(url) as store:
        rows = store.outcomes()
    by_robot = {
        r: sorted(o.context["i"] for o in rows if o.robot_id == r) for r in ("r0", "r1", "r2", "victim")
    }
    assert all(by_robot[f"r{k}"] == list(range(40)) for k in range(3))
    # every acknowledged outcome survived, plus at most the one committed but not yet printed; none twice
    assert by_robot["victim"][:acknowledged] == list(range(acknowledged))
    assert len(by_robot["victim"]) in (acknowledged, acknowledged + 1)
    assert len({o.outcome_id for o in rows}) == len(rows)


def test_sqlite_and_postgres_return_the_same_outcomes(pg_url, tmp_path):
    outcomes = [_outcome(i, robot=f"r{i % 2}") for i in range(8)]
    with open_store(pg_url) as pg, ExperienceStore(tmp_path / "e.sqlite") as lite:
        for o in outcomes:
            pg.append(o)
            lite.append(o)
        for kwargs in ({}, {"robot_id": "r1"}, {"arm": "panda", "embedder": "minilm"}):
            a, b = pg.outcomes(**kwargs), lite.outcomes(**kwargs)
            assert a == b and [o.outcome_id for o in a] == [o.outcome_id for o in b]


@pytest.mark.parametrize(
    ("context", "why"),
    [
        ("[1, 2]", "context is a JSON list, not an object"),
        ('{"execution": {"shelf_tier": "two"}}', "context execution: shelf_tier must be int, got 'two'"),
    ],
)
def test_an_unreadable_row_is_quarantined_with_one_warning_and_the_rest_still_teach(
    pg_url, context, why, capsys
):
    from scone_bt.confidence import make_estimator, rebuild_estimator
    from scone_bt.embedding.onehot import OneHotEmbedder

    with open_store(pg_url) as store:
        for i in range(5):
            store.append(_outcome(i))
    with psycopg.connect(pg_url, autocommit=True) as conn:  # damage made outside scone-bt
        conn.execute(
            "UPDATE scone_outcomes SET context = %s::jsonb WHERE outcome_id = 'panda-1:1'", (context,)
        )
        row_id = conn.execute("SELECT id FROM scone_outcomes WHERE outcome_id = 'panda-1:1'").fetchone()[0]
        raw_before = conn.execute("SELECT * FROM scone_outcomes ORDER BY id").fetchall()
    capsys.readouterr()
    # Two robots of the fleet read the store: each warns once, and learns from the four whole rows.
    for _robot in range(2):
        with open_store(pg_url) as store:
            assert [o.outcome_id for o in store.outcomes()] == [f"panda-1:{i}" for i in (0, 2, 3, 4)]
            warning = capsys.readouterr().err
            assert warning.count("\n") == 1 and warning.startswith(f"warning: experience store {pg_url}: ")
            assert f"row {row_id} (outcome panda-1:1: {why}" in warning
            assert "left in the database as it is, not learnt from" in warning
            assert list(store.quarantined) == [row_id]
            est = make_estimator("grounded-knn")
            actions = sorted({o.action for o in _outcomes_all()})
            assert rebuild_estimator(est, store, OneHotEmbedder(actions)) == 4
            assert capsys.readouterr().err == ""  # named once per store
            assert len(store) == 5  # still in the database
    with psycopg.connect(pg_url, autocommit=True) as conn:
        assert conn.execute("SELECT * FROM scone_outcomes ORDER BY id").fetchall() == raw_before


def _outcomes_all() -> list[Outcome]:
    return [_outcome(i) for i in range(5)]
