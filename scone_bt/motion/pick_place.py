"""Planning a whole pick-and-place up front: grasp choice, IK, OMPL queries and ruckig timing of every segment.

Runs in a worker thread: it touches only Pinocchio, coal, OMPL and ruckig, never the simulator.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from scone_bt.config import ObjectSpec
from scone_bt.motion.collision import CollisionWorld, Obstacle
from scone_bt.motion.grasp import (
    GraspCandidate,
    GraspParams,
    grasp_candidates,
    lifted,
    object_pose,
    place_pose,
)
from scone_bt.motion.model import ArmModel
from scone_bt.motion.planner import PlannerOptions, plan_joint_path
from scone_bt.motion.timing import KinematicLimits, time_path
from scone_bt.motion.types import FailureStage, PlanResult, TimedTrajectory
from scone_bt.perception.types import Detection

__all__ = [
    "Segment",
    "PickPlacePlan",
    "PickPlaceFailure",
    "PickPlaceRequest",
    "plan_pick_and_place",
    "plan_home",
]

CARTESIAN_SPEED = 0.8
"""Fraction of the robot's limits used for the short straight moves near objects (descend, lift, lower, retreat)."""


@dataclass(frozen=True, eq=False)
class Segment:
    """One timed arm motion of the sequence.

    Attributes:
        phase: Name shown in progress ("approach", "descend", "lift", "transit", "lower", "retreat", "home").
        trajectory: Commanded samples at the control rate.
        waypoints: (N, dof) joint path it was timed through, radians.
    """

    phase: str
    trajectory: TimedTrajectory
    waypoints: np.ndarray | None = None


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

    def ee_path(self, arm: ArmModel, stride: int = 12) -> np.ndarray:
        """(N, 3) planned end-effector positions, metres."""
        pts = [arm.fk(q)[:3, 3] for seg in self.segments for q in seg.trajectory.positions[::stride]]
        return np.asarray(pts)


@dataclass(frozen=True, eq=False)
class PickPlaceFailure:
    """Why no plan exists: stage (IK or PLANNING), message, and any OMPL results made before failing."""

    stage: FailureStage
    message: str
    plans: tuple[PlanResult, ...] = ()
    collision_checks: int = 0
    planning_wall_s: float = 0.0


@dataclass(frozen=True, eq=False)
class PickPlaceRequest:
    """Inputs of one pick-and-place plan (all from perception, the catalogue and known scene geometry).

    Attributes:
        q_start: (dof,) current arm joints, radians.
        target: Detection of the object to move.
        spec: Its catalogue model.
        obstacles: Other detected objects with their catalogue models.
        static: Known scene boxes (world-frame obstacles).
        place_spot: (x, y, table top z) where the object goes.
        other_spots: Further free spots to try, in order, if no collision-free place pose exists at place_spot.
        home: (dof,) joints to return to.
        rng_seed: Seeds IK restarts and OMPL.
        remembered: Objects this robot placed earlier and has not seen since (the camera watches only the shelf).
        params: Approach, lift and place distances.
        preferred_yaw: Closing-axis yaw (rad) of the home pose; the symmetric grasp nearest to it is used.
    """

    q_start: np.ndarray
    target: Detection
    spec: ObjectSpec
    obstacles: tuple[tuple[Detection, ObjectSpec], ...]
    static: tuple[Obstacle, ...]
    place_spot: tuple[float, float, float]
    home: np.ndarray
    rng_seed: int
    remembered: tuple[Obstacle, ...] = ()
    other_spots: tuple[tuple[float, float, float], ...] = ()
    params: GraspParams = field(default_factory=GraspParams)
    preferred_yaw: float = -np.pi / 2


def detected_obstacle(det: Detection, spec: ObjectSpec) -> Obstacle:
    """The collision shape of a detected object (its catalogue model at the detected pose)."""
    return Obstacle(det.name, spec.shape, spec.size, object_pose(det, spec))


