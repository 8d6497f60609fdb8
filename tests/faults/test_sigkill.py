"""SIGKILL during an episode and during a study session: what was printed or acknowledged is stored.

The episode is a real `scone-run` process (unbuffered stdout, so a printed line is a line the user saw); the study
session is a real tablet server with its StudyLog in a child process, answered over HTTP. Kill points are seeded.
"""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time
import urllib.request

import numpy as np
import pytest

from scone_bt.experience import ExperienceStore
from scone_bt.study import MDMT_PERFORMANCE, TPS_HRI_14, StudyLog

OUTCOME_PREFIXES = ("    + success", "    x failure")


def _kill_after_outcomes(db, n_outcomes: int, delay_s: float, seed: int) -> tuple[int, int]:
    """Run scone-run, SIGKILL it `delay_s` after its n-th printed outcome; (printed, stored) outcomes."""
    argv = [
        sys.executable,
        "-u",
        "-m",
        "scone_bt.cli.run",
        "--robot",
        "sim",
        "--recipe",
        "example:hummus",
        "--distractors",
        "1",
        "--no-self-confidence",
        "--seed",
        str(seed),
        "--max-ticks",
        "3000",
        "--experience",
        str(db),
    ]
    proc = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True, bufsize=1)
    printed = 0
    try:
        deadline = time.monotonic() + 400
        for line in proc.stdout:  # type: ignore[union-attr]
            if line.startswith(OUTCOME_PREFIXES):
                printed += 1
                if printed >= n_outcomes:
                    time.sleep(delay_s)
                    break
            if time.monotonic() > deadline:
                break
        proc.send_signal(signal.SIGKILL)
        proc.wait(30)
        # lines that reached the pipe before the kill were printed too
        printed += sum(1 for line in proc.stdout if line.startswith(OUTCOME_PREFIXES))  # type: ignore[union-attr]
    finally:
        if proc.poll() is None:
            proc.kill()
    with ExperienceStore(db) as store:
        return printed, len(store)


@pytest.mark.slow
def test_sigkill_during_an_episode_keeps_every_printed_outcome(tmp_path):
    delay = float(np.random.default_rng(18).uniform(0.0, 0.5))  # seeded kill point after the 2nd outcome
    printed, stored = _kill_after_outcomes(tmp_path / "exp.db", 2, delay, seed=0)
    print(f"SIGKILL episode: printed {printed} outcomes, stored {stored}")
    assert printed >= 2
    assert stored >= printed  # every printed outcome is stored (one more may be stored, not yet printed)


SERVER = r"""
import json, sys, threading, time
from scone_bt.study import StudyLog, plan_session
from scone_bt.study.ui import serve_tablet
log = StudyLog(sys.argv[1])
sid = log.start_session(plan_session("P01", "A", 1))
server = serve_tablet("127.0.0.1", 0, "kill-token-123")
server.state.start_episode(["Cook."], "kill test")
server.ask_questionnaires(lambda name, answers: log.record_responses(sid, name, answers))
print(json.dumps({"port": server.port, "session": sid}), flush=True)
i = 0
while True:  # the episode's event stream: each event is printed once it is recorded
    log.record_event(sid, "decision", {"i": i})
    print(f"event {i}", flush=True)
    i += 1
    time.sleep(0.002)
"""


def test_sigkill_during_a_study_session_keeps_every_acknowledged_answer(tmp_path):
    db = tmp_path / "study.db"
    proc = subprocess.Popen(
        [sys.executable, "-u", "-c", SERVER, str(db)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        info = json.loads(proc.stdout.readline())  # type: ignore[union-attr]
        base = f"http://127.0.0.1:{info['port']}/api/questionnaires/"
        acked = {}
        for q, value in ((MDMT_PERFORMANCE, 4.0), (TPS_HRI_14, 60.0)):
            body = json.dumps({i.key: value for i in q.items}).encode()
            req = urllib.request.Request(
                base + q.name,
                data=body,
                method="POST",
                headers={"Content-Type": "application/json", "X-Session-Token": "kill-token-123"},
            )
            with urllib.request.urlopen(req, timeout=30) as r:
                assert r.status == 200
                acked[q.name] = value
            if q is MDMT_PERFORMANCE:
                proc.send_signal(signal.SIGKILL)  # right after the first acknowledgement
                break
        proc.wait(30)
        printed = sum(1 for line in proc.stdout if line.startswith("event "))  # type: ignore[union-attr]
    finally:
        if proc.poll() is None:
            proc.kill()
    with StudyLog(db) as log:  # reopens cleanly after the kill
        responses = log.responses()
        events = log.events(info["session"])
    stored = {r.questionnaire: r.value for r in responses}
    print(
        f"SIGKILL session: acknowledged {len(acked)} questionnaires, stored {len(stored)}; printed {printed} events, stored {len(events)}"
    )
    assert {q: stored.get(q) for q in acked} == acked  # every acknowledged answer is in the log
    assert len([r for r in responses if r.questionnaire == "mdmt"]) == len(MDMT_PERFORMANCE.items)
    assert len(events) >= printed > 0  # every printed event too
    assert [e.data["i"] for e in events] == list(range(len(events)))
