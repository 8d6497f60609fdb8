"""The gate's named steps (behaviours.gate_steps) and its bundles (behaviours.gate_config), without py_trees."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from scone_bt.behaviours import GatePorts, GateSettings
from scone_bt.behaviours.gate_steps import (
    CARD_ITEMS_LEFT,
    EVERY_STEP_SERVED,
    candidate_contexts,
    confidences,
    decision_event,
    gate_counts,
    past_the_end,
    probe_reasons,
    settle_idle,
    shown_target,
)
from scone_bt.behaviours.ports import AttemptHistory
from scone_bt.events import EventLog
from scone_bt.experience.types import ExecutionContext
from scone_bt.gate import GateOptions
from scone_bt.gate.budget import BudgetCounts, BudgetOptions, FeltCarry
from scone_bt.gate.types import Decision, DecisionKind
from scone_bt.relevance.types import RankedAction
from tests.behaviours.fakes import FakeHuman, FakeRobot, affordance

SALT = "Put salt on table"


def _idle() -> Decision:
    return Decision(DecisionKind.IDLE, None, 0.0, 0.0, "nothing to do")


def test_the_settings_give_the_rules_the_behaviour_decides_by() -> None:
    budget = BudgetOptions(explore_rate=0.0)
    settings = GateSettings(
        GateOptions(), max_failures_per_action=3, steps_total=4, budget=budget, opening_m=0.08
    )
    rules = settings.rules
    assert (rules.budget, rules.exploration, rules.failure_limit, rules.opening_m) == (
        budget,
        budget,
        3,
        0.08,
    )
    with pytest.raises(dataclasses.FrozenInstanceError):
        settings.seed = 1  # type: ignore[misc]


def test_the_ports_are_frozen_with_optional_planning() -> None:
    events = EventLog()
    ports = GatePorts(lambda: None, events, events, FakeRobot().now, FakeHuman())  # type: ignore[arg-type,return-value]
    assert ports.contexts is None and ports.robot is None and ports.seeds is None
    with pytest.raises(dataclasses.FrozenInstanceError):
        ports.robot = None  # type: ignore[misc]


def test_an_idle_decision_asks_for_a_missing_item_once_with_the_budget_and_only_waits_without() -> None:
    asked: set[str] = set()
    first = settle_idle(_idle(), ("salt",), budget_gate=True, asked_missing=asked)
    assert (first.kind, first.rule, asked) == (DecisionKind.ASK, "missing", {"salt"})
    again = settle_idle(_idle(), ("salt",), budget_gate=True, asked_missing=asked)
    assert (again.kind, again.rule) == (DecisionKind.IDLE, "missing")
    paper = settle_idle(_idle(), ("salt",), budget_gate=False, asked_missing=set())
    assert paper.kind is DecisionKind.IDLE and "salt" in paper.reason
    assert settle_idle(_idle(), (), budget_gate=True, asked_missing=set()) == _idle()


def test_the_shown_target_is_the_acted_or_asked_about_affordance_only() -> None:
    salt = affordance("salt")
    act = Decision(DecisionKind.ACT, SALT, 0.9, 0.9, "go")
    ask = Decision(DecisionKind.ASK, SALT, 0.9, 0.1, "help")
    assert shown_target(act, salt) is salt and shown_target(ask, salt) is salt
    assert shown_target(dataclasses.replace(ask, rule="missing"), salt) is None
    assert shown_target(_idle(), salt) is None


def test_contexts_are_keyed_by_action_text_and_skip_unknown_objects() -> None:
    salt, sugar = affordance("salt"), affordance("sugar")
    source = lambda targets, seen, frames: {"salt": ExecutionContext(detected=True)}  # noqa: E731
    assert candidate_contexts(source, [salt, sugar], [], {}) == {salt.text: ExecutionContext(detected=True)}
    assert candidate_contexts(None, [salt], [], {}) == {}


class _Explorer:
    def predict(self, x: np.ndarray) -> np.ndarray:
        raise AssertionError("an exploring κ̂ is read through its belief")

    def update(self, x, success) -> None:
        pass

    def belief(self, x: np.ndarray) -> np.ndarray:
        return np.full(len(x), 0.25)

    def explores(self, x: np.ndarray) -> np.ndarray:
        return np.ones(len(x), dtype=bool)


def test_confidences_read_the_belief_and_draws_of_an_exploring_kappa() -> None:
    ranked = [RankedAction(SALT, 0.7)]
    assert confidences(_Explorer(), ranked, {SALT: np.array([1.0, 0.0])}, {}) == ([0.25], [True])
    assert confidences(_Explorer(), [], {}, {}) == ([], [])


def test_probe_reasons_name_only_what_a_probe_set_back() -> None:
    class _History:
        def failures_of(self, action: str) -> int:
            return 0

        def budget_counts(self) -> tuple[int, int, int]:
            return 3, 1, 0

        def held_fast_carries(self) -> tuple[FeltCarry, ...]:
            return FeltCarry(0.05, True), FeltCarry(0.04, False)

        def probe_reason(self, action: str) -> str | None:
            return "too heavy" if action == SALT else None

    history = _History()
    assert isinstance(history, AttemptHistory)
    ranked = [RankedAction(SALT, 0.7), RankedAction("Put sugar on table", 0.5)]
    assert probe_reasons(history, ranked) == {SALT: "too heavy"}
    assert probe_reasons(EventLog(), ranked) == {}  # no probe yet
    counts = gate_counts(history, _Explorer())
    assert (counts.attempts, counts.failures, counts.held_fast_record()) == (3, 1, BudgetCounts(2, 1))
    assert counts.held_fast_record(0.035) == BudgetCounts(1, 0)  # the fall felt heavier: it says nothing here


def test_the_event_carries_the_decision_and_rounds_the_planning_time() -> None:
    assert past_the_end(True) == CARD_ITEMS_LEFT and past_the_end(False) == EVERY_STEP_SERVED
    decision = Decision(DecisionKind.ACT, SALT, 0.7, 0.9, "go", object_name="salt")
    event = decision_event(
        decision, sim_time=2.0, step=3, instruction="salt it", context=None, planning_s=0.123456
    )
    assert (event.action, event.verdict, event.step, event.planning_s) == (SALT, DecisionKind.ACT, 3, 0.1235)
