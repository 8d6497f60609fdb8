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
from scone_bt.study import StudyLog, plan_session
log = StudyLog({str(db)!r})
sid = log.start_session(plan_session("P07", "B", 1))
sink = log.event_sink(sid)
for i in range(5):
    sink("outcome", {{"object": "salt", "success": i % 2 == 0}})
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
