"""AskForHelp, WaitForHuman, RecipeDone, Perceive and GenerateAffordances with fakes (no simulator)."""

from __future__ import annotations

import py_trees

from scone_bt.behaviours import (
    AskForHelp,
    ClearGripper,
    GenerateAffordances,
    Keys,
    Perceive,
    RecipeDone,
    WaitForHuman,
)
from scone_bt.config import load_kitchen
from scone_bt.events import EventLog, HelpRequested
from scone_bt.motion.types import FailureStage, MotionOutcome
from tests.behaviours.fakes import FakeHuman, FakeRobot, affordance, blackboard, det

Status = py_trees.common.Status


def test_ask_for_help_waits_until_the_human_fetched_it() -> None:
    human, robot, events = FakeHuman(), FakeRobot(time=4.0), EventLog()
    bb = blackboard(TARGET=affordance("eggs"))
    node = AskForHelp("ask", human, events, robot.now)
    node.tick_once()
    assert node.status is Status.RUNNING and human.helped == ["eggs"] and human.busy == [True]
    assert (
        events.events == [HelpRequested(4.0, "Put eggs on table", "eggs")] and events.stats.help_requests == 1
    )
    human.pending.clear()  # the human put the eggs on the table
    node.tick_once()
    assert node.status is Status.SUCCESS and human.busy == [True, False]
    assert bb.get(Keys.TARGET).object_name == "eggs"


def test_clear_gripper_asks_the_human_to_take_out_what_stuck_between_the_fingers() -> None:
    human, robot, events = FakeHuman(), FakeRobot(time=7.0), EventLog()
    stuck = MotionOutcome(False, FailureStage.PLACE, "released, but it stuck", 9.0, still_held="bell pepper")
    blackboard(TARGET=affordance("bell pepper"), MOTION_OUTCOME=stuck)
    node = ClearGripper("clear", human, events, robot.now)
    node.tick_once()
    assert node.status is Status.RUNNING and human.helped == ["bell pepper"] and human.busy == [True]
    (event,) = events.events
    assert isinstance(event, HelpRequested) and event.object_name == "bell pepper"
    assert event.action == "Put bell pepper on table"
    assert event.reason.startswith("the bell pepper is stuck in my gripper")
    assert events.stats.help_requests == 1
    human.pending.clear()  # the human took it out
    node.tick_once()
    assert node.status is Status.SUCCESS and human.busy == [True, False]


def test_clear_gripper_names_what_stuck_not_what_was_targeted() -> None:
    human, robot, events = FakeHuman(), FakeRobot(time=7.0), EventLog()
    # The fingers closed on a neighbour, and it is the neighbour that stuck.
    stuck = MotionOutcome(False, FailureStage.PLACE, "stuck", 9.0, still_held="onion")
    blackboard(TARGET=affordance("bell pepper"), MOTION_OUTCOME=stuck)
    ClearGripper("clear", human, events, robot.now).tick_once()
    assert human.helped == ["onion"] and [e.object_name for e in events.events] == ["onion"]


def test_clear_gripper_does_not_ask_for_what_the_human_is_already_fetching() -> None:
    human, robot, events = FakeHuman(fetching={"bell pepper"}), FakeRobot(time=7.0), EventLog()
    # The human took over mid-attempt: their intervention fetch takes it out of the hand anyway.
    stuck = MotionOutcome(False, FailureStage.CANCELLED, "taken over", 3.0, still_held="bell pepper")
    blackboard(TARGET=affordance("bell pepper"), MOTION_OUTCOME=stuck)
    node = ClearGripper("clear", human, events, robot.now)
    node.tick_once()
    assert node.status is Status.SUCCESS and human.helped == [] and events.events == [] and human.busy == []


def test_clear_gripper_does_nothing_when_the_hand_is_empty() -> None:
    human, robot, events = FakeHuman(), FakeRobot(time=7.0), EventLog()
    blackboard(
        TARGET=affordance("bell pepper"),
        MOTION_OUTCOME=MotionOutcome(False, FailureStage.PLACE, "toppled", 9.0),
    )
    node = ClearGripper("clear", human, events, robot.now)
    node.tick_once()
    assert node.status is Status.SUCCESS and human.helped == [] and events.events == [] and human.busy == []


def test_wait_for_human_waits_on_the_robots_clock() -> None:
    robot = FakeRobot(time=10.0)
    node = WaitForHuman("wait", robot.now, seconds=1.0)
    node.tick_once()
    assert node.status is Status.RUNNING
    robot.time = 11.0
    node.tick_once()
    assert node.status is Status.SUCCESS


def test_recipe_done_asks_the_human() -> None:
    human = FakeHuman(step_index=2)
    node = RecipeDone("done?", human, 3)
    node.tick_once()
    assert node.status is Status.FAILURE and node.feedback_message == "2/3 steps done"
    human.done = True
    node.tick_once()
    assert node.status is Status.SUCCESS


def test_perceive_writes_what_the_robot_sees() -> None:
    robot = FakeRobot(shelf=[det("salt"), det("oil")], table=(det("oil", (0.4, -0.4, 0.2)),))
    bb = blackboard()
    Perceive("perceive", robot).tick_once()
    assert [d.name for d in bb.get(Keys.DETECTIONS)] == ["salt", "oil"]
    assert [d.name for d in bb.get(Keys.TABLE_DETECTIONS)] == ["oil"]


def test_perceive_looks_longer_only_when_the_gate_asked_to_look_again() -> None:
    from scone_bt.perception.exposure import LOOK_AGAIN_EXPOSURES

    robot = FakeRobot(shelf=[det("salt")])
    bb = blackboard()
    node = Perceive("perceive", robot)
    node.tick_once()  # nothing written yet by the gate: one frame
    bb.set(Keys.LOOK_AGAIN, ("spaghetti",))
    node.tick_once()
    assert "looked again for spaghetti" in node.feedback_message
    bb.set(Keys.LOOK_AGAIN, ())
    node.tick_once()
    assert robot.looks == [1, LOOK_AGAIN_EXPOSURES, 1] and LOOK_AGAIN_EXPOSURES > 1


def test_affordances_are_what_stands_on_the_shelf_and_the_human_is_not_fetching() -> None:
    scene = load_kitchen().scene
    slots = scene.shelf_slots()
    above = [(x, y, z + 0.1) for x, y, z in slots[:2]]
    on_shelf = [det("salt", above[0]), det("sugar", above[1]), det("far", (9.0, 9.0, 0.1))]
    bb = blackboard(DETECTIONS=on_shelf)
    GenerateAffordances("affordances", scene, FakeHuman(fetching={"sugar"})).tick_once()
    assert [a.text for a in bb.get(Keys.AFFORDANCES)] == ["Put salt on table"]
