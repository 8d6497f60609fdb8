"""Perceive: one capture per camera → tracked detections of the shelf and of the table."""

from __future__ import annotations

import py_trees

from scone_bt.behaviours.base import Keys, StageBehaviour
from scone_bt.behaviours.context import EpisodeContext
from scone_bt.robot.interface import Robot

__all__ = ["Perceive"]


class Perceive(StageBehaviour):
    """Writes the first shelf camera's frame, every tracked detection, and what stands on the table.

    ``Keys.TABLE_DETECTIONS`` comes from the table camera alone (empty if the kitchen has none or it is covered):
    the robot's only knowledge of table obstacles and free placing area.
    """

    WRITES = (Keys.FRAME, Keys.FRAMES, Keys.DETECTIONS, Keys.TABLE_DETECTIONS)

    def __init__(self, name: str, robot: Robot) -> None:
        super().__init__(name)
        self.robot = robot

    @classmethod
    def from_context(cls, name: str, context: EpisodeContext) -> Perceive:
        return cls(name, context.robot)

    def update(self) -> py_trees.common.Status:
        seen = self.robot.perceive()
        self.write(Keys.FRAME, seen.frame)
        self.write(Keys.FRAMES, dict(seen.frames))
        self.write(Keys.DETECTIONS, list(seen.detections))
        self.write(Keys.TABLE_DETECTIONS, seen.table_detections)
        on_table = len(seen.table_detections)
        self.feedback_message = f"{len(seen.detections)} objects detected, {on_table} of them on the table"
        return py_trees.common.Status.SUCCESS