class _Planner:
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

    def world(self, *args: object, **kwargs: object) -> CollisionWorld:
        w = CollisionWorld(self.arm, *args, **kwargs)  # type: ignore[arg-type]
        self.worlds.append(w)
        return w

    @property
    def checks(self) -> int:
        return sum(w.checks for w in self.worlds)

    def ik(self, pose: np.ndarray, seed: np.ndarray, restarts: int | None = None) -> np.ndarray | None:
        from scone_bt.motion.model import IKOptions

        t = time.perf_counter()
        opts = IKOptions() if restarts is None else IKOptions(restarts=restarts)
        sol = self.arm.ik(pose, seed, self.rng, opts)
        self.ik_time += time.perf_counter() - t
        return None if sol is None else sol.q

    def line(
        self, q_from: np.ndarray, pose_to: np.ndarray, world: CollisionWorld, what: str
    ) -> tuple[np.ndarray | None, str]:
        """Joints at `pose_to` reached by a straight end-effector line from q_from, or None and why.

        IK follows the line in small steps (each seeded by the last) so the solution stays on the same branch; the
        joint-space segment between the ends must then stay within 1 cm of the line and be collision-free.
        """
        pose_from = self.arm.fk(q_from)
        q = q_from
        for t in np.linspace(0.0, 1.0, 5)[1:]:
            pose = pose_to.copy()
            pose[:3, 3] = pose_from[:3, 3] + (pose_to[:3, 3] - pose_from[:3, 3]) * t
            q = self.ik(pose, q, restarts=0)
            if q is None:
                return None, f"{what}: out of reach"
        pa, pb = pose_from[:3, 3], pose_to[:3, 3]
        axis = (pb - pa) / max(float(np.linalg.norm(pb - pa)), 1e-9)
        for t in np.linspace(0.0, 1.0, 9):
            off = self.arm.fk(q_from + (q - q_from) * t)[:3, 3] - pa
            if np.linalg.norm(off - axis * (off @ axis)) > 0.006:  # sideways drift pushes the object
                return None, f"{what}: the joint motion leaves the straight line"
        if not world.segment_valid(q_from, q):
            bad = next(
                q_from + (q - q_from) * t
                for t in np.linspace(0, 1, 21)
                if not world.is_valid(q_from + (q - q_from) * t)
            )
            return None, f"{what}: collides ({_pair(world, bad)})"
        return q, ""

    def plan(self, qa: np.ndarray, qb: np.ndarray, world: CollisionWorld) -> PlanResult:
        opts = PlannerOptions(
            name=self.options.name,
            time_limit_s=self.options.time_limit_s,
            simplify=self.options.simplify,
            rng_seed=self.seed * 16 + self.queries,
            resolution=self.options.resolution,
            simplify_rounds=self.options.simplify_rounds,
        )
        self.queries += 1
        result = plan_joint_path(qa, qb, self.arm.lower, self.arm.upper, world.is_valid, opts)
        self.plans.append(result)
        return result

    def timed(self, phase: str, path: np.ndarray, slow: bool = False) -> Segment:
        limits = self.limits.scaled(CARTESIAN_SPEED) if slow else self.limits
        traj, report = time_path(path, limits, self.rate_hz)
        self.ruckig_time += report.calculation_s
        self.ruckig_times.append(report.calculation_s)
        return Segment(phase, traj, np.asarray(path))


