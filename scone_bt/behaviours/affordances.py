"""GenerateAffordances: detections on the shelf → "Put X on table" actions."""

from __future__ import annotations

import py_trees

from scone_bt.affordances import generate_affordances
from scone_bt.behaviours.base import Keys, StageBehaviour
from scone_bt.behaviours.context import EpisodeContext
from scone_bt.behaviours.ports import HumanChannel
from scone_bt.config import SceneSpec

__all__ = ["GenerateAffordances"]


class GenerateAffordances(StageBehaviour):
    """One action per detected product, "Put X on table" (affordances.generate), leaving out what the human is
    already fetching; always SUCCESS."""

    READS = (Keys.DETECTIONS,)
    WRITES = (Keys.AFFORDANCES,)

    def __init__(self, name: str, scene: SceneSpec, human: HumanChannel) -> None:
        super().__init__(name)
        self.scene = scene
        self.human = human

    @classmethod
    def from_context(cls, name: str, context: EpisodeContext) -> GenerateAffordances:
        return cls(name, context.scene, context.human)

    def update(self) -> py_trees.common.Status:
        affordances = generate_affordances(self.read(Keys.DETECTIONS, []), self.scene)
        # Objects the human is already fetching are not the robot's to take.
        affordances = [a for a in affordances if not self.human.is_fetching(a.object_name)]
        self.write(Keys.AFFORDANCES, affordances)
        self.feedback_message = f"{len(affordances)} affordances"
        return py_trees.common.Status.SUCCESS
