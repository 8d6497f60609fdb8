"""PickAndPlace: an OMPL-planned, ruckig-timed pick-and-place; planning runs in a worker thread."""

from __future__ import annotations

import py_trees

from scone_bt.behaviours.base import Keys, StageBehaviour
from scone_bt.config import ObjectSpec
from scone_bt.motion.types import FailureStage, MotionOutcome
from scone_bt.perception.types import Detection

__all__ = ["PickAndPlace"]


class PickAndPlace(StageBehaviour):
    READS = (Keys.DECISION, Keys.AFFORDANCES, Keys.DETECTIONS)
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
        obstacles = [(d, catalogue.get(d.name)) for d in seen] + self._table_objects(target.object_name, seen)
        self.object_name = target.object_name
        self.task = self.system.pick_and_place(
            target.detection,
            catalogue.get(target.object_name),
            obstacles,
            rng_seed=s.options.seed + s.stats.attempted,
        )
        s.stats.attempted += 1
        s.human.robot_busy(True)
        s.human.decide_takeover(self.object_name)
        s.emit("act", action=decision.action, object=self.object_name, confidence=decision.confidence)
        self.task.start()
        self.write(Keys.MOTION_TASK, self.task)
        self.write(Keys.MOTION_OUTCOME, None)

    def _table_objects(self, target: str, seen: list[Detection]) -> list[tuple[Detection, ObjectSpec]]:
        """Objects standing on the table, as obstacles.

        The shelf camera does not see the table. Whoever puts something there (the robot or the human) puts it
        on one of the table's marked spots, and the table's occupancy is shared with the robot: that is what
        this reads (in a real kitchen: a second camera or the human's tablet).
        """
        k = self.services.kitchen
        seen_names = {d.name for d in seen}
        out = []
        for name in k.objects:
            if name == target or name in seen_names or not k.is_on_table(name):
                continue
            st = k.object_state(name)
            spec = k.specs[name]
            x, y, z = st.position
            yaw = float(k.bc.getEulerFromQuaternion(st.orientation)[2])
            out.append((Detection(name, -1, (x, y, z + spec.height / 2), yaw, 1.0, (0, 0, 0, 0)), spec))
        return out

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
