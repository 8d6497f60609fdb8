"""Honest counts: an intervention is what the participant did unasked; waiting on the robot's own request is not
idling (the event sequence a tablet session recorded, replayed)."""

from __future__ import annotations

from scone_bt.events import (
    INTERVENTION_CAUSES,
    CleanUpStarted,
    EventLog,
    HelpGiven,
    HelpRequested,
    Intervention,
    TakeOver,
)
from scone_bt.human import HumanOptions
from scone_bt.study.tablet import TabletHuman, TabletState


def _ticks(kitchen, human, events, n: int) -> None:
    for _ in range(n):
        kitchen.advance(0.1)
        for e in human.update():
            events(e)


def _on_step_three(kitchen, stocked, events):
    """A tablet human (default patience, 20 s) on the step that needs the olive oil and the garlic."""
    human = TabletHuman(kitchen, stocked, HumanOptions(cook_time_s=0.2), seed=0, state=TabletState())
    for name in ("salt", "spaghetti"):
        kitchen.place_on_table(name)
    for _ in range(100):
        if human.step_index == 2:
            break
        _ticks(kitchen, human, events, 1)
    assert set(stocked.steps[human.step_index].objects) == {"olive oil", "garlic"}
    return human


def _ask(human, events, name: str) -> None:
    """What AskForHelp does on entry."""
    human.request_help(name)
    human.robot_busy(True)
    events(HelpRequested(human.kitchen.sim_time, f"Put {name} on table", name))


def _answered(kitchen, human, events, name: str) -> None:
    """The participant taps Done; the robot's ask ends once the item is on the table."""
    assert human.state.confirm(name)
    for _ in range(20):
        _ticks(kitchen, human, events, 1)
        if not human.help_pending(name):
            break
    human.robot_busy(False)  # AskForHelp.terminate


def _about(events: EventLog, name: str, kind: type) -> int:
    return sum(1 for e in events.events if isinstance(e, kind) and e.object_name == name)


def test_a_slow_answer_to_one_request_does_not_make_the_next_request_an_intervention(kitchen, stocked):
    events = EventLog()
    human = _on_step_three(kitchen, stocked, events)
    _ask(human, events, "olive oil")
    _ticks(kitchen, human, events, 250)  # the participant takes 25 s, longer than the 20 s patience
    _answered(kitchen, human, events, "olive oil")
    _ticks(kitchen, human, events, 1)  # the robot's next decision comes a tick later
    _ask(human, events, "garlic")
    _ticks(kitchen, human, events, 30)
    _answered(kitchen, human, events, "garlic")
    assert _about(events, "garlic", HelpRequested) == 1
    assert _about(events, "garlic", Intervention) == 0
    assert _about(events, "garlic", CleanUpStarted) == 0
    assert _about(events, "garlic", HelpGiven) == 1
    assert events.stats.help_requests == 2 and events.stats.interventions == 0


def test_a_clean_up_the_robot_then_asks_for_is_help(kitchen, stocked):
    """The robot idles past the participant's patience (a clean-up starts), then asks for that very item."""
    events = EventLog()
    human = _on_step_three(kitchen, stocked, events)
    _ticks(kitchen, human, events, 205)
    started = [e for e in events.events if isinstance(e, CleanUpStarted)]
    assert started and started[0].detail == "the robot was idle too long"
    name = started[0].object_name
    _ask(human, events, name)
    assert human.help_pending(name)  # the robot now waits for it as for any request
    _answered(kitchen, human, events, name)
    assert _about(events, name, HelpGiven) == 1 and _about(events, name, Intervention) == 0


def test_every_counted_intervention_carries_its_cause(kitchen, stocked):
    events = EventLog()
    human = _on_step_three(kitchen, stocked, events)
    # a take-over of the robot's action on the olive oil
    human.robot_busy(True)
    human.decide_takeover("olive oil")
    assert human.state.request_takeover() == "olive oil" and human.wants_takeover("olive oil")
    human.take_over("olive oil")
    events(TakeOver(kitchen.sim_time, "Put olive oil on table", "olive oil"))
    human.robot_busy(False)
    _answered(kitchen, human, events, "olive oil")
    # then the idle robot: the participant brings the garlic unasked
    _ticks(kitchen, human, events, 205)
    assert human.state.snapshot()["requests"][0]["object"] == "garlic"
    _answered(kitchen, human, events, "garlic")
    counted = [(e.object_name, e.cause) for e in events.events if isinstance(e, Intervention)]
    assert counted == [("olive oil", "takeover"), ("garlic", "idle")]
    assert all(cause in INTERVENTION_CAUSES for _, cause in counted)


def test_the_study_log_counts_from_causes(tmp_path):
    from scone_bt.study import StudyLog, plan_session

    log = StudyLog(tmp_path / "s.db")
    sid = log.start_session(plan_session("P01", "A", 1))
    for event in (
        Intervention(1.0, "salt", "fetched by the human", "takeover"),
        Intervention(2.0, "garlic", "fetched by the human", "idle"),
        HelpGiven(3.0, "basil", "fetched by the human"),
    ):
        log.record(sid, event)
    log.record_event(sid, "intervention", {"sim_time": 4.0, "object": "salt", "detail": "old log"})
    causes = log.intervention_causes(sid)
    assert causes == {"takeover": 1, "dropped": 0, "idle": 1, "by-hand": 0, "unrecorded": 1}
    assert log.interventions(sid) == 3
    paths = log.export_csv(tmp_path / "csv")
    import pandas as pd

    row = pd.read_csv(paths["sessions"]).iloc[0]
    assert (
        row.interventions,
        row.interventions_takeover,
        row.interventions_idle,
        row.interventions_by_hand,
    ) == (
        3,
        1,
        1,
        0,
    )
