"""The typed events: their stored JSON, reading them back, and the summary folded from them."""

from __future__ import annotations

import math

import pytest

from scone_bt.errors import SconeError
from scone_bt.events import (
    EVENT_TYPES,
    ActCancelled,
    ActOutcome,
    ActStarted,
    ClarificationAsked,
    CleanUpStarted,
    ConfidenceStated,
    DecisionMade,
    EpisodeStats,
    EventLog,
    HelpDeclined,
    HelpGiven,
    HelpRequested,
    Intervention,
    PlanInfeasible,
    ProbeAborted,
    StepDone,
    TakeOver,
    TrustEstimated,
    from_json,
    summarise,
)
from scone_bt.gate.budget import FeltCarry
from scone_bt.gate.types import DecisionKind

EPISODE = [
    DecisionMade(0.5, 1, "Add salt.", "Put salt on table", 0.6, 0.5, DecisionKind.ACT, "now", (), "salt"),
    ActStarted(0.5, "Put salt on table", "salt", 0.5),
    ActOutcome(9.0, "Put salt on table", "salt", False, "grasp", 8.5, "slipped"),
    PlanInfeasible(9.05, "Put salt on table", "salt", "grasps_blocked", "every grasp of salt collides"),
    ActStarted(9.06, "Put salt on table", "salt", 0.5),
    ProbeAborted(9.08, "Put salt on table", "salt", "the salt slips in my fingers", 7.5, 2.4, 1.3),
    DecisionMade(9.1, 1, "Add salt.", "Put salt on table", 0.6, 0.3, DecisionKind.ASK, "now", (), "salt"),
    HelpRequested(9.1, "Put salt on table", "salt"),
    HelpGiven(15.1, "salt", "fetched by the human"),
    HelpRequested(15.15, "Put pepper on table", "pepper"),
    HelpDeclined(15.15, "pepper", "the human declined: try it yourself"),
    DecisionMade(
        15.2, 2, "Which oil?", None, math.nan, math.nan, DecisionKind.CLARIFY, "", ("Put a on table",)
    ),
    ClarificationAsked(15.2, ("a", "b"), ("a",), 2),
    ActStarted(17.0, "Put a on table", "a", 0.8),
    TakeOver(18.0, "Put a on table", "a"),
    ActCancelled(18.1, "Put a on table", "a"),
    Intervention(24.0, "a", "fetched by the human", "takeover"),
    CleanUpStarted(25.0, "b", "the robot dropped it"),
    StepDone(26.0, "Add salt."),
    TrustEstimated(26.5, "Put a on table", "a", 0.71, 0.3, "over"),
    ConfidenceStated(26.5, "Put a on table", "a", "I am not sure about this one: I may drop the a.", 0.3),
]


def test_every_kind_is_registered_once() -> None:
    assert set(EVENT_TYPES) == {type(e).kind for e in EPISODE}
    assert len({cls.kind for cls in EVENT_TYPES.values()}) == len(EVENT_TYPES)


def test_stored_json_keeps_the_logs_field_names() -> None:
    decision, act, outcome = (e.to_json() for e in EPISODE[:3])
    assert list(decision)[:7] == [
        "sim_time",
        "step",
        "instruction",
        "action",
        "relevance",
        "confidence",
        "kind",
    ]
    assert decision["kind"] == "act" and decision["object"] == "salt" and decision["candidates"] == []
    assert act == {
        "sim_time": 0.5,
        "action": "Put salt on table",
        "object": "salt",
        "confidence": 0.5,
        "window_s": 0.0,
    }
    assert (outcome["success"], outcome["stage"]) == (False, "grasp")
    assert StepDone(1.23456, "x").to_json() == {"sim_time": 1.235, "object": None, "detail": "x"}


def test_json_round_trip() -> None:
    for event in EPISODE:
        back = from_json(event.kind, event.to_json())
        if isinstance(event, DecisionMade) and math.isnan(event.relevance):
            assert math.isnan(back.relevance) and back.verdict is event.verdict
        else:
            assert back == event, event


def test_a_take_over_in_an_old_log_reads_as_a_take_over() -> None:
    old = {"sim_time": 3.0, "action": "Put salt on table", "object": "salt"}
    assert from_json("intervention", old) == TakeOver(3.0, "Put salt on table", "salt")
    assert isinstance(
        from_json("intervention", {"sim_time": 3.0, "object": "salt", "detail": "d"}), Intervention
    )


def test_bad_rows_are_one_line_errors() -> None:
    with pytest.raises(SconeError, match="unknown event kind 'party'; valid: aborted, act, cancelled"):
        from_json("party", {})
    with pytest.raises(SconeError, match="event 'act' lacks 'object'"):
        from_json("act", {"sim_time": 1.0, "action": "x", "confidence": 0.5})


