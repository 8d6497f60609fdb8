"""PickAndPlace with a fake robot: obstacles come from perception, seeds per attempt, take-over cancellation,
INVALID termination, and the planning phase that freezes simulated time."""

from __future__ import annotations

import py_trees
import pytest

from scone_bt.behaviours import Keys, PickAndPlace
from scone_bt.events import ActStarted, EventLog, TakeOver
from scone_bt.gate.types import Decision, DecisionKind
from scone_bt.motion.types import FailureStage
from tests.behaviours.fakes import FakeHuman, FakeRobot, affordance, blackboard, det

Status = py_trees.common.Status


class _Seeds:
    """Planner seeds 4, 5, 6, ... (the real ones come from the planners' SeedSequence stream)."""

    def __init__(self) -> None:
        self.next = 4

    def next_seed(self) -> int:
        self.next += 1
        return self.next - 1


@pytest.fixture
def setup():
    robot, human, events = FakeRobot(planning_ticks=1), FakeHuman(), EventLog()
    node = PickAndPlace("PickAndPlace", robot, human, events, _Seeds())
    node.setup()
    target = affordance("salt")
    bb = blackboard(
        DECISION=Decision(DecisionKind.ACT, target.text, 0.6, 0.9, "confident", "now", (), "salt"),
        TARGET=target,
        DETECTIONS=[target.detection, det("honey", (0.5, 0.4, 0.18))],
    )
    return node, robot, human, events, bb


def test_without_a_table_camera_the_robot_knows_only_its_own_placements(setup) -> None:
    node, robot, human, events, _ = setup
    node.tick_once()
    (request,) = robot.requests
    assert request.table is None  # the robot backend then uses what it placed itself
    assert request.target.name == "salt" and [d.name for d in request.obstacles] == ["honey"]
    assert human.busy == [True]
    assert events.events == [ActStarted(0.0, "Put salt on table", "salt", 0.9)]


def test_table_obstacles_come_from_the_table_detections_without_the_target(setup) -> None:
    node, robot, _, _, bb = setup
    bb.set(Keys.TABLE_DETECTIONS, (det("oil", (0.4, -0.4, 0.22)), det("salt", (0.5, -0.3, 0.1))))
    node.tick_once()
    assert [d.name for d in robot.requests[0].table] == ["oil"]


def test_each_attempt_gets_the_next_planner_seed(setup) -> None:
    node, robot, _, _, _ = setup
    for _ in range(3):
        node.tick_once()
        robot.handles[-1].finish(True)
        node.tick_once()
        assert node.status is Status.SUCCESS
    assert [r.rng_seed for r in robot.requests] == [4, 5, 6]


def test_simulated_time_freezes_exactly_while_planning(setup) -> None:
    node, robot, _, _, bb = setup
    node.tick_once()  # planning (the fake plans for one poll)
    assert node.status is Status.RUNNING and bb.get(Keys.MOTION_COMPUTING) is True
    node.tick_once()
    assert node.status is Status.RUNNING and bb.get(Keys.MOTION_COMPUTING) is False
    robot.handles[0].finish(True)
    node.tick_once()
    assert node.status is Status.SUCCESS and bb.get(Keys.MOTION_OUTCOME).success


def test_a_take_over_cancels_the_motion_and_hands_the_object_to_the_human(setup) -> None:
    node, robot, human, events, bb = setup
    node.tick_once()
    human.takeover = "salt"
    robot.time = 1.5
    node.tick_once()
    handle = robot.handles[0]
    assert handle.cancelled and human.taken == ["salt"]
    assert events.events[-1] == TakeOver(1.5, "Put salt on table", "salt")
    assert node.status is Status.SUCCESS and bb.get(Keys.MOTION_OUTCOME).stage is FailureStage.CANCELLED
    assert events.stats.takeovers == 1 and human.busy[-1] is False


