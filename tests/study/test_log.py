import csv
import sqlite3
import subprocess
import sys

import pytest

from scone_bt.errors import UnknownNameError
from scone_bt.study import StudyLog, StudyLogError, plan_session
from scone_bt.study.design import Condition


def test_plan_counterbalances():
    assert plan_session("P1", "A", 1).condition is Condition.ON
    assert plan_session("P1", "A", 2).condition is Condition.OFF
    assert plan_session("P1", "B", 1).condition is Condition.OFF
    with pytest.raises(UnknownNameError, match="valid: A, B"):
        plan_session("P1", "C", 1)
    with pytest.raises(UnknownNameError, match="valid: 1, 2"):
        plan_session("P1", "A", 3)


def test_events_survive_a_crash(tmp_path):
    db = tmp_path / "study.db"
    code = f"""
import os
from scone_bt.events import ActOutcome
from scone_bt.study import StudyLog, plan_session
log = StudyLog({str(db)!r})
sid = log.start_session(plan_session("P07", "B", 1))
sink = log.event_sink(sid)
for i in range(5):
    sink(ActOutcome(float(i), "Put salt on table", "salt", i % 2 == 0, None))
os._exit(9)  # no close, no commit at exit: a crash
"""
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 9, proc.stderr
    log = StudyLog(db)
    (session,) = log.sessions()
    assert session.participant == "P07" and session.condition == "off" and session.ended is None
    events = log.events(session.id)
    assert [e.data["success"] for e in events] == [True, False, True, False, True]
    assert all(e.time > 0 for e in events)


def test_responses_and_csv_export(tmp_path):
    from scone_bt.study.questionnaires import MDMT_PERFORMANCE

    with StudyLog(tmp_path / "s.db") as log:
        sid = log.start_session(plan_session("P01", "A", 2))
        log.record_event(sid, "intervention", {"object": "salt", "detail": "fetched by the human"})
        log.record_event(sid, "intervention", {"object": "salt", "action": "Put salt on table"})
        answers = {i.key: 5.0 for i in MDMT_PERFORMANCE.items}
        log.record_responses(sid, "mdmt", answers)
        with pytest.raises(Exception, match="not on the scale"):
            log.record_responses(sid, "mdmt", {**answers, "mdmt_capable": 9.0})
        log.end_session(sid, {"completed": True})
        assert log.interventions(sid) == 1  # the human's fetch, not the behaviour's notice of it
        paths = log.export_csv(tmp_path / "csv")
    rows = list(csv.DictReader(paths["scores"].open()))
    assert rows == [
        {
            "data": "real",
            "session_id": "1",
            "participant": "P01",
            "group": "A",
            "session_index": "2",
            "condition": "off",
            "questionnaire": "mdmt",
            "score": "5.0",
            "subscales": '{"capable": 5.0, "reliable": 5.0}',
        }
    ]
    assert len(list(csv.DictReader(paths["responses"].open()))) == 8


def test_refuses_foreign_files_and_mixing(tmp_path):
    other = tmp_path / "other.db"
    with sqlite3.connect(other) as db:
        db.execute("CREATE TABLE outcomes (x)")
    with pytest.raises(StudyLogError, match="not a study log"):
        StudyLog(other)
    junk = tmp_path / "junk.db"
    junk.write_bytes(b"not sqlite at all" * 100)
    with pytest.raises(StudyLogError, match="not an SQLite"):
        StudyLog(junk)
    StudyLog(tmp_path / "sim.db", simulated=True).close()
    with pytest.raises(StudyLogError, match="SIMULATED"):
        StudyLog(tmp_path / "sim.db")


# ---------------------------------------------------------------------------------------------- hostile files (issue 18)
import hashlib  # noqa: E402
import os  # noqa: E402
from pathlib import Path  # noqa: E402

from scone_bt.study.cli import main as study_main  # noqa: E402


def _digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _siblings(path: Path) -> set[str]:
    return {p.name for p in path.parent.iterdir()}


def test_foreign_and_empty_files_are_refused_unchanged(tmp_path, capsys):
    foreign = tmp_path / "foreign.db"
    with sqlite3.connect(foreign) as db:
        db.execute("CREATE TABLE t (x)")  # rollback journal, not WAL
    empty = tmp_path / "empty.db"
    empty.write_bytes(b"")
    before = {p: _digest(p) for p in (foreign, empty)}
    names = _siblings(foreign)
    for path in (foreign, empty):
        for opener in (lambda p: StudyLog(p), lambda p: StudyLog(p, readonly=True)):
            with pytest.raises(StudyLogError, match="left as it is"):
                opener(path)
        for argv in (["export", "--db", str(path), "--out", str(tmp_path / "csv")],):
            assert study_main(argv) == 2
            err = capsys.readouterr().err.strip()
            assert err.startswith("scone-study: error:") and "\n" not in err
    assert {p: _digest(p) for p in (foreign, empty)} == before
    assert _siblings(foreign) == names  # no -wal / -shm appeared: no journal switch
    with sqlite3.connect(foreign) as db:
        assert db.execute("PRAGMA journal_mode").fetchone()[0] == "delete"


