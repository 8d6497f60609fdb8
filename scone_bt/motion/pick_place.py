"""Planning a whole pick-and-place up front: grasp choice, placement, OMPL queries and ruckig timing.

Runs in a worker thread: it touches only Pinocchio, coal, OMPL and ruckig, never the simulator.

`plan_pick_and_place` runs these steps, all through one seeded `PlanSession` (so a seeded plan repeats exactly):

1. Grasp search (`grasp_search`): candidates cheapest first, filtered by the hand alone, then IK, the arm's
   collisions, and a straight descent and lift; the hand pre-shaped to the widest candidate.
2. Placement spots (`placement_search.find_spots`): seeded samples of the observed free table area, or given.
3. Path search (`path_search`): the approach to a goal set of grasps (ended at the first reached in a straight
   line; OMPL where none is), then, for the grasp reached, the placement search
   (`placement_search.search_placements`) gives the transit's goal set likewise; then the way home. A
   grasp without a feasible placement or transit is dropped and the approach planned again to the others.
4. Plan assembly (`assemble_plan`): every segment timed with ruckig into a `PickPlacePlan`; or failure diagnosis
   (`diagnose_failure`): a typed failure (`PlanFailureReason`) saying which stage ran out and what blocked it,
   from the statistics (`PlanStats`) each step returned.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from scone_bt.motion.collision import Obstacle
from scone_bt.motion.grasp import GraspCandidate, lifted
from scone_bt.motion.grasp_search import FeasibleGrasp, prepare_grasps, preshape
from scone_bt.motion.model import ArmModel
from scone_bt.motion.path_search import Paths, PathSearch, search_paths
from scone_bt.motion.pick_request import PickPlaceRequest, PickScene, detected_obstacle
from scone_bt.motion.placement_search import PlacementSpots, find_spots, obstacle_footprint
from scone_bt.motion.plan_session import PlanSession, Segment
from scone_bt.motion.plan_stats import format_point
from scone_bt.motion.planner import PlannerOptions
from scone_bt.motion.timing import KinematicLimits
from scone_bt.motion.types import FailureStage, MotionPhase, PlanFailureReason, PlanResult

__all__ = [
    "Diagnosis",
    "PickPlaceFailure",
    "PickPlacePlan",
    "PickPlaceRequest",
    "Segment",
    "assemble_plan",
    "detected_obstacle",
    "diagnose_failure",
    "obstacle_footprint",
    "plan_home",
    "plan_pick_and_place",
    "preshape",
]


@dataclass(frozen=True, eq=False)
class PickPlacePlan:
    """Everything the executor needs, planned before the arm moves.

    Attributes:
        segments: approach, descend (then close), lift, transit, lower (then open), retreat, home.
        grasp: The chosen grasp.
        plans: The OMPL results (approach, transit, home) for statistics.
        ik_time: Wall seconds spent in IK.
        collision_checks: State validity checks made.
        ruckig_time: Wall seconds in ruckig's solver over all segments.
        planning_wall_s: Total wall seconds of this plan.
        ruckig_times: Wall seconds in ruckig's solver per segment.
        collision_time: Wall seconds spent in those validity checks.
        placed: The object's collision shape where it will stand after the release (world frame).
        planning_cpu_s: CPU seconds the planning thread used (wall time includes waiting for the interpreter).
        place_spot: (x, y, table top z) where the object's centre goes.
        grasps_tried: Grasp candidates examined.
        goal_set_sizes: Number of goals handed to OMPL for the approach and the transit.
        finger_position: Each finger's position (m) the hand is pre-shaped to for the approach and opens to at
            the release; None: fully open.
        feasible: The grasp with its joint paths (what a new place spot is planned with, `motion.new_spot`).
    """

    segments: tuple[Segment, ...]
    grasp: GraspCandidate
    plans: tuple[PlanResult, ...]
    ik_time: float
    collision_checks: int
    ruckig_time: float
    planning_wall_s: float
    ruckig_times: tuple[float, ...] = ()
    collision_time: float = 0.0
    placed: Obstacle | None = None
    planning_cpu_s: float = 0.0
    place_spot: tuple[float, float, float] | None = None
    grasps_tried: int = 0
    goal_set_sizes: tuple[int, int] = (1, 1)
    finger_position: float | None = None
    feasible: FeasibleGrasp | None = None

    def ee_path(self, arm: ArmModel, stride: int = 12) -> np.ndarray:
        """(N, 3) planned end-effector positions, metres."""
        pts = [arm.fk(q)[:3, 3] for seg in self.segments for q in seg.trajectory.positions[::stride]]
        return np.asarray(pts)


@dataclass(frozen=True, eq=False)
class PickPlaceFailure:
    """Why no plan exists.

    Attributes:
        stage: IK (nothing within reach) or PLANNING.
        message: One line naming the stage that ran out and what blocked it.
        reason: Which stage ran out of options.
        blockers: Obstacles (scene boxes or object names) that blocked the most candidates, most frequent first.
        plans: OMPL results made before failing.
        collision_checks: State validity checks made.
        planning_wall_s: Wall seconds spent.
        planning_cpu_s: CPU seconds the planning thread used.
    """

    stage: FailureStage
    message: str
    reason: PlanFailureReason = PlanFailureReason.NO_PATH
    blockers: tuple[str, ...] = ()
    plans: tuple[PlanResult, ...] = ()
    collision_checks: int = 0
    planning_wall_s: float = 0.0
    planning_cpu_s: float = 0.0


@dataclass(frozen=True)
class Diagnosis:
    """Why no plan exists, before it is stamped with the plan's statistics.

    Attributes:
        reason: Which stage ran out of options.
        message: One line naming that stage and what blocked it.
        blockers: Obstacles that blocked the most candidates, most frequent first.
    """

    reason: PlanFailureReason
    message: str
    blockers: tuple[str, ...] = ()

    @property
    def stage(self) -> FailureStage:
        """IK when nothing was within reach, else PLANNING."""
        ik = (PlanFailureReason.NO_GRASP_IK, PlanFailureReason.NO_PLACEMENT_IK)
        return FailureStage.IK if self.reason in ik else FailureStage.PLANNING


@dataclass(frozen=True)
class _Clock:
    """When planning began: wall (perf_counter) and this thread's CPU seconds."""

    wall0: float
    cpu0: float

    @classmethod
    def start(cls) -> _Clock:
        return cls(time.perf_counter(), time.thread_time())

    def wall(self) -> float:
        return time.perf_counter() - self.wall0

    def cpu(self) -> float:
        return time.thread_time() - self.cpu0


