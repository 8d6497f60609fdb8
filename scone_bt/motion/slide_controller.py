"""Executing a planned slide (`motion.slide.plan_slide`): the pick-and-place controller with its own segments.

The fingers close before the hand comes down; then the approach, a wait above the pack for the arm to catch up,
the press, the drag and the rise are tracked as the pick's segments are, the press, drag and rise watched as the
descent is (the hand may touch the pack it slides). The controller finishes without an outcome when the hand has
risen (`slid`): the task looks again and plans the pinch (`motion.system.PickAndPlaceTask`). A collision, a
timeout or a plan that does not exist fail it as they fail a pick.
"""

from __future__ import annotations

import numpy as np

from scone_bt.motion.execution import PickPlaceController
from scone_bt.motion.slide import SlideFailure, SlidePlan
from scone_bt.motion.types import MotionPhase

__all__ = ["SlideController"]

_AS_TRACKED = {
    MotionPhase.PRESS: MotionPhase.DESCEND,
    MotionPhase.DRAG: MotionPhase.DESCEND,
    MotionPhase.RAISE: MotionPhase.RETREAT,
}
"""The slide's motions are watched for collisions as the descent and the retreat they resemble."""


class SlideController(PickPlaceController):
    """The per-step state machine of one slide (arguments as `PickPlaceController`)."""

    slide: SlidePlan | None = None
    slid = False
    """True once the hand has risen off the pack with nothing failed."""

    def _start_plan(self, ready: object) -> None:
        if isinstance(ready, SlideFailure):
            self.reason = ready.reason
            self.fail(ready.stage, ready.message)
            return
        if not isinstance(ready, SlidePlan):
            super()._start_plan(ready)  # cancelled, or the planner raised: handled as for a pick
            return
        self.slide = ready
        seg = {s.phase: s for s in ready.segments}
        self.queue = [
            (MotionPhase.APPROACH, seg[MotionPhase.APPROACH]),
            (MotionPhase.ALIGN, None),
            (MotionPhase.PRESS, seg[MotionPhase.PRESS]),
            (MotionPhase.DRAG, seg[MotionPhase.DRAG]),
            (MotionPhase.RAISE, seg[MotionPhase.RAISE]),
        ]
        self.total_exec_s = sum(x.trajectory.duration for x in ready.segments)
        self.exec_start = self.arm.sim_time
        self.arm.couple_fingers()
        g = self.cfg.gripper
        self.arm.set_gripper_target(g.closed_position, g.max_force)  # a fingertip, not a grasp
        self._next()

    def _next(self) -> None:
        if not self.queue and self.stage is None and self.phase is MotionPhase.RAISE:
            self.slid = True
        super()._next()

    def _check(self, phase: MotionPhase, q_cmd: np.ndarray) -> bool:
        return super()._check(_AS_TRACKED.get(phase, phase), q_cmd)
