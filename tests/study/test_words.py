"""The tablet's words: the rule's reason in plain words, and grammar for plurals and mass nouns."""

from __future__ import annotations

import dataclasses
import math

import pytest

from scone_bt.events import ActOutcome, DecisionMade, HelpGiven, Intervention
from scone_bt.gate.types import DecisionKind
from scone_bt.study.words import decision_words, feed_line, is_are, it_them


def _decision(rule: str, reason: str, kind=DecisionKind.ASK, item="parmesan", confidence=0.8) -> DecisionMade:
    return DecisionMade(0.0, 1, "step", f"Put {item} on table", 0.5, confidence, kind, object_name=item,
                        reason=reason, rule=rule)  # fmt: skip


@pytest.mark.parametrize(
    ("item", "verb", "pronoun"),
    [("spaghetti", "is", "it"), ("salt", "is", "it"), ("hummus", "is", "it"), ("molasses", "is", "it"),
     ("crushed tomatoes", "are", "them"), ("black beans", "are", "them"), ("berries", "are", "them")],
)  # fmt: skip
def test_plurals_and_mass_nouns(item, verb, pronoun):
    assert (is_are(item), it_them(item)) == (verb, pronoun)
    assert (
        feed_line(ActOutcome(1.0, f"Put {item} on table", item, True, None))
        == f"The {item} {verb} on the table."
    )


def test_the_robot_says_the_rules_reason_and_not_confident_only_when_kappa_decided():
    blocked = "I cannot grasp the parmesan: the cooking cream is in the way (known: not planned again in this scene)"
    said = {
        rule: decision_words(_decision(rule, reason))
        for rule, reason in [
            ("infeasible", blocked),
            ("failure-limit", "failed 3 times on this action"),
            ("missing", "I cannot see the parmesan the step needs: please bring it"),
            ("", "kappa below the threshold"),
        ]
    }
    assert said["infeasible"] == "I cannot grasp the parmesan: the cooking cream is in the way."
    assert said["failure-limit"] == "I have failed three times with the parmesan."
    assert said["missing"] == "I cannot see the parmesan."
    assert said[""].startswith("I might drop it: I am not confident")
    assert [r for r, text in said.items() if "confident" in text] == [""]
    control = decision_words(_decision("self-confidence-off", "self-confidence off", DecisionKind.ACT))
    assert control == "I am about to fetch the parmesan." and "confident" not in control
    nan = decision_words(_decision("", "kappa", item="crushed tomatoes", confidence=math.nan))
    assert nan == "I might drop them: I am not confident I can fetch the crushed tomatoes."


def test_the_feed_uses_the_participants_words():
    assert feed_line(HelpGiven(3.0, "spaghetti", "fetched by the human")) == "You brought the spaghetti."
    assert (
        feed_line(Intervention(3.0, "crushed tomatoes", "x", "idle")) == "You brought the crushed tomatoes."
    )
    failed = feed_line(ActOutcome(1.0, "Put parmesan on table", "parmesan", False, "planning"))
    assert failed == "The robot could not fetch the parmesan: it could not find a safe way to move."


def test_a_decline_for_want_of_room_is_not_told_as_try_it_yourself():
    from scone_bt.events import NO_ROOM, HelpDeclined

    assert (
        feed_line(HelpDeclined(2.0, "chicken", NO_ROOM)) == "There was no room on the table for the chicken."
    )
    asked = feed_line(HelpDeclined(2.0, "chicken", "the human declined: try it yourself"))
    assert asked == "You asked the robot to try the chicken itself."


def test_a_heft_first_is_told_before_the_arm_lifts():
    heft = dataclasses.replace(
        _decision("", "", DecisionKind.ACT, item="olive oil", confidence=0.5), probe=True
    )
    assert decision_words(heft) == (
        "I am not sure about the olive oil: I will lift it a little first to feel whether I can hold it, "
        "then fetch it or put it back and ask you."
    )
    plain = dataclasses.replace(heft, probe=False)
    assert decision_words(plain) == "I am about to fetch the olive oil."


def test_a_longer_look_for_a_missing_item_is_told_before_the_robot_waits_for_it():
    def idle(reason: str) -> str:
        return decision_words(_decision("missing", reason, DecisionKind.IDLE, item=""))

    assert (
        idle("waiting: parmesan not in sight (looking again)")
        == "I cannot see the parmesan: I am looking again."
    )
    assert idle("waiting: parmesan not in sight (asked for)") == "I cannot see the parmesan: I am waiting."
