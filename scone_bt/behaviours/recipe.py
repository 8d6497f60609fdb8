"""RecipeDone: the condition that ends the episode."""

from __future__ import annotations

import py_trees

from scone_bt.behaviours.base import StageBehaviour

__all__ = ["RecipeDone"]


class RecipeDone(StageBehaviour):
    def update(self) -> py_trees.common.Status:
        human = self.services.human
        self.feedback_message = f"{human.steps_completed()}/{len(human.recipe.steps)} steps done"
        return py_trees.common.Status.SUCCESS if human.done else py_trees.common.Status.FAILURE
