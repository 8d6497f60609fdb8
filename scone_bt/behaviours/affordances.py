"""GenerateAffordances: detections on the shelf → "Put X on table" actions."""

from __future__ import annotations

import py_trees

from scone_bt.affordances import generate_affordances
from scone_bt.behaviours.base import Keys, StageBehaviour

__all__ = ["GenerateAffordances"]


class GenerateAffordances(StageBehaviour):
    READS = (Keys.DETECTIONS,)
    WRITES = (Keys.AFFORDANCES,)

    def update(self) -> py_trees.common.Status:
        affordances = generate_affordances(self.read(Keys.DETECTIONS, []), self.services.kitchen_config.scene)
        # Objects the human is already fetching are not the robot's to take.
        affordances = [a for a in affordances if not self.services.human.is_fetching(a.object_name)]
        self.write(Keys.AFFORDANCES, affordances)
        self.feedback_message = f"{len(affordances)} affordances"
        return py_trees.common.Status.SUCCESS
