"""AskForHelp (ASK-HELP): the human fetches the object; the robot waits until it is on the table.
ClearGripper: after an attempt whose object stuck between the open fingers, ask the human to take it out and put
it on the table (else it rides along on every later attempt); the robot waits for that.
AskToClarify (ASK-CLARIFY): the robot asks which item the step means and remembers the answer for that step.
WaitForHuman: nothing relevant to do; wait a little."""

from __future__ import annotations

import py_trees

from scone_bt.affordances.types import action_text, object_of_action
from scone_bt.behaviours.base import Keys, StageBehaviour
from scone_bt.behaviours.context import EpisodeContext
from scone_bt.behaviours.ports import Clock, HumanChannel
from scone_bt.events import ClarificationAsked, EventSink, HelpRequested

__all__ = ["AskForHelp", "AskToClarify", "ClearGripper", "WaitForHuman", "WAIT_S"]


class _AskTheHuman(StageBehaviour):
    """A behaviour that asks the human something: the human channel, the event sink and the robot's clock."""

    def __init__(self, name: str, human: HumanChannel, events: EventSink, clock: Clock) -> None:
        super().__init__(name)
        self.human = human
        self.events = events
        self.clock = clock

    @classmethod
    def from_context(cls, name: str, context: EpisodeContext) -> _AskTheHuman:
        return cls(name, context.human, context.events, context.robot.now)


class AskForHelp(_AskTheHuman):
    """Asks the human to fetch the decided item (or the one the robot cannot see) and stays RUNNING until they
    have; nothing is learnt from an ask."""

    READS = (Keys.DECISION, Keys.TARGET)
    object_name: str  # set by initialise: the item asked for

    def initialise(self) -> None:
        target = self.read(Keys.TARGET)
        if target is None:  # an item the robot cannot see (the gate's "missing" rule): the decision names it
            decision = self.read(Keys.DECISION)
            self.object_name, text = str(decision.object_name), str(decision.action)
        else:
            self.object_name, text = target.object_name, target.text
        self.human.request_help(self.object_name)
        self.human.robot_busy(True)
        self.events(HelpRequested(self.clock(), text, self.object_name))

    def update(self) -> py_trees.common.Status:
        if self.human.help_pending(self.object_name):
            self.feedback_message = f"waiting for the human to fetch {self.object_name}"
            return py_trees.common.Status.RUNNING
        return py_trees.common.Status.SUCCESS

    def terminate(self, new_status: py_trees.common.Status) -> None:
        self.human.robot_busy(False)


class ClearGripper(_AskTheHuman):
    """Succeeds at once unless the attempt ended with an object still gripped (`MotionOutcome.still_held`, the
    arm's finger sensors): then it asks the human to take that object out and put it on the table, and waits
    until they have. Nothing is learnt from the ask: the attempt's own outcome is already labelled.

    No ask when the human is already fetching that object (they took over: the intervention clears the hand).
    A human who declines leaves the object where it is: the robot goes on, and says so in the event log (the
    decline), since it cannot free its own hand.
    """

    READS = (Keys.MOTION_OUTCOME,)

    def initialise(self) -> None:
        motion = self.read(Keys.MOTION_OUTCOME)
        self.object_name: str | None = None
        name = None if motion is None else motion.still_held
        if name is None or self.human.is_fetching(name):
            return
        self.object_name = name
        self.human.request_help(name)
        self.human.robot_busy(True)
        reason = f"the {name} is stuck in my gripper: please take it out and put it on the table"
        self.events(HelpRequested(self.clock(), action_text(name), name, reason))

    def update(self) -> py_trees.common.Status:
        if self.object_name is not None and self.human.help_pending(self.object_name):
            self.feedback_message = f"waiting for the human to take {self.object_name} out of the gripper"
            return py_trees.common.Status.RUNNING
        return py_trees.common.Status.SUCCESS

    def terminate(self, new_status: py_trees.common.Status) -> None:
        if self.object_name is not None:
            self.human.robot_busy(False)
            self.object_name = None


class AskToClarify(_AskTheHuman):
    """Asks which of the step's candidate items it means, writes the answer for the ranking (`Keys.CLARIFIED`,
    by step) and stays RUNNING for the human's answering time."""

    READS = (Keys.DECISION, Keys.STEP, Keys.CLARIFIED)
    WRITES = (Keys.CLARIFIED,)

    def initialise(self) -> None:
        decision = self.read(Keys.DECISION)
        view = self.read(Keys.STEP)
        items = tuple(object_of_action(c) for c in decision.candidates)
        self.answer = self.human.answer_clarification(items)
        now = self.clock()
        self.until = now + self.human.clarify_time_s
        clarified = dict(self.read(Keys.CLARIFIED, {}) or {})
        clarified[view.index] = self.answer
        self.write(Keys.CLARIFIED, clarified)
        self.events(ClarificationAsked(now, items, tuple(self.answer), view.index + 1))

    def update(self) -> py_trees.common.Status:
        if self.clock() < self.until:
            self.feedback_message = "waiting for the human's answer"
            return py_trees.common.Status.RUNNING
        return py_trees.common.Status.SUCCESS


WAIT_S = 1.0
"""How long `WaitForHuman` waits before the tree looks again, simulated seconds (a tree file's ``seconds:``)."""


class WaitForHuman(StageBehaviour):
    """Nothing relevant to do: wait a little (the human works on the step), then look again."""

    def __init__(self, name: str, clock: Clock, seconds: float = WAIT_S) -> None:
        super().__init__(name)
        self.clock = clock
        self.seconds = seconds

    @classmethod
    def from_context(cls, name: str, context: EpisodeContext, seconds: float = WAIT_S) -> WaitForHuman:
        return cls(name, context.robot.now, seconds)

    def initialise(self) -> None:
        self.until = self.clock() + self.seconds

    def update(self) -> py_trees.common.Status:
        if self.clock() < self.until:
            self.feedback_message = "nothing relevant for the robot; waiting"
            return py_trees.common.Status.RUNNING
        return py_trees.common.Status.SUCCESS
