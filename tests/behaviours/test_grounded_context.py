"""The grounded κ̂ with fakes: the gate gives it each candidate's execution context, ObserveOutcome stores the
attempt's context, UpdateSelfConfidence learns from it; an ungrounded κ̂ sees embeddings only."""

from __future__ import annotations

import numpy as np
import pytest

from scone_bt.behaviours import (
    ConfidenceGate,
    GatePorts,
    GateSettings,
    Keys,
    ObserveOutcome,
    OutcomeLabels,
    UpdateSelfConfidence,
)
from scone_bt.events import DecisionMade, EventLog
from scone_bt.experience.types import CONTEXT_FIELDS, ExecutionContext
from scone_bt.gate import GateOptions
from scone_bt.motion.types import FailureStage, MotionOutcome
from scone_bt.relevance.types import RankedAction
from tests.behaviours.fakes import FakeHuman, FakeRobot, affordance, blackboard

SALT, OIL = "Put salt on table", "Put olive oil on table"
CONTEXTS = {
    "salt": ExecutionContext(0, 0.03, 1, True, 0.05, 0.12),
    "olive oil": ExecutionContext(2, 0.5, 0, True, None, 0.25),
}


class _Kappa:
    """Records what it was given; a grounded one says so like GroundedEstimator does."""

    def __init__(self, grounded: bool) -> None:
        self.grounded = grounded
        self.predicted: list[np.ndarray] = []
        self.updates: list[tuple[np.ndarray, bool]] = []

    def predict(self, x: np.ndarray) -> np.ndarray:
        self.predicted.append(np.asarray(x))
        return np.full(len(x), 0.9)

    def update(self, x: np.ndarray, success: bool) -> None:
        self.updates.append((np.asarray(x), success))


class _Contexts:
    """A ContextSource that answers from CONTEXTS and records what perception it was handed."""

    def __init__(self) -> None:
        self.calls: list[tuple[list[str], int, dict]] = []

    def __call__(self, targets, detections, frames):
        self.calls.append(([t.name for t in targets], len(detections), frames))
        return {t.name: CONTEXTS[t.name] for t in targets}


def _gate(kappa: _Kappa, events: EventLog, contexts: _Contexts | None) -> ConfidenceGate:
    gate = ConfidenceGate(
        "gate",
        GatePorts(
            kappa=lambda: kappa,
            history=events,
            events=events,
            clock=FakeRobot(time=7.0).now,
            human=FakeHuman(step_index=1),
            contexts=contexts,
        ),
        GateSettings(
            gate=GateOptions(confidence_threshold=0.5, relevance_threshold=0.3),
            max_failures_per_action=3,
            steps_total=4,
        ),
    )
    gate.setup()
    return gate


def _decide(grounded: bool, contexts: _Contexts | None):
    kappa, events = _Kappa(grounded), EventLog()
    frames = {"shelf_left": "frame"}
    bb = blackboard(
        RANKED=[RankedAction(SALT, 0.7), RankedAction(OIL, 0.5)],
        ACTION_EMBEDDINGS={SALT: np.array([1.0, 0.0]), OIL: np.array([0.0, 1.0])},
        INSTRUCTION="Add the salt.",
        AFFORDANCES=[affordance("salt"), affordance("olive oil")],
        DETECTIONS=[affordance("salt").detection, affordance("olive oil").detection],
        FRAMES=frames,
    )
    _gate(kappa, events, contexts).tick_once()
    return kappa, events, bb


def test_the_gate_predicts_a_grounded_kappa_from_embeddings_and_this_ticks_contexts() -> None:
    source = _Contexts()
    kappa, events, bb = _decide(grounded=True, contexts=source)
    assert source.calls == [(["salt", "olive oil"], 2, {"shelf_left": "frame"})]
    (X,) = kappa.predicted
    assert X.shape == (2, 2 + len(CONTEXT_FIELDS))
    np.testing.assert_array_equal(X[0, :2], [1.0, 0.0])
    np.testing.assert_array_equal(X[0, 2:], CONTEXTS["salt"].vector())
    np.testing.assert_array_equal(X[1, 2:], CONTEXTS["olive oil"].vector())  # NaN where nothing was measured
    assert bb.get(Keys.CONTEXTS) == {SALT: CONTEXTS["salt"], OIL: CONTEXTS["olive oil"]}
    assert bb.get(Keys.DECISION).action == SALT and bb.get(Keys.TARGET_CONTEXT) == CONTEXTS["salt"]
    (decision,) = events.events
    assert isinstance(decision, DecisionMade) and decision.context == CONTEXTS["salt"]


def test_an_ungrounded_kappa_sees_embeddings_only_and_the_context_is_still_kept() -> None:
    kappa, events, bb = _decide(grounded=False, contexts=_Contexts())
    (X,) = kappa.predicted
    assert X.shape == (2, 2)
    assert bb.get(Keys.TARGET_CONTEXT) == CONTEXTS["salt"]  # stored with the outcome for a later grounded κ̂


def test_without_a_context_source_a_grounded_kappa_sees_every_context_value_missing() -> None:
    kappa, events, bb = _decide(grounded=True, contexts=None)
    (X,) = kappa.predicted
    assert X.shape == (2, 2 + len(CONTEXT_FIELDS)) and np.isnan(X[:, 2:]).all()
    assert bb.get(Keys.TARGET_CONTEXT) is None and events.events[0].context is None


class _Store:
    def __init__(self) -> None:
        self.stored: list = []

    def append(self, outcome) -> None:
        self.stored.append(outcome)


@pytest.mark.parametrize("grounded", [True, False])
def test_the_outcome_stores_the_attempts_context_and_kappa_learns_from_it(grounded: bool) -> None:
    store = _Store()
    bb = blackboard(
        TARGET=affordance("salt"),
        TARGET_CONTEXT=CONTEXTS["salt"],
        MOTION_OUTCOME=MotionOutcome(False, FailureStage.GRASP, "slipped", 4.0),
        ACTION_EMBEDDINGS={SALT: np.array([1.0, 0.0])},
    )
    observe = ObserveOutcome(
        "observe", FakeRobot(time=3.0), lambda: store, EventLog(), OutcomeLabels("minilm", "r1", "panda")
    )
    observe.setup()
    observe.tick_once()
    (outcome,) = store.stored
    assert outcome.execution == CONTEXTS["salt"] and not outcome.success and bb.get(Keys.OUTCOME) is outcome
    kappa = _Kappa(grounded)
    learn = UpdateSelfConfidence("learn", lambda: kappa)
    learn.setup()
    learn.tick_once()
    ((x, success),) = kappa.updates
    assert not success
    expected = np.concatenate([[1.0, 0.0], CONTEXTS["salt"].vector()]) if grounded else np.array([1.0, 0.0])
    np.testing.assert_array_equal(x, expected)
