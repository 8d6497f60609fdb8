"""ObserveOutcome with fakes: the label comes from the table, and the outcome is stored before it is reported."""

from __future__ import annotations

from types import SimpleNamespace

import py_trees
import pytest

from scone_bt.affordances.types import Affordance, action_text
from scone_bt.behaviours import BehaviourOptions, Keys, ObserveOutcome
from scone_bt.behaviours.services import EpisodeStats
from scone_bt.gate.types import Decision, DecisionKind
from scone_bt.motion.types import FailureStage, MotionOutcome
from scone_bt.perception.types import Detection


class _Services:
    def __init__(self, on_table: bool) -> None:
        self.log: list[str] = []
        self.kitchen = SimpleNamespace(is_on_table=lambda name: on_table, sim_time=3.0)
        self.options = BehaviourOptions().resolve()
        self.context = {"robot": "panda"}
        self.robot_id = "r1"
        self.robot_config = SimpleNamespace(name="panda")
        self.stats = EpisodeStats()
        self.stored = []

    def store(self):
        services = self

        class _Store:
            def append(self, outcome) -> None:
                services.log.append("stored")
                services.stored.append(outcome)

        return _Store()

    def printer(self, line: str) -> None:
        self.log.append("printed")

    def emit(self, kind: str, **data) -> None:
        self.log.append(f"emitted {kind}")


@pytest.fixture(autouse=True)
def _clean_blackboard():
    py_trees.blackboard.Blackboard.clear()
    yield
    py_trees.blackboard.Blackboard.clear()


def _observe(services, motion: MotionOutcome):
    w = py_trees.blackboard.Client(name="test")
    for key in (Keys.DECISION, Keys.AFFORDANCES, Keys.MOTION_OUTCOME):
        w.register_key(key=key, access=py_trees.common.Access.WRITE)
    text = action_text("salt")
    w.set(Keys.DECISION, Decision(DecisionKind.ACT, text, 0.6, 0.9, "confident"))
    w.set(
        Keys.AFFORDANCES,
        [Affordance("salt", text, Detection("salt", 1, (0.5, 0.3, 0.1), 0.0, 1.0, (0, 0, 1, 1)))],
    )
    w.set(Keys.MOTION_OUTCOME, motion)
    b = ObserveOutcome("observe", services)
    b.setup()
    b.tick_once()
    return b


def test_success_is_stored_before_it_is_printed() -> None:
    s = _Services(on_table=True)
    _observe(s, MotionOutcome(True, None, "placed", 9.0))
    assert s.log == ["stored", "printed", "emitted outcome"]
    assert s.stored[0].success and s.stats.successes == 1


def test_a_motion_success_that_left_the_object_off_the_table_is_a_failure() -> None:
    s = _Services(on_table=False)
    _observe(s, MotionOutcome(True, None, "placed", 9.0))
    assert not s.stored[0].success and s.stats.failures == 1
    assert s.stats.failures_by_action == {"Put salt on table": 1}


def test_a_take_over_is_not_an_outcome() -> None:
    s = _Services(on_table=True)
    _observe(s, MotionOutcome(False, FailureStage.CANCELLED, "taken over", 1.0))
    assert s.stored == [] and s.stats.cancelled == 1
