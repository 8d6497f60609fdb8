"""A real PyBullet episode with the tablet-driven human: help requests wait for "done", a take-over cancels.

The participant acts on the tablet's state directly, in the episode's own thread (no HTTP polling thread racing
the episode): it takes over the robot's first action as soon as it starts, and confirms every request the
tablet shows before the human's next update.
"""

from __future__ import annotations

import pytest

from scone_bt.events import ActStarted, Event, TakeOver
from scone_bt.study import StudyLog, plan_session
from scone_bt.study.tablet import TabletHuman, TabletState
from scone_bt.study.ui import serve_tablet


class _Participant:
    """What a person does on the tablet, applied to its state between the episode's ticks."""

    def __init__(self, state: TabletState) -> None:
        self.state = state
        self.actions: list[tuple[str, str, str]] = []

    def on_event(self, event: Event) -> None:
        if isinstance(event, ActStarted) and not any(a[0] == "takeover" for a in self.actions):
            taken = self.state.request_takeover()  # the button: the robot's current action
            assert taken == event.object_name
            self.actions.append(("takeover", taken, ""))

    def confirm_requests(self) -> None:
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
