"""AskForHelp: the human fetches the object; the robot waits until it is on the table."""

from __future__ import annotations

import py_trees

from scone_bt.behaviours.base import Keys, StageBehaviour

__all__ = ["AskForHelp", "WaitForHuman"]


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