def plan_pick_and_place(
    arm: ArmModel,
    request: PickPlaceRequest,
    options: PlannerOptions,
    limits: KinematicLimits,
    rate_hz: float,
) -> PickPlacePlan | PickPlaceFailure:
    """Choose a grasp and a placement and plan every segment; or say which stage ran out of options and why.

    Raises:
        SconeError: a configuration error (e.g. an unknown planner); it is not an outcome of the attempt.
    """
    clock = _Clock.start()
    session = PlanSession(arm, options, limits, rate_hz, request.rng_seed)
    scene = PickScene.of(request, arm)
    site = prepare_grasps(session, scene)
    spots = find_spots(scene)
    if not spots.spots:  # nothing to try, whichever grasp is used
        return _failure(session, clock, diagnose_failure(request, len(site.candidates), spots, None))
    search = search_paths(session, scene, site, spots)
    if search.paths is None:
        return _failure(session, clock, diagnose_failure(request, len(site.candidates), spots, search))
    return assemble_plan(session, search.paths, search.grasps.examined, site.finger_position, clock)


def assemble_plan(
    session: PlanSession,
    paths: Paths,
    grasps_tried: int,
    finger_position: float | None,
    clock: _Clock,
) -> PickPlacePlan:
    """Every segment timed with ruckig, in order, with the plan's statistics."""
    grasp, placement = paths.grasp, paths.placement
    segments = (
        session.timed(MotionPhase.APPROACH, paths.approach.waypoints),
        session.timed(MotionPhase.DESCEND, grasp.descend, slow=True),
        session.timed(MotionPhase.LIFT, grasp.lift, slow=True),
        session.timed(MotionPhase.TRANSIT, paths.transit.waypoints),
        session.timed(MotionPhase.LOWER, placement.lower, slow=True),
        session.timed(MotionPhase.RETREAT, placement.retreat, slow=True),
        session.timed(MotionPhase.HOME, paths.home.waypoints),
    )
    return PickPlacePlan(
        segments=segments,
        grasp=grasp.cand,
        plans=tuple(session.plans),
        ik_time=session.ik_time,
        collision_checks=session.checks,
        ruckig_time=session.ruckig_time,
        planning_wall_s=clock.wall(),
        ruckig_times=tuple(session.ruckig_times),
        collision_time=session.check_time,
        placed=paths.placed,
        planning_cpu_s=clock.cpu(),
        place_spot=placement.spot,
        grasps_tried=grasps_tried,
        goal_set_sizes=paths.goal_set_sizes,
        finger_position=finger_position,
        feasible=grasp,
    )


