"""PickAndPlace: the robot's pick-and-place (planning runs in the background), polled each tick."""

from __future__ import annotations

import py_trees

from scone_bt.behaviours.base import Keys, StageBehaviour
from scone_bt.behaviours.context import EpisodeContext
from scone_bt.behaviours.ports import HumanChannel, PlannerSeeds
from scone_bt.events import ActStarted, EventSink, TakeOver
from scone_bt.motion.types import FailureStage, MotionOutcome, MotionPhase
from scone_bt.perception.types import Detection
from scone_bt.robot.interface import MotionHandle, PickRequest, Robot, obstacles_except

__all__ = ["PickAndPlace"]


class PickAndPlace(StageBehaviour):
    """Moves the decided object from the shelf to the table.

    Obstacles are what perception reports: the shelf detections, and what stands on the table from
    `Keys.TABLE_DETECTIONS`. While that key is absent (no table camera), the robot knows only what it placed
    itself; it never reads the simulator's true poses. Each tick it asks the human whether they take over; if so
    the motion is cancelled (`TakeOver`), and `ObserveOutcome` labels nothing.
    """

    READS = (Keys.DECISION, Keys.TARGET, Keys.DETECTIONS, Keys.TABLE_DETECTIONS)
    WRITES = (Keys.MOTION_OUTCOME, Keys.MOTION_TASK, Keys.MOTION_COMPUTING)

    def __init__(
        self, name: str, robot: Robot, human: HumanChannel, events: EventSink, seeds: PlannerSeeds
    ) -> None:
        super().__init__(name)
        self.robot = robot
        self.human = human
        self.events = events
        self.seeds = seeds
        self.task: MotionHandle | None = None

    @classmethod
    def from_context(cls, name: str, context: EpisodeContext) -> PickAndPlace:
        return cls(name, context.robot, context.human, context.events, context.seeds)

    def setup(self, **kwargs: object) -> None:
        self.write(Keys.MOTION_COMPUTING, False)

    def initialise(self) -> None:
        decision = self.read(Keys.DECISION)
        target = self.read(Keys.TARGET)
        self.object_name = target.object_name
        self.action = target.text
        table: tuple[Detection, ...] | None = self.read(Keys.TABLE_DETECTIONS, None)
        request = PickRequest(
            target=target.detection,
            obstacles=obstacles_except(self.read(Keys.DETECTIONS, []), self.object_name),
            table=None if table is None else obstacles_except(table, self.object_name),
            rng_seed=self.seeds.next_seed(),
        )
        self.human.robot_busy(True)
        self.human.decide_takeover(self.object_name)
        self.events(ActStarted(self.robot.now(), self.action, self.object_name, decision.confidence))
        self.task = self.robot.start_pick_and_place(request)
        self.write(Keys.MOTION_TASK, self.task)
        self.write(Keys.MOTION_OUTCOME, None)

    def update(self) -> py_trees.common.Status:
        task = self.task
        assert task is not None  # initialise ran
        if not task.done() and self.human.wants_takeover(self.object_name):
            task.cancel()
            self.human.take_over(self.object_name)
            self.events(TakeOver(self.robot.now(), self.action, self.object_name))
        progress = task.progress()
        # While the planner computes, the episode holds simulated time still (a typed phase, not a string).
        self.write(Keys.MOTION_COMPUTING, progress.is_planning)
        if not task.done():
            self.feedback_message = f"{MotionPhase(progress.phase).value} {progress.fraction:.0%}"
            return py_trees.common.Status.RUNNING
        outcome = task.outcome()
        self.write(Keys.MOTION_OUTCOME, outcome)
        self.write(Keys.MOTION_COMPUTING, False)
        self.feedback_message = "done" if outcome.success else f"failed at {outcome.stage.value}"
        return py_trees.common.Status.SUCCESS

    def terminate(self, new_status: py_trees.common.Status) -> None:
        task = self.task
        if new_status is py_trees.common.Status.INVALID and task is not None and not task.done():
            task.cancel()
            self.write(
                Keys.MOTION_OUTCOME,
                MotionOutcome(False, FailureStage.CANCELLED, "interrupted by the tree", 0.0),
            )
        self.write(Keys.MOTION_COMPUTING, False)
        self.human.robot_busy(False)
