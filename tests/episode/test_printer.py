"""The decision lines and the condition say which rule decided: κ̂ against the threshold, or another rule."""

from __future__ import annotations

import dataclasses
import math

import pytest

from scone_bt.behaviours import BehaviourOptions
from scone_bt.config.tree_parameters import ProbeParameters
from scone_bt.episode.printer import LinePrinter, condition_line, decision_line, shown_confidence
from scone_bt.episode.summary import EpisodeSummary
from scone_bt.events import DecisionMade
from scone_bt.gate.types import DecisionKind


def _decision(
    verdict: DecisionKind = DecisionKind.ACT, rule: str = "", reason: str = "", **kw
) -> DecisionMade:
    return DecisionMade(
        0.0,
        2,
        "Cook the spaghetti.",
        "Put garlic on table",
        0.39,
        0.4,
        verdict,
        reason=reason,
        rule=rule,
        **kw,
    )


def test_a_line_the_failure_rule_decided_says_so() -> None:
    line = decision_line(_decision(DecisionKind.ASK, "failure-limit", "failed 3 times on this action"), 5)
    assert line.endswith("ASK-HELP  (failure rule: failed 3 times on this action)")
    plain = decision_line(_decision(DecisionKind.ASK, "", "asking for help: confidence 0.40 < 0.50"), 5)
    assert plain.endswith("ASK-HELP") and "rule" not in plain


def test_with_self_confidence_off_a_line_does_not_read_as_kappas_call() -> None:
    event = _decision(DecisionKind.ACT, "self-confidence-off", "acting: self-confidence is off", need="later")
    line = decision_line(event, 5)
    assert line.endswith("ACT  (needed later)  (self-confidence off: acts whatever κ̂ says)")


def test_rules_to_come_are_shown_by_label_and_reason() -> None:
    line = decision_line(_decision(DecisionKind.ASK, "infeasible", "no grasp fits"), 5)
    assert line.endswith("(infeasible: no grasp fits)")
    waiting = DecisionMade(
        0.0, 2, "Cook.", None, math.nan, math.nan, DecisionKind.IDLE, reason="waiting: pasta", rule="missing"
    )
    assert decision_line(waiting, 5).endswith("IDLE  (missing)")  # the reason is the target already


def test_the_printer_counts_the_decisions_each_rule_made() -> None:
    printed: list[str] = []
    printer = LinePrinter(printed.append, 5)
    printer(_decision(DecisionKind.ACT, "self-confidence-off"))
    printer(_decision(DecisionKind.ACT, "self-confidence-off"))
    printer(_decision(DecisionKind.ASK, "failure-limit", "failed 3 times on this action"))
    printer(_decision(DecisionKind.ACT))
    assert printer.rules == {"self-confidence-off": 2, "failure-limit": 1}


def test_the_condition_names_kappa_and_its_threshold_or_the_control() -> None:
    on = BehaviourOptions().resolve()  # the shipped tree: the strict promise and the heft test on
    assert condition_line(on) == (
        f"self-confidence on ({on.estimator}, failure budget: 15% of attempts, kept over the long run; explores "
        f"only on earned credit; hefts what it is unsure of), ask after 1 failure on one action"
    )
    before = BehaviourOptions(exploration_credit=False, probe=ProbeParameters(enabled=False)).resolve()
    assert condition_line(before) == (
        f"self-confidence on ({on.estimator}, failure budget: 15% of attempts, kept over the long run), "
        "ask after 1 failure on one action"  # the shipped tree's: it never repeats a failure
    )
    small = BehaviourOptions(target_failure_rate=0.004).resolve()
    assert "failure budget: 0.4% of attempts" in condition_line(small)  # was rounded to "0%"
    assert "failure budget: 2.5% of attempts" in condition_line(
        BehaviourOptions(target_failure_rate=0.025).resolve()
    )
    paper = BehaviourOptions(gate="paper").resolve()
    assert condition_line(paper) == (
        f"self-confidence on ({paper.estimator}, threshold {paper.confidence_threshold:g}), "
        "ask after 1 failure on one action"
    )
    strict = BehaviourOptions(exploration_credit=True, probe=ProbeParameters(enabled=False)).resolve()
    assert (
        "failure budget: 15% of attempts, kept over the long run; explores only on earned credit), ask"
        in condition_line(strict)
    )
    hefts = BehaviourOptions(exploration_credit=True, probe=ProbeParameters(enabled=True)).resolve()
    assert (
        "kept over the long run; explores only on earned credit; hefts what it is unsure of), ask"
        in condition_line(hefts)
    )
    assert (
        BehaviourOptions(use_self_confidence=False).resolve().max_failures_per_action == 3
    )  # the paper's control
    off = BehaviourOptions(use_self_confidence=False, max_failures_per_action=1).resolve()
    assert (
        condition_line(off)
        == "self-confidence OFF (the paper's control: always act, ask after 1 failure on one action)"
    )


