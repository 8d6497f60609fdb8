"""ObserveOutcome and UpdateSelfConfidence with fakes: the label comes from the outcome sensor, the outcome is
stored before it is reported, and a take-over is no label."""

from __future__ import annotations

import numpy as np
import pytest

from scone_bt.behaviours import Keys, ObserveOutcome, OutcomeLabels, UpdateSelfConfidence
from scone_bt.behaviours.outcome import label_outcome
from scone_bt.episode.printer import LinePrinter
from scone_bt.events import ActCancelled, ActOutcome, EventLog
from scone_bt.motion.types import FailureStage, MotionOutcome
from tests.behaviours.fakes import FakeRobot, affordance, blackboard

LABELS = OutcomeLabels("onehot", "r1", "panda", "", {"robot": "panda"})


class _Store:
    def __init__(self, log: list[str]) -> None:
        self.log, self.stored = log, []

    def append(self, outcome) -> None:
        self.log.append("stored")
        self.stored.append(outcome)


def _observe(motion: MotionOutcome, on_table: bool):
    order: list[str] = []
    store = _Store(order)
    printer = LinePrinter(lambda line: order.append("printed"), 3)
    events = EventLog(lambda e: order.append(f"emitted {e.kind}"), printer)
    robot = FakeRobot(on_table={"salt"} if on_table else set(), time=3.0)
    bb = blackboard(TARGET=affordance("salt"), MOTION_OUTCOME=motion)
    node = ObserveOutcome("observe", robot, lambda: store, events, LABELS)
    node.setup()
    node.tick_once()
    return node, store, events, order, bb


def test_success_is_stored_before_it_is_emitted_and_printed() -> None:
    _, store, events, order, bb = _observe(MotionOutcome(True, None, "placed", 9.0), on_table=True)
    assert order == ["stored", "emitted outcome", "printed"]
    (outcome,) = store.stored
    assert outcome.success and outcome.context == {"robot": "panda", "sim_time": 3.0}
    assert (outcome.robot_id, outcome.arm, outcome.embedder) == ("r1", "panda", "onehot")
    assert events.stats.successes == 1 and bb.get(Keys.OUTCOME) is outcome


def test_a_motion_success_that_left_the_object_off_the_table_is_a_failure_at_place() -> None:
    _, store, events, _, _ = _observe(MotionOutcome(True, None, "placed", 9.0), on_table=False)
    assert not store.stored[0].success and store.stored[0].failure_stage == "place"
    (event,) = events.events
    assert isinstance(event, ActOutcome) and event.stage == "place" and not event.success
    assert events.stats.failures_by_action == {"Put salt on table": 1}


def test_a_failure_keeps_the_motion_stage_and_its_first_message_line() -> None:
    motion = MotionOutcome(False, FailureStage.GRASP, "slipped; at 0.3 m", 4.0)
    _, store, events, _, _ = _observe(motion, on_table=False)
    assert store.stored[0].failure_stage == "grasp"
    assert events.events[0].message == "slipped" and events.stats.failures_by_stage == {"grasp": 1}


def test_a_take_over_is_not_an_outcome() -> None:
    _, store, events, order, bb = _observe(MotionOutcome(False, FailureStage.CANCELLED, "taken", 1.0), True)
    assert store.stored == [] and [type(e) for e in events.events] == [ActCancelled]
    assert events.stats.cancelled == 1 and events.stats.failures == 0
    assert bb.get(Keys.OUTCOME) is None and order == ["emitted cancelled", "printed"]


@pytest.mark.parametrize(
    ("success", "stage", "on_table", "label"),
    [
        (True, None, True, (True, None)),
        (True, None, False, (False, FailureStage.PLACE)),
        (False, FailureStage.IK, False, (False, FailureStage.IK)),
        (False, FailureStage.TRANSIT, True, (False, FailureStage.TRANSIT)),
    ],
)
def test_label_outcome(success, stage, on_table, label) -> None:
    assert label_outcome(MotionOutcome(success, stage, "", 1.0), on_table) == label


class _Kappa:
    def __init__(self) -> None:
        self.updates: list[tuple[list[float], bool]] = []

    def predict(self, x):
        return np.full(len(x), 0.5)

    def update(self, x, success: bool) -> None:
        self.updates.append((list(x), success))


def test_update_self_confidence_learns_the_label_and_skips_a_take_over() -> None:
    kappa = _Kappa()
    _, store, _, _, bb = _observe(MotionOutcome(False, FailureStage.GRASP, "slipped", 4.0), on_table=False)
    bb.set(Keys.ACTION_EMBEDDINGS, {"Put salt on table": np.array([1.0, 0.0])})
    node = UpdateSelfConfidence("learn", lambda: kappa)
    node.setup()
    node.tick_once()
    assert kappa.updates == [([1.0, 0.0], False)]
    bb.set(Keys.OUTCOME, None)
    node.tick_once()
    assert len(kappa.updates) == 1 and "human took over" in node.feedback_message
