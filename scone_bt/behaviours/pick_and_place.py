"""PickAndPlace: an OMPL-planned, ruckig-timed pick-and-place; planning runs in a worker thread."""

from __future__ import annotations

import py_trees

from scone_bt.behaviours.base import Keys, StageBehaviour
from scone_bt.config import ObjectSpec
from scone_bt.motion.types import FailureStage, MotionOutcome
from scone_bt.perception.types import Detection

__all__ = ["PickAndPlace"]


class PickAndPlace(StageBehaviour):
    """Moves the decided object from the shelf to the table.

    Obstacles are what perception reports: the shelf detections, and what stands on the table from
    `Keys.TABLE_DETECTIONS` (sizes from the catalogue by name). While that key is absent (no table camera), the
    robot knows only what it placed itself (`MotionSystem.placed`); it never reads the simulator's true poses.
    """

    READS = (Keys.DECISION, Keys.AFFORDANCES, Keys.DETECTIONS, Keys.TABLE_DETECTIONS)
    WRITES = (Keys.MOTION_OUTCOME, Keys.MOTION_TASK, Keys.MOTION_COMPUTING)

    def setup(self, **kwargs: object) -> None:
        self.system = self.services.motion()
        self.write(Keys.MOTION_COMPUTING, False)

    def initialise(self) -> None:
        s = self.services
        decision = self.read(Keys.DECISION)
        by_text = {a.text: a for a in self.read(Keys.AFFORDANCES, [])}
        target = by_text[decision.action]
        catalogue = s.kitchen_config.catalogue
        seen = [d for d in self.read(Keys.DETECTIONS, []) if d.name != target.object_name]
        obstacles = [(d, catalogue.get(d.name)) for d in seen]
        self.object_name = target.object_name
        self.task = self.system.pick_and_place(
            target.detection,
            catalogue.get(target.object_name),
            obstacles,
            rng_seed=s.options.seed + s.stats.attempted,
            table_obstacles=self._table_obstacles(target.object_name),
        )
        s.stats.attempted += 1
        s.human.robot_busy(True)
        s.human.decide_takeover(self.object_name)
        s.emit("act", action=decision.action, object=self.object_name, confidence=decision.confidence)
        self.task.start()
        self.write(Keys.MOTION_TASK, self.task)
        self.write(Keys.MOTION_OUTCOME, None)

    def _table_obstacles(self, target: str) -> list[tuple[Detection, ObjectSpec]] | None:
        """What the table camera sees on the table, with catalogue sizes; None while the table is not observed."""
        seen: tuple[Detection, ...] | None = self.read(Keys.TABLE_DETECTIONS, None)
        if seen is None:
            return None
        catalogue = self.services.kitchen_config.catalogue
        return [(d, catalogue.get(d.name)) for d in seen if d.name != target]

    def update(self) -> py_trees.common.Status:
        s = self.services
        if not self.task.done() and s.human.wants_takeover(self.object_name):
            self.task.cancel()
            s.human.take_over(self.object_name)
            s.emit("intervention", action=self.read(Keys.DECISION).action, object=self.object_name)
        progress = self.task.progress()
        self.write(Keys.MOTION_COMPUTING, progress.phase == "planning")
        if not self.task.done():
            self.feedback_message = f"{progress.phase} {progress.fraction:.0%}"
            return py_trees.common.Status.RUNNING
        outcome = self.task.outcome()
        self.write(Keys.MOTION_OUTCOME, outcome)
        self.write(Keys.MOTION_COMPUTING, False)
        self.feedback_message = "done" if outcome.success else f"failed at {outcome.stage.value}"
        return py_trees.common.Status.SUCCESS

    def terminate(self, new_status: py_trees.common.Status) -> None:
        task = getattr(self, "task", None)
        if new_status is py_trees.common.Status.INVALID and task is not None and not task.done():
            task.cancel()
            self.write(
                Keys.MOTION_OUTCOME,
                MotionOutcome(False, FailureStage.CANCELLED, "interrupted by the tree", 0.0),
            )
        self.write(Keys.MOTION_COMPUTING, False)
        self.services.human.robot_busy(False)