def test_summary_is_the_fold_of_the_events() -> None:
    stats = summarise(EPISODE)
    assert stats == EpisodeStats(
        decisions=3,
        attempted=3,
        successes=0,
        failures=1,
        help_requests=2,
        help_declined=1,
        clarifications=1,
        cancelled=1,
        takeovers=1,
        help_given=1,
        interventions=1,
        steps_done=1,
        failures_by_stage={"grasp": 1},
        failures_by_action={"Put salt on table": 1},
        aborted=1,
        probe_reasons={"Put salt on table": "the salt slips in my fingers"},
    )
    assert stats.attempted == stats.successes + stats.failures + stats.cancelled + stats.aborted


def test_an_explored_attempt_counts_in_the_budget_and_apart_as_an_exploration() -> None:
    explored = DecisionMade(
        0.5, 1, "Add salt.", "Put salt on table", 0.6, 0.3, DecisionKind.ACT, "now", (), "salt", explored=True
    )
    stats = summarise([explored, ActOutcome(9.0, "Put salt on table", "salt", False, "grasp")])
    assert (stats.failures, stats.explored_failures) == (1, 1)
    log = EventLog()
    for event in (*EPISODE, explored, ActOutcome(20.0, "Put salt on table", "salt", False, "grasp")):
        log(event)
    # EPISODE's failed attempt and the exploratory one: the promise covers every labelled attempt
    assert log.budget_counts() == (2, 2, 1)


def test_the_event_log_folds_as_it_goes_and_passes_events_on() -> None:
    seen: list = []
    log = EventLog(seen.append)
    for event in EPISODE:
        log(event)
    assert seen == EPISODE and log.stats == summarise(EPISODE)
    assert log.failures_of("Put salt on table") == 1 and log.failures_of("Put a on table") == 0


def test_a_carry_on_explored_after_a_probe_counts_as_an_explored_attempt() -> None:
    """The decision to probe is not explored; the judge after the probe may carry on below τ on credit
    (gate.after_probe): its outcome says so, and a failure of it is an explored failure."""
    probe = DecisionMade(
        0.5, 1, "Add salt.", "Put salt on table", 0.6, 0.5, DecisionKind.ACT, "now", (), "salt", probe=True
    )
    on_credit = ActOutcome(9.0, "Put salt on table", "salt", False, "place", 8.5, explored=True)
    assert summarise([probe, on_credit]).explored_failures == 1
    confident = ActOutcome(9.0, "Put salt on table", "salt", False, "place", 8.5)
    assert summarise([probe, confident]).explored_failures == 0
    assert from_json("outcome", on_credit.to_json()) == on_credit
    old = {k: v for k, v in on_credit.to_json().items() if k != "explored"}  # a log written before the field
    assert from_json("outcome", old) == confident


def test_a_set_back_on_kappas_doubt_is_an_aborted_attempt_in_its_words() -> None:
    doubt = ProbeAborted(
        9.0, "Put salt on table", "salt", "I am not sure I can carry the salt", 7.5, 0.9, 1.2
    )
    log = EventLog()
    log(doubt)
    assert (log.stats.aborted, log.budget_counts()) == (1, (0, 0, 0))
    assert log.probe_reason("Put salt on table") == "I am not sure I can carry the salt"
    assert from_json("aborted", doubt.to_json()) == doubt


def test_attempts_after_a_probe_that_felt_it_held_fast_keep_a_record_of_their_own() -> None:
    """gate.after_probe's held-fast rule reads its own record: the attempts whose probe felt the product held
    fast and their failures, counted within the budget's attempts."""
    log = EventLog()
    for event in (
        ActOutcome(1.0, "Put salt on table", "salt", True, None, held_fast=True, traction=0.03),
        ActOutcome(2.0, "Put jam on table", "jam", False, "place", held_fast=True, traction=0.06),
        ActOutcome(3.0, "Put oil on table", "oil", False, "transit", traction=0.2),
        ActOutcome(4.0, "Put rice on table", "rice", True, None, held_fast=True),  # an older log: no load
        ActOutcome(5.0, "Put jam on table", "jam", False, "transit", held_fast=True, by_feel=True),
    ):
        log(event)
        assert from_json("outcome", event.to_json()) == event
    # the older log's fall without a load counts against every load; its success without one says nothing
    assert log.held_fast_carries() == (
        FeltCarry(0.03, True),
        FeltCarry(0.06, False),
        FeltCarry(0.0, False, by_feel=True),
    )
    assert log.budget_counts() == (5, 3, 0)