def diagnose_failure(
    request: PickPlaceRequest, candidates: int, spots: PlacementSpots, search: PathSearch | None
) -> Diagnosis:
    """Which stage ran out of options and what blocked it, from the steps' statistics.

    Args:
        request: The request planned for.
        candidates: Number of grasp candidates there were.
        spots: The placement spots there were.
        search: The path search's result; None: it did not run, as there was no spot.

    Stages are blamed latest first: the way home, placements, paths, then grasps (reach before collisions).
    """
    name = request.target.name
    if search is None:
        where = ", ".join(spots.blockers) or "the table's edges"
        message = f"no free spot on the table for {name}: none clears {where}"
        return Diagnosis(PlanFailureReason.NO_TABLE_SPACE, message, spots.blockers)
    if search.home_failure is not None:
        return Diagnosis(PlanFailureReason.NO_PATH, search.home_failure)
    if search.placement_failed:
        placed = search.placements
        if not placed.reachable and not placed.blockers:
            message = (
                f"no free table spot is within reach with {name} in the hand ({len(spots.spots)} spots tried)"
            )
            return Diagnosis(PlanFailureReason.NO_PLACEMENT_IK, message)
        blockers = placed.top()
        message = f"no placement of {name} clears {', '.join(blockers) or 'the arm'}: {placed.summary()}"
        return Diagnosis(PlanFailureReason.PLACEMENTS_BLOCKED, message, blockers)
    if search.path_failures:
        return Diagnosis(
            PlanFailureReason.NO_PATH, f"no path to any grasp of {name}: {search.path_failures[-1]}"
        )
    grasps = search.grasps
    if not grasps.reachable and not grasps.blockers:
        where = format_point(request.target.position)
        return Diagnosis(PlanFailureReason.NO_GRASP_IK, f"no IK solution for any grasp of {name} at {where}")
    blockers = grasps.top()
    message = (
        f"every grasp of {name} collides with {', '.join(blockers) or 'the arm itself'} "
        f"({candidates} tried): {grasps.summary()}"
    )
    return Diagnosis(PlanFailureReason.GRASPS_BLOCKED, message, blockers)


def _failure(session: PlanSession, clock: _Clock, diagnosis: Diagnosis) -> PickPlaceFailure:
    return PickPlaceFailure(
        stage=diagnosis.stage,
        message=diagnosis.message,
        reason=diagnosis.reason,
        blockers=diagnosis.blockers,
        plans=tuple(session.plans),
        collision_checks=session.checks,
        planning_wall_s=clock.wall(),
        planning_cpu_s=clock.cpu(),
    )


def plan_home(
    arm: ArmModel,
    q_start: np.ndarray,
    home: np.ndarray,
    static: Sequence[Obstacle],
    options: PlannerOptions,
    limits: KinematicLimits,
    rate_hz: float,
    seed: int,
) -> Segment | None:
    """A timed motion back home among the static scene (used after a failure or a cancel); None if impossible."""
    p = PlanSession(arm, options, limits, rate_hz, seed)
    world = p.world(list(static), padding=0.0)
    q_start = arm.as_measured(q_start)
    if not world.is_valid(q_start):
        # Hand still touching something: back off straight up first if possible.
        up = p.ik(lifted(arm.fk(q_start), 0.08), q_start, restarts=0)
        if up is None or not world.is_valid(up):
            return None
        result = p.plan(up, np.asarray(home, dtype=float), world)
        if not result.success:
            return None
        return p.timed(MotionPhase.HOME, np.vstack([q_start, result.waypoints]))
    result = p.plan(q_start, np.asarray(home, dtype=float), world)
    if not result.success:
        return None
    return p.timed(MotionPhase.HOME, result.waypoints)
