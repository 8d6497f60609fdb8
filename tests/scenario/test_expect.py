"""Expectations on synthetic event streams: a false one fails with its name, the tick and the events around it."""

from __future__ import annotations

import math

import pytest

from scone_bt.events import ActOutcome, ActStarted, DecisionMade, HelpRequested, StepDone
from scone_bt.gate.types import DecisionKind
from scone_bt.scenario.expect import CHECKS, Outcome, Record, check, decision_tokens
from scone_bt.scenario.model import EXPECTATION_KINDS, ScenarioFile


def _decision(t: float, verdict: str, obj: str | None, conf: float = 0.5, rule: str = "") -> DecisionMade:
    return DecisionMade(
        t,
        1,
        "step",
        f"Put {obj} on table" if obj else None,
        0.5,
        conf,
        DecisionKind(verdict),
        object_name=obj,
        rule=rule,
    )


STREAM = [
    Record(1, _decision(0.1, "act", "salt", 0.7)),
    Record(1, ActStarted(0.1, "Put salt on table", "salt", 0.7)),
    Record(40, ActOutcome(4.0, "Put salt on table", "salt", False, "grasp")),
    Record(41, _decision(4.1, "act", "salt", 0.3)),
    Record(41, ActStarted(4.1, "Put salt on table", "salt", 0.3)),
    Record(80, ActOutcome(8.0, "Put salt on table", "salt", False, "grasp")),
    Record(81, _decision(8.1, "ask", "olive oil", 0.2)),
    Record(81, HelpRequested(8.1, "Put olive oil on table", "olive oil")),
    Record(150, StepDone(15.0, "Bring a large pot of water to the boil")),
]
END = Outcome(completed=False, steps_completed=1, on_table={"salt": False}, ticks=200, sim_time=20.0)


def _expect(item: dict) -> object:
    return ScenarioFile.model_validate({"description": "d", "expect": [item]}).expect[0]


@pytest.mark.parametrize(
    ("item", "problem", "tick"),
    [
        ({"never_attempts": "salt"}, "the robot attempted 'salt'", 1),
        ({"asks_before_attempt": "salt"}, "the robot attempted 'salt' before asking for help with it", 1),
        ({"max_failures": 1}, "2 failures, more than 1", 80),
        ({"no_repeated_failure": True}, "'Put salt on table' failed at grasp again", 80),
        ({"completes_step": 1, "within_s": 10}, "step 1 was done at 15.0 s, after 10 s", 150),
        ({"completes_step": 2}, "step 2 was never done (1 steps done)", 200),
        ({"completes": True}, "the recipe was not done (1 steps done)", 200),
        (
            {"kappa": "salt", "above": 0.5, "after": {"kind": "outcome", "object": "salt"}},
            "κ̂ was 0.300, not above 0.5",
            41,
        ),
        ({"decisions_match": "^ask:"}, "the decisions were: act:salt act:salt ask:olive_oil", 200),
        ({"count": {"kind": "help_request"}, "max": 0}, "1 matching events, more than 0", 81),
        ({"on_table": ["salt"]}, "not on the table at the end: salt", 200),
    ],
)
def test_a_false_expectation_fails_with_its_name_and_where(item: dict, problem: str, tick: int) -> None:
    failure = check(_expect(item), STREAM, END)
    assert failure is not None
    assert failure.problem == problem
    assert failure.tick == tick
    assert any(line.startswith("→ ") for line in failure.around) or tick == END.ticks
    text = failure.format()
    assert text.splitlines()[0].startswith(f"expectation '{next(iter(item))}")
    assert f"at tick {tick}" in text


@pytest.mark.parametrize(
    "item",
    [
        {"never_attempts": "olive oil"},
        {"asks_before_attempt": "olive oil"},
        {"max_failures": 2},
        {"max_failures": 0, "object": "olive oil"},
        {"completes_step": 1, "within_s": 20},
        {"completes": False},
        {"kappa": "salt", "below": 0.5, "after": {"kind": "outcome", "object": "salt", "success": False}},
        {"kappa": "salt", "above": 0.5},
        {"decisions_match": r"act:salt act:salt ask:olive_oil"},
        {"count": {"kind": "outcome", "success": False, "stage": "grasp"}, "min": 2, "max": 2},
        {"count": {"kind": "decision", "verdict": "ask", "object": "olive oil"}, "min": 1},
    ],
)
def test_a_true_expectation_holds(item: dict) -> None:
    assert check(_expect(item), STREAM, END) is None


def test_a_named_expectation_reports_its_name_and_tokens_replace_spaces() -> None:
    failure = check(_expect({"never_attempts": "salt", "name": "keeps off the salt"}), STREAM, END)
    assert failure is not None and failure.expectation == "keeps off the salt"
    assert decision_tokens(STREAM) == "act:salt act:salt ask:olive_oil"
    assert math.isnan(_decision(0, "idle", None, math.nan).confidence)


def test_every_expectation_kind_has_its_own_check():
    assert set(CHECKS) == set(EXPECTATION_KINDS.values())


def test_an_unknown_expectation_is_refused_naming_its_type():
    class Stranger:
        name = "stranger"

    with pytest.raises(TypeError, match="unknown expectation Stranger"):
        check(Stranger(), STREAM, END)
