"""One plan's seeded access to IK, straight-line moves, OMPL and ruckig, with the time and checks it spent.

Every step of a pick-and-place plan (grasp search, placement search, path search, assembly) calls through the same
session, in a fixed order: its one random generator (IK restarts) and its OMPL query counter (each query's seed)
make a seeded plan repeat exactly.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from scone_bt.motion.collision import CollisionWorld, Obstacle
from scone_bt.motion.model import ArmModel, IKOptions
from scone_bt.motion.planner import PlannerOptions, direct_path, path_free, plan_joint_path
from scone_bt.motion.segments import CARRY_RESOLUTION_SCALE, motion_step
from scone_bt.motion.timing import KinematicLimits, time_path
from scone_bt.motion.types import MotionPhase, PlanResult, PlanStatus, TimedTrajectory

__all__ = [
    "CARTESIAN_SPEED",
    "LINE_MAX_WAYPOINTS",
    "LINE_MIN_TOLERANCE",
    "LINE_TOLERANCE",
    "LOCAL_IK_ITERATIONS",
    "PlanSession",
    "Segment",
    "blockers_at",
    "collision_pair",
]

LOCAL_IK_ITERATIONS = 20
"""Iterations of an IK solve seeded nearby (line steps, placements seeded from the lifted arm). Those that converge
need at most 16 (the motion benchmark's Panda plan requests); those that do not spent 37 of 40 on average before."""

LINE_TOLERANCE = 0.006
"""Largest sideways drift (m) of the hand from a straight descent, lift, lowering or retreat."""

LINE_MIN_TOLERANCE = 0.001
"""Tightest sideways drift (m) asked of a descent (beside a tight fit; the arm tracks to about this)."""

LINE_MAX_WAYPOINTS = 8
"""Most pieces a straight hand motion is split into (each timed from rest to rest)."""

CARTESIAN_SPEED = 0.8
"""Fraction of the robot's limits used for the short straight moves near objects (descend, lift, lower, retreat)."""


@dataclass(frozen=True, eq=False)
class Segment:
    """One timed arm motion of the sequence.

    Attributes:
        phase: APPROACH, DESCEND, LIFT, TRANSIT, LOWER, RETREAT or HOME.
        trajectory: Commanded samples at the control rate.
        waypoints: (N, dof) joint path it was timed through, radians.
    """

    phase: MotionPhase
    trajectory: TimedTrajectory
    waypoints: np.ndarray | None = None


class PlanSession:
    """IK, straight lines, OMPL queries and timing for one plan, seeded by `seed`, with what they cost.

    Attributes:
        plans: Every OMPL result, in query order.
        ik_time: Wall seconds spent in IK.
        ruckig_time: Wall seconds in ruckig's solver over all segments.
        ruckig_times: Wall seconds in ruckig's solver per segment.
        worlds: The collision worlds made (their checks are the plan's).
    """

    def __init__(
        self, arm: ArmModel, options: PlannerOptions, limits: KinematicLimits, rate_hz: float, seed: int
    ) -> None:
        self.arm = arm
        self.options = options
        self.limits = limits
        self.rate_hz = rate_hz
        self.rng = np.random.default_rng(seed)
        self.seed = seed
        self.queries = 0
        self.plans: list[PlanResult] = []
        self.ik_time = 0.0
        self.ruckig_time = 0.0
        self.ruckig_times: list[float] = []
        self.worlds: list[CollisionWorld] = []

    def world(
        self,
        obstacles: Sequence[Obstacle],
        attached: Obstacle | None = None,
        *,
        padding: float = 0.01,
        ignore_for_hand: list[str] | tuple[str, ...] = (),
        max_tilt: float | None = None,
        finger_position: float | None = None,
    ) -> CollisionWorld:
        """A collision world whose checks count towards this plan's (arguments as `CollisionWorld`)."""
        w = CollisionWorld(
            self.arm,
            obstacles,
            attached,
            padding=padding,
            ignore_for_hand=ignore_for_hand,
            max_tilt=max_tilt,
            finger_position=finger_position,
        )
        self.worlds.append(w)
        return w

    @property
    def checks(self) -> int:
        """State validity checks made so far."""
        return sum(w.checks for w in self.worlds)

    @property
    def check_time(self) -> float:
        """Wall seconds spent in those validity checks."""
        return sum(w.check_time for w in self.worlds)

    def ik(self, pose: np.ndarray, seed: np.ndarray, restarts: int | None = None) -> np.ndarray | None:
        """Joints reaching `pose` from `seed`; `restarts=0` is a quick local solve, None the default search."""
        t = time.perf_counter()
        if restarts is None:
            opts = IKOptions()
        elif restarts == 0:
            # From a nearby seed a reachable pose converges in a few iterations; an unreachable one is dropped fast.
            opts = IKOptions(restarts=0, max_iterations=LOCAL_IK_ITERATIONS)
        else:
            opts = IKOptions(restarts=restarts)
        sol = self.arm.ik(pose, seed, self.rng, opts)
        self.ik_time += time.perf_counter() - t
        return None if sol is None else sol.q

    def line(
        self,
        q_from: np.ndarray,
        pose_to: np.ndarray,
        world: CollisionWorld,
        what: str,
        tolerance: float = LINE_TOLERANCE,
    ) -> tuple[np.ndarray | None, str, list[str]]:
        """A joint path from q_from to `pose_to` along a straight end-effector line, or None, why, and blockers.

        IK follows the line in small steps (each seeded by the last) so the solution stays on the same branch.
        Between successive waypoints the joint motion must stay within `tolerance` of the line (sideways
        drift pushes the object); where one joint-space segment bows out further (the arm's joints do not move
        linearly for a straight hand motion), the line is split in halves, up to `LINE_MAX_WAYPOINTS` pieces.
        Each piece must be collision-free.

        Returns:
            ((k + 1, dof) waypoints starting at q_from, "", []) or (None, the reason, the obstacles that block).
        """
        pose_from = self.arm.fk(q_from)
        pa, pb = pose_from[:3, 3], pose_to[:3, 3]
        axis = (pb - pa) / max(float(np.linalg.norm(pb - pa)), 1e-9)

        def at(t: float) -> np.ndarray:
            pose = pose_to.copy()
            pose[:3, 3] = pa + (pb - pa) * t
            return pose

        def straight(qa: np.ndarray, qb: np.ndarray) -> bool:
            for t in (0.25, 0.5, 0.75):
                off = self.arm.fk(qa + (qb - qa) * t)[:3, 3] - pa
                if np.linalg.norm(off - axis * (off @ axis)) > tolerance:
                    return False
            return True

        q = self.ik(at(1.0), q_from, restarts=0)
        if q is None:
            return None, f"{what}: out of reach", []
        path = [q_from, q]
        pieces = 1
        while not all(straight(a, b) for a, b in zip(path[:-1], path[1:], strict=True)):
            pieces *= 2
            if pieces > LINE_MAX_WAYPOINTS:
                return None, f"{what}: the joint motion leaves the straight line", []
            q = q_from
            path = [q_from]
            for t in np.linspace(0.0, 1.0, pieces + 1)[1:]:
                q = self.ik(at(float(t)), q, restarts=0)
                if q is None:
                    return None, f"{what}: out of reach", []
                path.append(q)
        for qa, qb in zip(path[:-1], path[1:], strict=True):
            if not world.segment_valid(qa, qb):
                bad = next(
                    (
                        qa + (qb - qa) * t
                        for t in np.linspace(0, 1, 21)
                        if not world.is_valid(qa + (qb - qa) * t)
                    ),
                    qb,
                )
                return None, f"{what}: collides ({collision_pair(world, bad)})", blockers_at(world, bad)
        return np.array(path), "", []

    def plan(self, qa: np.ndarray, qb: np.ndarray, world: CollisionWorld, retries: int = 0) -> PlanResult:
        """One OMPL query; repeated up to `retries` times with the next seed while it times out."""
        result = self._plan_once(qa, qb, world)
        for _ in range(retries):
            if result.status is not PlanStatus.TIMED_OUT:
                break
            result = self._plan_once(qa, qb, world)
        return result

    def direct(self, qa: np.ndarray, qb: np.ndarray, world: CollisionWorld) -> PlanResult | None:
        """The straight joint-space segment from qa to qb when it is free in `world` (`planner.direct_path`), as
        this plan's next query; None (no query used) where it is not, or the options do not try it.

        It takes the place of the query `plan` would have made (that query's seed is used up), so a plan that
        asks this first, and `plan` only where it answers None, seeds its later queries as one that asked `plan`.
        """
        if not self.options.try_direct or not (world.is_valid(qa) and world.is_valid(qb)):
            return None
        result = direct_path(qa, qb, self.arm.lower, self.arm.upper, world.is_valid, self.options)
        if result is None or not self._carry_clear(result, world):
            return None
        self.queries += 1
        self.plans.append(result)
        return result

    def _carry_clear(self, result: PlanResult, world: CollisionWorld) -> bool:
        """Whether a path found in ``world`` is also free at the carry's finer step, where the hand holds a product
        (`segments.CARRY_RESOLUTION_SCALE`: the product reaches beyond the fingertips, and sweeps farther between
        two states of the default step than its clearance). Checked on the path found, not on every candidate:
        the default step rejects most of them at a quarter of the cost."""
        if not world.holds_object or result.path is None:
            return True
        fine = motion_step(self.arm.lower, self.arm.upper, self.options.resolution * CARRY_RESOLUTION_SCALE)
        return path_free(world.is_valid, result.path, fine)

    def _plan_once(self, qa: np.ndarray, qb: np.ndarray, world: CollisionWorld) -> PlanResult:
        opts = replace(self.options, rng_seed=self.seed * 16 + self.queries)
        self.queries += 1
        result = plan_joint_path(qa, qb, self.arm.lower, self.arm.upper, world.is_valid, opts)
        if result.success and not self._carry_clear(result, world):
            # a path the default step passed grazes something between its states: plan again at the finer step
            fine = replace(opts, resolution=opts.resolution * CARRY_RESOLUTION_SCALE)
            result = plan_joint_path(qa, qb, self.arm.lower, self.arm.upper, world.is_valid, fine)
        self.plans.append(result)
        return result

    def timed(self, phase: MotionPhase, path: np.ndarray, slow: bool = False) -> Segment:
        """`path` timed with ruckig at the robot's limits (`CARTESIAN_SPEED` of them if `slow`)."""
        limits = self.limits.scaled(CARTESIAN_SPEED) if slow else self.limits
        traj, report = time_path(path, limits, self.rate_hz)
        self.ruckig_time += report.calculation_s
        self.ruckig_times.append(report.calculation_s)
        return Segment(phase, traj, np.asarray(path))


def blockers_at(world: CollisionWorld, q: np.ndarray) -> list[str]:
    """The obstacles (not arm links) in collision at q."""
    names = []
    for a, b in world.colliding_pairs(q):
        for n in (a, b):
            if n.startswith("obstacle:") and n[9:] not in names:
                names.append(n[9:])
    return names


def collision_pair(world: CollisionWorld, q: np.ndarray) -> str:
    """Up to two colliding pairs at q for a message, e.g. 'panda_hand ~ obstacle:step1'."""
    pairs = world.colliding_pairs(q)
    return " / ".join(f"{a} ~ {b}" for a, b in pairs[:2]) or "joint limits"