def test_an_interrupted_action_is_cancelled_on_invalid(setup) -> None:
    node, robot, human, _, bb = setup
    node.tick_once()
    assert node.status is Status.RUNNING
    node.stop(Status.INVALID)  # a higher-priority branch preempted the action
    assert robot.handles[0].cancelled
    assert bb.get(Keys.MOTION_OUTCOME).stage is FailureStage.CANCELLED
    assert bb.get(Keys.MOTION_COMPUTING) is False and human.busy == [True, False]


def test_trust_aware_states_its_confidence_before_an_act_the_person_over_trusts() -> None:
    from scone_bt.events import ConfidenceStated, TrustEstimated
    from scone_bt.trust.estimate import OnlineTrust
    from scone_bt.trust.transfer import TransferModel, load_fitted

    trust = OnlineTrust(TransferModel(load_fitted()))
    for kappa, warned in ((0.3, True), (0.9, False)):
        robot, human, events = FakeRobot(planning_ticks=1), FakeHuman(), EventLog()
        node = PickAndPlace("PickAndPlace", robot, human, events, _Seeds(), trust)
        node.setup()
        target = affordance("salt")
        blackboard(
            DECISION=Decision(DecisionKind.ACT, target.text, 0.6, kappa, "confident", "now", (), "salt"),
            TARGET=target,
            DETECTIONS=[target.detection],
        )
        node.tick_once()
        kinds = [type(e) for e in events.events]
        estimate = events.events[0]
        assert isinstance(estimate, TrustEstimated) and estimate.confidence == kappa and estimate.trust > 0.6
        if warned:  # a person's ~0.7 trust against κ̂ 0.3: over-trust, said in words before the act starts
            assert kinds == [TrustEstimated, ConfidenceStated, ActStarted]
            assert events.events[1].text.startswith("I am not sure about this one: I may drop the salt")
        else:
            assert kinds == [TrustEstimated, ActStarted]


class _Person(FakeHuman):
    """A human channel with a person on it (the tablet): the robot announces each attempt first."""

    announces_attempts = True


def _announcing(window_s: float):
    robot, human, events = FakeRobot(), _Person(), EventLog()
    node = PickAndPlace("PickAndPlace", robot, human, events, _Seeds(), window_s=window_s)
    node.setup()
    target = affordance("salt")
    bb = blackboard(
        DECISION=Decision(DecisionKind.ACT, target.text, 0.6, 0.9, "confident", "now", (), "salt"),
        TARGET=target,
        DETECTIONS=[target.detection],
    )
    return node, robot, human, events, bb


def test_the_robot_announces_and_stays_still_for_the_take_over_window() -> None:
    node, robot, _, events, _ = _announcing(2.0)
    node.tick_once()
    assert events.events == [ActStarted(0.0, "Put salt on table", "salt", 0.9, window_s=2.0)]
    for t in (0.5, 1.0, 1.9):
        robot.time = t
        node.tick_once()
        assert node.status is Status.RUNNING and robot.requests == []  # nothing moves in the window
    robot.time = 2.0
    node.tick_once()
    assert len(robot.requests) == 1  # then it moves


def test_a_take_over_in_the_window_cancels_before_anything_moved() -> None:
    node, robot, human, events, bb = _announcing(2.0)
    node.tick_once()
    robot.time, human.takeover = 1.2, "salt"
    node.tick_once()
    assert node.status is Status.SUCCESS and robot.requests == [] and human.taken == ["salt"]
    assert events.events[-1] == TakeOver(1.2, "Put salt on table", "salt")
    assert bb.get(Keys.MOTION_OUTCOME).stage is FailureStage.CANCELLED


def test_a_simulated_human_gets_no_window() -> None:
    robot, human, events = FakeRobot(), FakeHuman(), EventLog()
    node = PickAndPlace("PickAndPlace", robot, human, events, _Seeds(), window_s=2.0)
    assert node.window_s == 0.0