def test_a_corrupt_page_is_reported_not_a_traceback(tmp_path, capsys):
    db = tmp_path / "s.db"
    with StudyLog(db) as log:
        sid = log.start_session(plan_session("P01", "A", 1))
        for i in range(400):
            log.record_event(sid, "outcome", {"object": "salt", "i": i, "pad": "x" * 200})
    raw = bytearray(db.read_bytes())
    page = 4096
    raw[page * 3 : page * 3 + 64] = b"\xa5" * 64  # damage one page of the events table
    db.write_bytes(bytes(raw))
    before = _digest(db)
    assert study_main(["export", "--db", str(db), "--out", str(tmp_path / "csv")]) == 2
    err = capsys.readouterr().err.strip()
    assert "corrupt" in err and "\n" not in err and "Traceback" not in err
    assert _digest(db) == before


def test_answers_are_never_replaced(tmp_path):
    from scone_bt.study.questionnaires import MDMT_PERFORMANCE

    with StudyLog(tmp_path / "s.db") as log:
        sid = log.start_session(plan_session("P01", "A", 1))
        log.record_responses(sid, "mdmt", {i.key: 2.0 for i in MDMT_PERFORMANCE.items})
        with pytest.raises(StudyLogError, match="never replaced"):
            log.record_responses(sid, "mdmt", {i.key: 6.0 for i in MDMT_PERFORMANCE.items})
        assert {r.value for r in log.responses()} == {2.0}


def test_readonly_opening_and_export_never_overwrites(tmp_path, capsys):
    db = tmp_path / "s.db"
    with StudyLog(db) as log:
        log.start_session(plan_session("P01", "A", 1))
    before = _digest(db)
    with StudyLog(db, readonly=True) as log:
        assert len(log.sessions()) == 1
        with pytest.raises(StudyLogError, match="read-only"):
            log.start_session(plan_session("P02", "A", 1))
    assert _digest(db) == before
    out = tmp_path / "csv"
    assert study_main(["export", "--db", str(db), "--out", str(out)]) == 0
    capsys.readouterr()
    first = (out / "sessions.csv").read_bytes()
    assert study_main(["export", "--db", str(db), "--out", str(out)]) == 2
    assert "never overwritten" in capsys.readouterr().err
    assert (out / "sessions.csv").read_bytes() == first
    blocker = tmp_path / "file"
    blocker.write_text("x")
    assert study_main(["export", "--db", str(db), "--out", str(blocker / "csv")]) == 2
    assert "is a file" in capsys.readouterr().err
    assert blocker.read_text() == "x"


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes through file permissions")
def test_readonly_file_is_reported_as_readonly(tmp_path):
    db = tmp_path / "s.db"
    StudyLog(db).close()
    db.chmod(0o444)
    with pytest.raises(StudyLogError, match="read-only"):
        StudyLog(db)


def test_session_arguments_are_checked_before_a_session_exists(tmp_path, capsys):
    db = tmp_path / "study.db"
    base = ["session", "--db", str(db), "--participant", "P01", "--group", "A", "--session", "1"]
    for extra, expected in (
        (["--port", "99999"], "0..65535"),
        (["--seed", "-1"], "0..4294967295"),
        (["--recipe", "example:nope"], "example:"),
        (["--arm", "no_such_arm"], "panda"),
    ):
        assert study_main([*base, *extra]) == 2
        err = capsys.readouterr().err.strip()
        assert expected in err and "\n" not in err
    assert not db.exists()  # no session row, no file: a configuration error is not a session


def test_typed_events_round_trip_and_take_overs_are_not_interventions(tmp_path):
    from scone_bt.events import (
        ActOutcome,
        DecisionMade,
        HelpGiven,
        Intervention,
        StepDone,
        TakeOver,
        summarise,
    )
    from scone_bt.gate.types import DecisionKind

    sent = [
        DecisionMade(
            1.0, 1, "Add salt.", "Put salt on table", 0.61, 0.52, DecisionKind.ACT, "now", (), "salt"
        ),
        ActOutcome(9.5, "Put salt on table", "salt", False, "grasp", 8.5, "slipped"),
        TakeOver(10.0, "Put salt on table", "salt"),
        Intervention(16.0, "salt", "fetched by the human"),
        HelpGiven(20.0, "oil", "fetched by the human"),
        StepDone(22.0, "Add salt."),
    ]
    with StudyLog(tmp_path / "s.db") as log:
        sid = log.start_session(plan_session("P01", "A", 1))
        sink = log.event_sink(sid)
        for event in sent:
            sink(event)
        assert [e.kind for e in log.events(sid)] == [
            "decision",
            "outcome",
            "takeover",
            "intervention",
            "help",
            "step_done",
        ]
        back = log.typed_events(sid)
        assert back == sent
        assert log.interventions(sid) == summarise(sent).interventions == 1
