"""ConfidenceGate with fakes: the failure limit reads the attempt history folded from the events, and each
decision is emitted as a typed event carrying its object."""

from __future__ import annotations

import numpy as np
import py_trees
import pytest

from scone_bt.behaviours import ConfidenceGate, DecisionIs, GatePorts, GateSettings, Keys
from scone_bt.events import ActOutcome, DecisionMade, EventLog
from scone_bt.gate import GateOptions
from scone_bt.gate.rules import apply_failure_limit
from scone_bt.gate.types import Decision, DecisionKind
from scone_bt.relevance.types import RankedAction
from tests.behaviours.fakes import FakeHuman, FakeRobot, affordance, blackboard

SALT = "Put salt on table"


class _Kappa:
    def __init__(self, confidence: float) -> None:
        self.confidence = confidence

    def predict(self, x: np.ndarray) -> np.ndarray:
        return np.full(len(x), self.confidence)

    def update(self, x, success) -> None:
        pass


def _gate(events: EventLog, confidence: float = 0.9, human: FakeHuman | None = None) -> ConfidenceGate:
    gate = ConfidenceGate(
        "gate",
        GatePorts(
            kappa=lambda: _Kappa(confidence),
            history=events,
            events=events,
            clock=FakeRobot(time=7.0).now,
            human=human or FakeHuman(step_index=1),
        ),
        GateSettings(
            gate=GateOptions(confidence_threshold=0.5, relevance_threshold=0.3),
            max_failures_per_action=3,
            steps_total=4,
        ),
    )
    gate.setup()
    return gate


def _decide(events: EventLog, **kw) -> Decision:
    bb = blackboard(
        RANKED=[RankedAction(SALT, 0.7)],
        ACTION_EMBEDDINGS={SALT: np.array([1.0, 0.0])},
        INSTRUCTION="Add the salt.",
        AFFORDANCES=[affordance("salt")],
    )
    _gate(events, **kw).tick_once()
    assert bb.get(Keys.TARGET) == (affordance("salt") if bb.get(Keys.DECISION).action else None)
    return bb.get(Keys.DECISION)


def _failures(events: EventLog, n: int) -> None:
    for _ in range(n):
        events(ActOutcome(1.0, SALT, "salt", False, "grasp"))


@pytest.mark.parametrize(
    ("failed", "kind"), [(0, DecisionKind.ACT), (2, DecisionKind.ACT), (3, DecisionKind.ASK)]
)
def test_failure_limit_asks_after_three_failures_on_the_action(failed, kind) -> None:
    events = EventLog()
    _failures(events, failed)
    decision = _decide(events)
    assert decision.kind is kind and decision.object_name == "salt"
    if kind is DecisionKind.ASK:
        assert decision.reason == "failed 3 times on this action"


def test_failures_of_another_action_do_not_count() -> None:
    events = EventLog()
    for _ in range(5):
        events(ActOutcome(1.0, "Put sugar on table", "sugar", False, "grasp"))
    assert _decide(events).kind is DecisionKind.ACT


def test_the_decision_is_emitted_with_the_humans_step_when_recipe_blind() -> None:
    events = EventLog()
    _decide(events, confidence=0.2)
    (event,) = events.events
    assert isinstance(event, DecisionMade)
    assert (event.verdict, event.step, event.sim_time, event.object_name) == (
        DecisionKind.ASK,
        2,
        7.0,
        "salt",
    )
    assert event.to_json()["kind"] == "ask" and event.to_json()["object"] == "salt"


def test_apply_failure_limit_leaves_asks_and_idles_alone() -> None:
    ask = Decision(DecisionKind.ASK, SALT, 0.5, 0.1, "not confident")
    idle = Decision(DecisionKind.IDLE, None, float("nan"), float("nan"), "nothing")
    assert apply_failure_limit(ask, 9, 3) is ask and apply_failure_limit(idle, 9, 3) is idle


def test_decision_is_checks_the_kind() -> None:
    bb = blackboard(DECISION=Decision(DecisionKind.ASK, SALT, 0.5, 0.1, "not confident"))
    ask, act = DecisionIs("ask?", "ask"), DecisionIs("act?", DecisionKind.ACT)
    ask.tick_once()
    act.tick_once()
    assert ask.status is py_trees.common.Status.SUCCESS and act.status is py_trees.common.Status.FAILURE
    assert bb.get(Keys.DECISION).kind is DecisionKind.ASK


class _Wrapped:
    """A κ̂ provider for the gate: the real ε-greedy estimator (no outcomes yet, so its belief is the prior)."""

    def __init__(self, epsilon: float) -> None:
        from scone_bt.confidence import make_estimator

        self.estimator = make_estimator("eps-knn", seed=1, epsilon=epsilon)

    def __call__(self):
        return self.estimator


@pytest.mark.parametrize(
    ("epsilon", "kind", "explored"), [(1.0, DecisionKind.ACT, True), (0.0, DecisionKind.ASK, False)]
)
def test_exploration_acts_but_the_decision_shows_the_belief(epsilon, kind, explored) -> None:
    events = EventLog()
    wrapped = _Wrapped(epsilon)
    bb = blackboard(
        RANKED=[RankedAction(SALT, 0.7)],
        ACTION_EMBEDDINGS={SALT: np.array([1.0, 0.0], dtype=np.float32)},
        INSTRUCTION="Add the salt.",
        AFFORDANCES=[affordance("salt")],
    )
    gate = ConfidenceGate(
        "gate",
        GatePorts(
            kappa=wrapped,
            history=events,
            events=events,
            clock=FakeRobot(time=7.0).now,
            human=FakeHuman(step_index=1),
        ),
        GateSettings(
            gate=GateOptions(confidence_threshold=0.6, relevance_threshold=0.3),
            max_failures_per_action=3,
            steps_total=4,
        ),
    )
    gate.setup()
    gate.tick_once()
    decision = bb.get(Keys.DECISION)
    prior = float(wrapped.estimator.belief(np.array([[1.0, 0.0]], dtype=np.float32))[0])
    assert (decision.kind, decision.explored, decision.confidence) == (kind, explored, prior)
    assert prior < 0.6  # so only the exploration draw can make it act
    event = [e for e in events.events if isinstance(e, DecisionMade)][-1]
    assert event.explored is explored and event.confidence == prior
    assert bb.get(Keys.CONFIDENCES)[SALT] == prior


def test_decision_is_from_context_needs_a_kind():
    # kind is optional in the signature only to match StageBehaviour.from_context; missing, it fails in one line
    assert DecisionIs.from_context("act?", object(), kind="act").kind is DecisionKind.ACT
    with pytest.raises(ValueError, match="args.kind is required, one of: .*act"):
        DecisionIs.from_context("act?", object())
