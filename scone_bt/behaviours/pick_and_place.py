"""PickAndPlace: the robot's pick-and-place (planning runs in the background), polled each tick."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import py_trees

from scone_bt.behaviours.base import Keys, StageBehaviour
from scone_bt.behaviours.context import EpisodeContext
from scone_bt.behaviours.ports import HumanChannel, PlannerSeeds
from scone_bt.events import ActStarted, ConfidenceStated, EventSink, TakeOver
from scone_bt.motion.types import FailureStage, MotionOutcome, MotionPhase
from scone_bt.perception.types import Detection
from scone_bt.robot.interface import MotionHandle, PickRequest, PlannedPick, Robot, obstacles_except
from scone_bt.trust.estimate import confidence_in_words

__all__ = ["PickAndPlace", "pick_request", "scene_key"]

_NEAR_M = 0.35  # shelf detections within this of the target are the scene a grasp plan depends on
_GRID_M = 0.02  # positions are compared on this grid: a product that moved less did not change the scene


def pick_request(
    target: Detection, detections: Sequence[Detection], table: Sequence[Detection] | None, seed: int
) -> PickRequest:
    """What the robot asks its arm to do, from what it perceives: the target, the rest of the shelf and the table."""
    name = target.name
    return PickRequest(
        target=target,
        obstacles=obstacles_except(detections, name),
        table=None if table is None else obstacles_except(table, name),
        rng_seed=seed,
    )


def _stage(outcome: MotionOutcome) -> str:
    """Where a motion failed (a failed outcome names its stage)."""
    return "?" if outcome.stage is None else outcome.stage.value


def scene_key(request: PickRequest) -> tuple[object, ...]:
    """The scene a pick-and-place plan depends on, on a 2 cm grid: the target and what stands near it, and the
    table. Two requests with the same key plan in an unchanged scene (an infeasible one is not planned again)."""

    def cell(d: Detection) -> tuple[str, tuple[int, ...]]:
        return d.name, tuple(int(round(v / _GRID_M)) for v in d.position)

    t = request.target.position
    near = frozenset(
        cell(d)
        for d in request.obstacles
        if ((d.position[0] - t[0]) ** 2 + (d.position[1] - t[1]) ** 2) ** 0.5 <= _NEAR_M
    )
    table = None if request.table is None else frozenset(cell(d) for d in request.table)
    return cell(request.target), near, table


class PickAndPlace(StageBehaviour):
    """Moves the decided object from the shelf to the table.

    Obstacles are what perception reports: the shelf detections, and what stands on the table from
    `Keys.TABLE_DETECTIONS`. While that key is absent (no table camera), the robot knows only what it placed
    itself; it never reads the simulator's true poses. Each tick it asks the human whether they take over; if so
    the motion is cancelled (`TakeOver`), and `ObserveOutcome` labels nothing. With `trust` (tree parameter
    ``trust_aware``) it first emits the person's estimated trust in the act (`TrustEstimated`) and, when they likely
    over-trust it, says its confidence in words (`ConfidenceStated`).

    With a person on the human channel (``announces_attempts``, the tablet) the robot first announces the attempt
    and stays still for ``window_s`` simulated seconds (the tree's ``takeover_window_s``), so that the person has
    time to take over before anything moves; `ActStarted` records the window.
    """

    READS = (Keys.DECISION, Keys.TARGET, Keys.DETECTIONS, Keys.TABLE_DETECTIONS, Keys.PLANNED)
    WRITES = (Keys.MOTION_OUTCOME, Keys.MOTION_TASK, Keys.MOTION_COMPUTING, Keys.PLANNED)

    def __init__(
        self,
        name: str,
        robot: Robot,
        human: HumanChannel,
        events: EventSink,
        seeds: PlannerSeeds,
        trust: Any = None,
        window_s: float = 0.0,
    ) -> None:
        super().__init__(name)
        self.robot = robot
        self.human = human
        self.events = events
        self.seeds = seeds
        self.trust = trust
        # simulated humans decide at once (their take-over delay is the reaction): only a person gets a window
        self.window_s = window_s if getattr(human, "announces_attempts", False) else 0.0
        self.task: MotionHandle | None = None

    @classmethod
    def from_context(cls, name: str, context: EpisodeContext) -> PickAndPlace:
        window = context.options.takeover_window_s
        return cls(
            name,
            context.robot,
            context.human,
            context.events,
            context.seeds,
            context.trust,
            window_s=float(window or 0.0),
        )

    def _state_confidence(self, confidence: float) -> None:
        """trust_aware: the person's estimated trust in this act, and a spoken warning when they over-trust it."""
        now = self.robot.now()
        (estimate,) = self.trust.estimate(now, {self.action: (self.object_name, confidence)})
        self.events(estimate)
        if estimate.risk == "over":
            text = confidence_in_words(self.object_name, confidence)
            self.events(ConfidenceStated(now, self.action, self.object_name, text, round(confidence, 4)))

    def setup(self, **kwargs: object) -> None:
        self.write(Keys.MOTION_COMPUTING, False)

    def initialise(self) -> None:
        decision = self.read(Keys.DECISION)
        target = self.read(Keys.TARGET)
        self.object_name = target.object_name
        self.action = target.text
        # the gate planned before it committed (plan_pick_and_place)
        planned: PlannedPick | None = self.read(Keys.PLANNED)
        self.write(Keys.PLANNED, None)
        if self.trust is not None and math.isfinite(decision.confidence):
            self._state_confidence(decision.confidence)
        self.human.robot_busy(True)
        self.human.decide_takeover(self.object_name)
        now = self.robot.now()
        self.events(
            ActStarted(now, self.action, self.object_name, decision.confidence, window_s=self.window_s)
        )
        self.task = None
        self._planned = planned
        self._target = target
        self.move_at = now + self.window_s
        self.write(Keys.MOTION_OUTCOME, None)
        if self.window_s <= 0:
            self._move()

    def _move(self) -> None:
        """Start the motion: the plan the gate made, or a new one."""
        if self._planned is not None:
            self.task = self._planned.execute()
        else:
            table: Sequence[Detection] | None = self.read(Keys.TABLE_DETECTIONS, None)
            request = pick_request(
                self._target.detection, self.read(Keys.DETECTIONS, []), table, self.seeds.next_seed()
            )
            self.task = self.robot.start_pick_and_place(request)
        self._planned = None
        self.write(Keys.MOTION_TASK, self.task)

    def update(self) -> py_trees.common.Status:
        if self.task is None:  # announcing: the arm has not moved
            if self.human.wants_takeover(self.object_name):
                self.human.take_over(self.object_name)
                self.events(TakeOver(self.robot.now(), self.action, self.object_name))
                self.write(
                    Keys.MOTION_OUTCOME,
                    MotionOutcome(False, FailureStage.CANCELLED, "taken over before the robot moved", 0.0),
                )
                self.feedback_message = "taken over before moving"
                return py_trees.common.Status.SUCCESS
            if self.robot.now() < self.move_at:
                self.feedback_message = (
                    f"announcing {self.action}: {self.move_at - self.robot.now():.1f} s to take over"
                )
                return py_trees.common.Status.RUNNING
            self._move()
        task = self.task
        assert task is not None
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
        assert outcome is not None  # the task is done
        self.write(Keys.MOTION_OUTCOME, outcome)
        self.write(Keys.MOTION_COMPUTING, False)
        if outcome.aborted:
            self.feedback_message = f"set back: {outcome.probe_reason}"
        else:
            self.feedback_message = "done" if outcome.success else f"failed at {_stage(outcome)}"
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
