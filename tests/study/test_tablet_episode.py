"""A real PyBullet episode with the tablet-driven human: help requests wait for "done", a take-over cancels.

The participant acts on the tablet's state directly, in the episode's own thread (no HTTP polling thread racing
the episode): it takes over the robot's first action as soon as it starts, and confirms every request the
tablet shows before the human's next update.
"""

from __future__ import annotations

import math

import pytest

from scone_bt.events import ActStarted, DecisionMade, Event, TakeOver
from scone_bt.study import StudyLog, plan_session
from scone_bt.study.tablet import TabletHuman, TabletState
from scone_bt.study.ui import serve_tablet


class _Participant:
    """What a person does on the tablet, applied to its state between the episode's ticks."""

    def __init__(self, state: TabletState) -> None:
        self.state = state
        self.actions: list[tuple[str, str, str]] = []
        self.trust_seen: dict[str, list[dict]] = {}  # object → the study view's rows for it, as the run went
        self.participant_saw_trust = False

    def on_event(self, event: Event) -> None:
        if isinstance(event, ActStarted) and not any(a[0] == "takeover" for a in self.actions):
            taken = self.state.request_takeover()  # the button: the robot's current action
            assert taken == event.object_name
            self.actions.append(("takeover", taken, ""))

    def confirm_requests(self) -> None:
        self.participant_saw_trust |= "trust" in self.state.snapshot()
        for row in self.state.snapshot(researcher=True)["trust"]:
            seen = self.trust_seen.setdefault(row["object"], [])
            if not seen or seen[-1] != row:
                seen.append(row)
        for request in self.state.snapshot()["requests"]:
            if not request.get("confirmed") and self.state.confirm(request["object"]):
                self.actions.append(("done", request["object"], request["kind"]))


class _Human(TabletHuman):
    participant: _Participant | None = None

    def update(self):  # noqa: ANN201 - TabletHuman's
        if self.participant is not None:
            self.participant.confirm_requests()
        return super().update()


@pytest.mark.slow
def test_episode_with_tablet(tmp_path):
    from scone_bt.episode import EpisodeOptions, run_episode

    log = StudyLog(tmp_path / "study.db")
    sid = log.start_session(plan_session("P01", "A", 1))
    with serve_tablet("127.0.0.1", 0, None) as server:
        participant = _Participant(server.state)

        def factory(kitchen, recipe, options, seed):  # noqa: ANN001, ANN202 - run_episode's HumanFactory
            human = _Human(kitchen, recipe, options, seed=seed, state=server.state)
            human.participant = participant
            return human

        summary = run_episode(
            EpisodeOptions(recipe="example:hummus", distractors=2, max_ticks=3000, seed=0),
            printer=lambda _l: None,
            on_event=server.chain(log.event_sink(sid), participant.on_event),
            human_factory=factory,
        )
    assert summary.completed
    events = log.typed_events(sid)
    kinds = [e.kind for e in events]
    (took,) = [a for a in participant.actions if a[0] == "takeover"]
    taken = [e for e in events if isinstance(e, TakeOver)]
    assert [e.object_name for e in taken] == [took[1]]  # the robot's action was cancelled
    assert summary.takeovers == 1 and kinds.count("cancelled") == 1
    # the participant fetched what they took over (an intervention), and every object the robot asked for
    assert ("done", took[1], "intervention") in participant.actions
    helps = [a for a in participant.actions if a[0] == "done" and a[2] == "help"]
    assert kinds.count("help_request") == summary.help_requests and len(helps) == kinds.count("help")
    assert summary.interventions == log.interventions(sid) >= 1
    # the study view: the person's estimated trust beside κ̂ for every object the robot offered to fetch,
    # updated as the episode ran; hidden from the participant (the default)
    needed = set(summary.needed_on_table)
    assert needed <= set(participant.trust_seen), (needed, set(participant.trust_seen))
    decided = [
        e for e in events if isinstance(e, DecisionMade) and e.object_name and math.isfinite(e.confidence)
    ]
    for e in decided:  # the decision's κ̂ is one of the values the view showed for its object
        assert any(
            abs(r["confidence"] - round(e.confidence, 4)) < 1e-4
            for r in participant.trust_seen[e.object_name]
        )
    assert any(len(rows) > 1 for rows in participant.trust_seen.values())  # it changed as the episode ran
    assert not participant.participant_saw_trust
    log.close()
