"""RecipeDone: the condition that ends the episode."""

from __future__ import annotations

import py_trees

from scone_bt.behaviours.base import StageBehaviour
from scone_bt.behaviours.context import EpisodeContext
from scone_bt.behaviours.ports import HumanChannel

__all__ = ["RecipeDone"]


class RecipeDone(StageBehaviour):
    """SUCCESS once the human has completed every step of the recipe, else FAILURE (a guard for the tree)."""

    def __init__(self, name: str, human: HumanChannel, steps_total: int) -> None:
        super().__init__(name)
        self.human = human
        self.steps_total = steps_total

    @classmethod
    def from_context(cls, name: str, context: EpisodeContext) -> RecipeDone:
        return cls(name, context.human, len(context.recipe.steps))

    def update(self) -> py_trees.common.Status:
        self.feedback_message = f"{self.human.steps_completed()}/{self.steps_total} steps done"
        return py_trees.common.Status.SUCCESS if self.human.done else py_trees.common.Status.FAILURE