def test_the_summary_states_the_condition_and_the_rules_that_decided() -> None:
    summary = EpisodeSummary(
        "example:x", "X", "panda", True, 1, 1, 1, 1, 0, {}, 1, 0, 0, 0, 3, 10, 10, 1.0, 1.0, {}, (),
        condition="self-confidence OFF (the paper's control: always act, ask after 3 failures on one action)",
        decided_by_rule={"self-confidence-off": 1, "failure-limit": 1},
    )  # fmt: skip
    text = summary.format()
    assert "condition          self-confidence OFF (the paper's control" in text
    assert "made by a rule, not κ̂: failure rule 1, self-confidence off 1" in text


@pytest.mark.parametrize(
    ("verdict", "confidence", "rule", "explored", "shown"),
    [
        (DecisionKind.ASK, 0.928, "", False, "0.92"),  # below a threshold of 0.93: never printed as 0.93
        (
            DecisionKind.ACT,
            0.921,
            "",
            False,
            "0.93",
        ),  # at or above a threshold of 0.921: never printed as 0.92
        (DecisionKind.ACT, 0.928, "", True, "0.92"),  # an exploration acts below the threshold
        (DecisionKind.ACT, 0.93, "", False, "0.93"),  # exact to the print: neither up nor down
        (DecisionKind.ASK, 0.93, "", False, "0.93"),
        (DecisionKind.ASK, 0.928, "failure-limit", False, "0.93"),  # a rule decided: plain rounding
        (DecisionKind.IDLE, math.nan, "missing", False, "--"),
    ],
)
def test_the_confidence_shown_never_contradicts_the_verdict(
    verdict, confidence, rule, explored, shown
) -> None:
    event = DecisionMade(
        0.0, 2, "Cook.", "Put garlic on table", 0.39, confidence, verdict, rule=rule, explored=explored
    )
    assert shown_confidence(event) == shown
    assert f"conf {shown:>4}  {verdict.label}" in decision_line(event, 5)


def test_a_decision_to_heft_first_says_so() -> None:
    heft = DecisionMade(0.0, 2, "Cook.", "Put garlic on table", 0.39, 0.5, DecisionKind.ACT, probe=True)
    assert decision_line(heft, 5).endswith("conf 0.50  ACT  (heft first)")
    plain = dataclasses.replace(heft, probe=False)
    assert decision_line(plain, 5).endswith("conf 0.50  ACT")


def test_the_summary_accounts_for_every_attempt_ingredient_and_the_budget() -> None:
    base = dict(condition="", needed_on_table={"rice noodles": True})
    cut = EpisodeSummary(
        "example:x", "X", "panda", False, 0, 2, 1, 0, 0, {}, 0, 0, 0, 0, 3, 60, 60, 6.5, 1.0, **base,
        decision_log=(), not_stocked=2, failure_budget=0.15,
    )  # fmt: skip
    text = cut.format()
    assert "ingredients        1/1 on the table   2 more not stocked (the human brings them)" in text
    assert "failures 0 (none)   cut short by the end of the episode 1" in text
    assert "failure rate" not in text  # no attempt has an outcome yet
    failed = EpisodeSummary(
        "example:x", "X", "panda", True, 2, 2, 3, 0, 3, {"grasp": 3}, 0, 0, 0, 0, 3, 60, 60, 6.5, 1.0, **base,
        decision_log=(), failure_budget=0.15,
    )  # fmt: skip
    line = next(x for x in failed.format().splitlines() if x.startswith("actions attempted"))
    assert line.endswith("failures 3 (grasp 3)   failure rate 100% (budget 15%, kept over the long run)")
    strict = dataclasses.replace(failed, strict_promise=True)
    assert (
        strict.format().count(
            "failure rate 100% (budget 15%, kept over the long run; explores only on earned credit)"
        )
        == 1
    )
    assert "more not stocked" not in failed.format() and "cut short" not in line
    # A heft test's set-back is neither a success nor a failure, and no attempt the episode's end cut short
    # (it was counted as cut short).
    set_back = dataclasses.replace(cut, completed=True, steps_completed=2, set_back=1)
    line = next(x for x in set_back.format().splitlines() if x.startswith("actions attempted"))
    assert line.endswith("failures 0 (none)   set back after a heft 1") and "cut short" not in line