def plan_pick_and_place(
    arm: ArmModel,
    request: PickPlaceRequest,
    options: PlannerOptions,
    limits: KinematicLimits,
    rate_hz: float,
) -> PickPlacePlan | PickPlaceFailure:
    """Choose a grasp and plan every segment of the pick-and-place; or say which stage makes it impossible."""
    t0 = time.perf_counter()
    p = _Planner(arm, options, limits, rate_hz, request.rng_seed)
    req = request
    target = detected_obstacle(req.target, req.spec)
    others = [detected_obstacle(d, s) for d, s in req.obstacles if d.name != req.target.name]
    fixed = [*req.static, *others, *req.remembered]

    def fail(stage: FailureStage, message: str) -> PickPlaceFailure:
        return PickPlaceFailure(stage, message, tuple(p.plans), p.checks, time.perf_counter() - t0)

    w_free = p.world([*fixed, target])
    # Near the grasp the fingers come within millimetres of the supporting shelf: a thinner margin there.
    w_grasp = p.world([*fixed, target], ignore_for_hand=[target.name], padding=0.004)
    w_other = p.world(fixed, padding=0.004)

    # 1. A grasp whose pre-grasp pose is reachable and collision-free, with a clear straight descent and lift.
    chosen = None
    reasons: list[str] = []
    reachable = False
    for cand in grasp_candidates(req.target, req.spec, req.params, req.preferred_yaw):
        q_pre = p.ik(cand.pregrasp, req.q_start)
        if q_pre is None:
            reasons.append("pre-grasp out of reach")
            continue
        reachable = True
        if not w_free.is_valid(q_pre):
            reasons.append(f"pre-grasp collides ({_pair(w_free, q_pre)})")
            continue
        q_grasp, why = p.line(q_pre, cand.grasp, w_grasp, "descent")
        if q_grasp is None:
            reasons.append(why)
            continue
        q_lift, why = p.line(q_grasp, lifted(cand.grasp, req.params.lift), w_grasp, "lift")
        if q_lift is None:
            reasons.append(why)
            continue
        chosen = (cand, q_pre, q_grasp, q_lift)
        break
    if chosen is None:
        if not reachable:
            return fail(
                FailureStage.IK,
                f"no IK solution for any grasp of {req.target.name} at {_fmt(req.target.position)}",
            )
        return fail(
            FailureStage.PLANNING,
            f"no feasible grasp of {req.target.name}: {'; '.join(dict.fromkeys(reasons))}",
        )
    cand, q_pre, q_grasp, q_lift = chosen

    # 2. A place pose above the spot, reachable with the object in the hand.
    carried = Obstacle(req.target.name, req.spec.shape, req.spec.size, cand.object_in_ee)
    w_carry = p.world(fixed, attached=carried, max_tilt=req.params.max_carry_tilt)
    placed = None
    reasons = []
    place_reachable = False
    spots = [req.place_spot, *(sp for sp in req.other_spots if sp != req.place_spot)]
    target_dir = float(np.arctan2(req.target.position[1], req.target.position[0]))

    def turns(spot: tuple[float, float, float]) -> tuple[float, ...]:
        if cand.tilt == 0.0:
            return (0.0, np.pi / 4, -np.pi / 4, np.pi / 2)
        # A tilted hand keeps leaning away from the robot: turn it with the direction to the spot.
        radial = float(np.arctan2(spot[1], spot[0])) - target_dir
        return (radial, radial + np.pi / 4, radial - np.pi / 4)

    for spot, dyaw in ((sp, d) for sp in spots for d in turns(sp)):
        yaw = cand.closing_yaw + dyaw
        ee_place = place_pose(spot, req.spec, cand.object_in_ee, yaw, req.params, cand.tilt)
        q_pp = p.ik(lifted(ee_place, req.params.approach), q_lift)
        if q_pp is None:
            reasons.append(f"above {_fmt(spot[:2])} out of reach")
            continue
        place_reachable = True
        if not w_carry.is_valid(q_pp):
            reasons.append(f"above {_fmt(spot[:2])} collides ({_pair(w_carry, q_pp)})")
            continue
        q_place, why = p.line(q_pp, ee_place, w_other, f"lowering to {_fmt(spot[:2])}")
        if q_place is None:
            reasons.append(why)
            continue
        q_ret, why = p.line(q_place, lifted(ee_place, req.params.retreat), w_other, "retreat")
        if q_ret is None:
            reasons.append(why)
            continue
        placed = (ee_place, q_pp, q_place, q_ret)
        break
    if placed is None:
        stage = FailureStage.PLANNING if place_reachable else FailureStage.IK
        where = "the free table spots" if len(spots) > 1 else _fmt(req.place_spot)
        return fail(stage, f"no way to place on {where}: {'; '.join(dict.fromkeys(reasons))}")
    ee_place, q_pp, q_place, q_ret = placed

    # 3. The free-space motions, planned with OMPL.
    approach = p.plan(req.q_start, q_pre, w_free)
    if not approach.success:
        return fail(FailureStage.PLANNING, f"approach: {approach.status.value} ({approach.message})")
    transit = p.plan(q_lift, q_pp, w_carry)
    if not transit.success:
        return fail(FailureStage.PLANNING, f"transit: {transit.status.value} ({transit.message})")
    placed_obstacle = Obstacle(req.target.name, req.spec.shape, req.spec.size, ee_place @ cand.object_in_ee)
    w_after = p.world([*fixed, placed_obstacle])
    home = p.plan(q_ret, np.asarray(req.home, dtype=float), w_after)
    if not home.success:
        return fail(FailureStage.PLANNING, f"return home: {home.status.value} ({home.message})")

    segments = (
        p.timed("approach", approach.path),  # type: ignore[arg-type]
        p.timed("descend", np.array([q_pre, q_grasp]), slow=True),
        p.timed("lift", np.array([q_grasp, q_lift]), slow=True),
        p.timed("transit", transit.path),  # type: ignore[arg-type]
        p.timed("lower", np.array([q_pp, q_place]), slow=True),
        p.timed("retreat", np.array([q_place, q_ret]), slow=True),
        p.timed("home", home.path),  # type: ignore[arg-type]
    )
    return PickPlacePlan(
        segments,
        cand,
        tuple(p.plans),
        p.ik_time,
        p.checks,
        p.ruckig_time,
        time.perf_counter() - t0,
        tuple(p.ruckig_times),
        sum(w.check_time for w in p.worlds),
        placed_obstacle,
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
    p = _Planner(arm, options, limits, rate_hz, seed)
    world = p.world(list(static), padding=0.0)
    if not world.is_valid(q_start):
        # Hand still touching something: back off straight up first if possible.
        up = p.ik(lifted(arm.fk(q_start), 0.08), q_start, restarts=0)
        if up is None or not world.is_valid(up):
            return None
        result = p.plan(up, np.asarray(home, dtype=float), world)
        if not result.success:
            return None
        return p.timed("home", np.vstack([q_start, result.path]))
    result = p.plan(q_start, np.asarray(home, dtype=float), world)
    if not result.success:
        return None
    return p.timed("home", result.path)  # type: ignore[arg-type]


def _pair(world: CollisionWorld, q: np.ndarray) -> str:
    pairs = world.colliding_pairs(q)
    return " / ".join(f"{a} ~ {b}" for a, b in pairs[:2]) or "joint limits"


def _fmt(p: Sequence[float]) -> str:
    return "(" + ", ".join(f"{v:.2f}" for v in p) + ")"
