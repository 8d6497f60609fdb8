"""Data that leaves the motion stage: typed plans, trajectories and pick-and-place outcomes."""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import Enum
from typing import Any

import numpy as np

from scone_bt.errors import SconeError

__all__ = [
    "MotionPhase",
    "FailureStage",
    "PlanFailureReason",
    "PlanStatus",
    "PlanResult",
    "TimedTrajectory",
    "MotionOutcome",
    "MotionProgress",
    "PLACED",
]

PLACED = "placed upright on the table"
"""A successful attempt's message; what follows it in parentheses are notes (another place spot was taken)."""


class MotionPhase(str, Enum):  # noqa: UP042 (compares equal to the phase strings callers used before)
    """What a pick-and-place is doing now; the values are the phase names shown in progress and logs."""

    IDLE = "idle"  # created, not started
    PLANNING = "planning"  # the worker computes; the arm holds still (a caller may pause simulated time)
    READY = "ready"  # the plan is ready; the arm still holds for the fixed thinking time
    APPROACH = "approach"
    ALIGN = "align"  # above the object, waiting for the arm to catch up with its command
    DESCEND = "descend"
    CLOSE = "close"
    LIFT = "lift"
    TRANSIT = "transit"
    LOWER = "lower"
    RELEASE = "release"
    RETREAT = "retreat"
    SETTLE = "settle"
    HOME = "home"
    NEW_SPOT = "new_spot"  # carrying: the place spot was taken; holding while the worker plans another
    PROBE = "probe"  # the heft test: lifting the grasped product a little (motion.probe)
    PROBE_HOLD = "probe_hold"  # holding it there while the fingers feel its load and slip
    SET_DOWN = "set_down"  # the probe said no: lowering it back where it stood
    PRESS = "press"  # sliding a flat pack: the closed fingertips pressing on its top (motion.slide)
    DRAG = "drag"  # pressing, moving it towards the robot
    RAISE = "raise"  # the fingertips rising off it; the cameras look again, then the pinch is planned
    RECOVER = "recover"  # after a failure: holding while the worker plans a way home
    RECOVER_HOME = "recover_home"
    DONE = "done"

    def __str__(self) -> str:
        return self.value

    def __format__(self, spec: str) -> str:
        return format(self.value, spec)


class FailureStage(str, Enum):  # noqa: UP042 (str() of members is relied upon elsewhere)
    """Where a pick-and-place failed. The values are stored in the experience database."""

    PERCEPTION = "perception"
    IK = "ik"
    PLANNING = "planning"
    GRASP = "grasp"  # the object slipped out while closing or lifting
    TRANSIT = "transit"  # dropped while carrying
    COLLISION = "collision"
    PLACE = "place"  # released but not resting upright on the table
    TIMEOUT = "timeout"
    CANCELLED = "cancelled"  # the human took over
    PROBE = "probe"  # set back where it stood after the heft test (motion.probe): an aborted attempt, not a failure


class PlanFailureReason(str, Enum):  # noqa: UP042
    """Which stage of planning a pick-and-place ran out of options (the fallbacks are tried in this order)."""

    NO_GRASP_IK = "no_grasp_ik"  # no grasp pose of the object is within the arm's reach
    GRASPS_BLOCKED = "grasps_blocked"  # every reachable grasp collides (with the named obstacles)
    NO_TABLE_SPACE = "no_table_space"  # no free spot on the table clears what stands there
    NO_PLACEMENT_IK = "no_placement_ik"  # no free spot is within reach with the object in the hand
    PLACEMENTS_BLOCKED = "placements_blocked"  # every reachable placement collides (with the named obstacles)
    NO_PATH = "no_path"  # OMPL found no collision-free path to any goal of the set within its time limit


class PlanStatus(str, Enum):  # noqa: UP042
    SUCCESS = "success"
    START_INVALID = "start_invalid"
    GOAL_INVALID = "goal_invalid"
    IK_FAILED = "ik_failed"
    TIMED_OUT = "timed_out"
    NO_SOLUTION = "no_solution"


@dataclass(frozen=True, eq=False)
class PlanResult:
    """Result of one joint-space planning query.

    Attributes:
        status: SUCCESS or why it failed.
        path: (N, dof) joint waypoints in radians when successful, else None.
        planning_time: Wall time spent, seconds.
        message: Human-readable detail.
        goal_index: Which goal of the goal set the path ends at (0 for a single goal).
    """

    status: PlanStatus
    path: np.ndarray | None
    planning_time: float
    message: str = ""
    goal_index: int = 0

    @property
    def success(self) -> bool:
        return self.status is PlanStatus.SUCCESS

    @property
    def waypoints(self) -> np.ndarray:
        """The path of a successful result (`path`, known to be there).

        Raises:
            SconeError: the query failed, so there is no path.
        """
        if self.path is None:
            raise SconeError(f"no path: the planning query failed ({self.status.value}: {self.message})")
        return self.path


@dataclass(frozen=True, eq=False)
class TimedTrajectory:
    """A jerk-limited trajectory sampled at the control rate.

    Attributes:
        times: (T,) seconds from the start.
        positions: (T, dof) radians.
        velocities: (T, dof) rad/s.
        accelerations: (T, dof) rad/s².
    """

    times: np.ndarray
    positions: np.ndarray
    velocities: np.ndarray
    accelerations: np.ndarray

    @property
    def duration(self) -> float:
        return float(self.times[-1]) if len(self.times) else 0.0


@dataclass(frozen=True, eq=False)
class MotionOutcome:
    """How one pick-and-place ended.

    Attributes:
        success: The object rests upright on the table.
        stage: None on success, else where it failed.
        message: Human-readable detail.
        duration: Simulated seconds from start to end.
        trajectories: Every timed segment that was executed (for plots and limit checks).
        ee_path: (N, 3) planned end-effector positions, metres (for the 3D trace).
        reason: For a planning or IK failure, which stage ran out of options; else None.
        still_held: The object the fingers still gripped when the attempt ended (it stuck between the open fingers
            and came back with the arm), by the arm's own finger sensors; None when the hand is empty.
        aborted: The heft test (motion.probe) set the product back where it stood: not a success, not a failure
            (``stage`` None); the person has to fetch it.
        probe: What the heft test felt (a motion.probe.ProbeReading), or None when there was none.
        probe_reason: Why it was set back, in the robot's words ("the jar slips in my fingers"); "" otherwise.
    """

    success: bool
    stage: FailureStage | None
    message: str
    duration: float
    trajectories: tuple[TimedTrajectory, ...] = ()
    ee_path: np.ndarray | None = field(default=None)
    reason: PlanFailureReason | None = None
    still_held: str | None = None
    aborted: bool = False
    probe: Any = None
    probe_reason: str = ""


@dataclass(frozen=True)
class MotionProgress:
    """What a running pick-and-place is doing now.

    Attributes:
        phase: The current phase (equal to its name string, e.g. "planning").
        fraction: Fraction of the planned motion executed so far, in [0, 1].
    """

    phase: MotionPhase
    fraction: float

    @property
    def is_planning(self) -> bool:
        """True exactly while the worker computes the plan (simulated time may be paused meanwhile)."""
        return self.phase is MotionPhase.PLANNING
