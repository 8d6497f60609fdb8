"""A small base class: blackboard access with declared READ/WRITE keys under stage namespaces."""

from __future__ import annotations

from typing import Any

import py_trees
from py_trees.common import Access

from scone_bt.behaviours.context import EpisodeContext

__all__ = ["StageBehaviour", "Keys"]


class Keys:
    """Blackboard keys, one namespace per stage of the data flow."""

    FRAME = "/perception/frame"
    # Every camera's frame of this tick, by camera name (the execution context measures sizes in them).
    FRAMES = "/perception/frames"
    DETECTIONS = "/perception/detections"
    # What stands on the table, as the table camera sees it: tuple[Detection, ...] (position = top-face centre).
    TABLE_DETECTIONS = "/perception/table_detections"
    AFFORDANCES = "/affordances/list"
    INSTRUCTION = "/relevance/instruction"
    RANKED = "/relevance/ranked"
    ACTION_EMBEDDINGS = "/relevance/action_embeddings"
    # The robot's own place in the recipe: a StepView (scone_bt.relevance.tracker).
    STEP = "/relevance/step"
    # Answers to ASK-CLARIFY: dict[step index, tuple[item, ...]] (what the human said the step wants).
    CLARIFIED = "/relevance/clarified"
    CONFIDENCES = "/gate/confidences"
    DECISION = "/gate/decision"
    # The Affordance the decision acts on or asks about (None when idle or clarifying).
    TARGET = "/gate/target"
    # ExecutionContext per ranked action text, as perceived this tick (what a grounded κ̂ reads).
    CONTEXTS = "/gate/contexts"
    # The target's ExecutionContext (stored with its outcome), or None.
    TARGET_CONTEXT = "/gate/target_context"
    # A PlannedPick for the decided target (plan before commit): PickAndPlace executes it; None once taken.
    PLANNED = "/gate/planned"
    # An Infeasible found by this decision's planning (a scene the robot had not planned in), else None.
    PLAN_VERDICT = "/gate/plan_verdict"
    MOTION_OUTCOME = "/motion/outcome"
    MOTION_TASK = "/motion/task"
    MOTION_COMPUTING = "/motion/computing"
    OUTCOME = "/experience/last_outcome"


class StageBehaviour(py_trees.behaviour.Behaviour):
    """A behaviour declaring the blackboard keys it reads and writes.

    Subclasses take their collaborators in the constructor (fakes in tests) and say in `from_context` which
    ones of the episode's they need; the tree builder calls `from_context` with the tree file's args.
    """

    READS: tuple[str, ...] = ()
    WRITES: tuple[str, ...] = ()

    def __init__(self, name: str) -> None:
        super().__init__(name=name)
        self.bb = self.attach_blackboard_client(name=name)
        for key in self.READS:
            self.bb.register_key(key=key, access=Access.READ)
        for key in self.WRITES:
            self.bb.register_key(key=key, access=Access.WRITE)

    @classmethod
    def from_context(cls, name: str, context: EpisodeContext) -> StageBehaviour:
        """This behaviour wired from the episode (subclasses with collaborators or args override it)."""
        return cls(name)

    def read(self, key: str, default: Any = None) -> Any:
        try:
            return self.bb.get(key)
        except KeyError:
            return default

    def write(self, key: str, value: Any) -> None:
        self.bb.set(key, value, overwrite=True)
