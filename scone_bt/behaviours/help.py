"""AskForHelp (ASK-HELP): the human fetches the object; the robot waits until it is on the table.
AskToClarify (ASK-CLARIFY): the robot asks which item the step means and remembers the answer for that step."""

from __future__ import annotations

import py_trees

from scone_bt.affordances.types import object_of_action
from scone_bt.behaviours.base import Keys, StageBehaviour

__all__ = ["AskForHelp", "AskToClarify", "WaitForHuman"]


class AskForHelp(StageBehaviour):
    READS = (Keys.DECISION, Keys.AFFORDANCES)

    def initialise(self) -> None:
        decision = self.read(Keys.DECISION)
        by_text = {a.text: a for a in self.read(Keys.AFFORDANCES, [])}
        self.object_name = by_text[decision.action].object_name
        self.services.human.request_help(self.object_name)
        self.services.human.robot_busy(True)
        self.services.stats.help_requests += 1
        self.services.emit("help_request", action=decision.action, object=self.object_name)

    def update(self) -> py_trees.common.Status:
        if self.services.human.help_pending(self.object_name):
            self.feedback_message = f"waiting for the human to fetch {self.object_name}"
            return py_trees.common.Status.RUNNING
        return py_trees.common.Status.SUCCESS

    def terminate(self, new_status: py_trees.common.Status) -> None:
        self.services.human.robot_busy(False)


class AskToClarify(StageBehaviour):
    READS = (Keys.DECISION, Keys.STEP, Keys.CLARIFIED)
    WRITES = (Keys.CLARIFIED,)

    def initialise(self) -> None:
        decision = self.read(Keys.DECISION)
        view = self.read(Keys.STEP)
        human = self.services.human
        items = tuple(object_of_action(c) for c in decision.candidates)
        self.answer = human.answer_clarification(items)
        self.until = self.services.kitchen.sim_time + human.options.clarify_time_s
        clarified = dict(self.read(Keys.CLARIFIED, {}) or {})
        clarified[view.index] = self.answer
        self.write(Keys.CLARIFIED, clarified)
        self.services.stats.clarifications += 1
        self.services.emit(
            "clarification", candidates=list(items), answer=list(self.answer), step=view.index + 1
        )
        said = ", ".join(self.answer) or "none of those"
        self.services.printer(f"    ? asked which of {', '.join(items)}: the human says {said}")

    def update(self) -> py_trees.common.Status:
        if self.services.kitchen.sim_time < self.until:
            self.feedback_message = "waiting for the human's answer"
            return py_trees.common.Status.RUNNING
        return py_trees.common.Status.SUCCESS


class WaitForHuman(StageBehaviour):
    """Nothing relevant to do: wait a little (the human works on the step), then look again."""

    def __init__(self, name: str, services: object, seconds: float = 1.0) -> None:
        super().__init__(name, services)  # type: ignore[arg-type]
        self.seconds = seconds

    def initialise(self) -> None:
        self.until = self.services.kitchen.sim_time + self.seconds

    def update(self) -> py_trees.common.Status:
        if self.services.kitchen.sim_time < self.until:
            self.feedback_message = "nothing relevant for the robot; waiting"
            return py_trees.common.Status.RUNNING
        return py_trees.common.Status.SUCCESS
