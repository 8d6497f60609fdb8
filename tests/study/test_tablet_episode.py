"""A real PyBullet episode driven through the tablet's HTTP API: help requests wait for "done", a take-over cancels."""

from __future__ import annotations

import json
import threading
import time
import urllib.error
import urllib.parse
import urllib.request

import pytest

from scone_bt.study import StudyLog, plan_session
from scone_bt.study.ui import serve_tablet


class _Participant(threading.Thread):
    """Polls the tablet like a person: confirms every request, takes over actions until one take-over lands.

    The episode runs faster than real time, so the robot can finish an action before the next tick sees the
    take-over; the participant then tries again on a later action, as a person would.
    """

    def __init__(self, base: str) -> None:
        super().__init__(daemon=True)
        self.base, self.stop, self.actions = base, threading.Event(), []

    def _post(self, path: str) -> None:
        urllib.request.urlopen(urllib.request.Request(self.base + path, data=b"", method="POST"), timeout=10)

    def run(self) -> None:
        landed = False
        while not self.stop.is_set():
            state = json.load(urllib.request.urlopen(self.base + "api/state", timeout=10))
            for r in state["requests"]:
                if not r.get("confirmed"):
                    self._post(f"api/requests/{urllib.parse.quote(r['object'])}/done")
                    self.actions.append(("done", r["object"], r["kind"]))
                    tried = {a[1] for a in self.actions if a[0] == "takeover"}
                    landed = landed or (r["kind"] == "intervention" and r["object"] in tried)
            if state["can_take_over"] and not landed:
                try:
                    self._post("api/takeover")
                except urllib.error.HTTPError as exc:  # 409: the action ended between the poll and the post
                    assert exc.code == 409, exc
                else:
                    self.actions.append(("takeover", state["acting_object"], ""))
            time.sleep(0.02)


@pytest.mark.slow
def test_episode_with_tablet(tmp_path):
    from scone_bt.episode import EpisodeOptions, run_episode

    log = StudyLog(tmp_path / "study.db")
    sid = log.start_session(plan_session("P01", "A", 1))
    with serve_tablet("127.0.0.1", 0, None) as server:
        participant = _Participant(server.url)
        participant.start()
        try:
            summary = run_episode(
                EpisodeOptions(recipe="example:hummus", distractors=2, max_ticks=3000, seed=0),
                printer=lambda _l: None,
                on_event=server.chain(log.event_sink(sid)),
                human_factory=server.human_factory,
            )
        finally:
            participant.stop.set()
            participant.join(5)
    assert summary.completed
    kinds = [e.kind for e in log.events(sid)]
    took = [a for a in participant.actions if a[0] == "takeover"]
    tried = {t[1] for t in took}
    # Interventions also include clean-ups (a dropped object, an idle robot); the take-over is the one on a tried object.
    fetched = [
        a[1] for a in participant.actions if a[0] == "done" and a[2] == "intervention" and a[1] in tried
    ]
    assert took and len(fetched) >= 1  # the participant fetched it after taking over
    cancelled = [e for e in log.events(sid) if e.kind == "intervention" and "action" in e.data]
    assert len(cancelled) == 1 and cancelled[0].data["object"] in fetched  # the robot's action was cancelled
    helps = [a for a in participant.actions if a[0] == "done" and a[2] == "help"]
    assert kinds.count("help_request") == summary.help_requests and len(helps) == kinds.count("help")
    assert summary.interventions == log.interventions(sid) >= 1
