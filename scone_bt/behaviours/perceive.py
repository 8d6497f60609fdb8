"""Perceive: one capture per camera → tracked detections of the shelf and of the table; a longer look (averaged
frames) when the gate asked to look again for an item it sees nowhere."""

from __future__ import annotations

import py_trees

from scone_bt.behaviours.base import Keys, StageBehaviour
from scone_bt.behaviours.context import EpisodeContext
from scone_bt.perception.exposure import LOOK_AGAIN_EXPOSURES
from scone_bt.robot.interface import Robot

__all__ = ["Perceive"]


class Perceive(StageBehaviour):
    """Writes the first shelf camera's frame, every tracked detection, and what stands on the table.

    ``Keys.TABLE_DETECTIONS`` comes from the table camera alone (empty if the kitchen has none or it is covered):
    the robot's only knowledge of table obstacles and free placing area.

    When the gate last wrote items to look for again (`Keys.LOOK_AGAIN`: the step needs them and no camera saw
    them), this look averages `LOOK_AGAIN_EXPOSURES` frames per camera (perception.exposure): a marker lost in
    one frame's noise is found in the mean, before the robot asks for the item.
    """

    READS = (Keys.LOOK_AGAIN,)
    WRITES = (Keys.FRAME, Keys.FRAMES, Keys.DETECTIONS, Keys.TABLE_DETECTIONS)

    def __init__(self, name: str, robot: Robot) -> None:
        super().__init__(name)
        self.robot = robot

    @classmethod
    def from_context(cls, name: str, context: EpisodeContext) -> Perceive:
        return cls(name, context.robot)

    def update(self) -> py_trees.common.Status:
        again = self.read(Keys.LOOK_AGAIN, ())
        seen = self.robot.perceive(LOOK_AGAIN_EXPOSURES) if again else self.robot.perceive()
        self.write(Keys.FRAME, seen.frame)
        self.write(Keys.FRAMES, dict(seen.frames))
        self.write(Keys.DETECTIONS, list(seen.detections))
        self.write(Keys.TABLE_DETECTIONS, seen.table_detections)
        on_table = len(seen.table_detections)
        self.feedback_message = f"{len(seen.detections)} objects detected, {on_table} of them on the table"
        if again:
            self.feedback_message += f" (looked again for {', '.join(again)})"
        return py_trees.common.Status.SUCCESS
