"""Planning a whole pick-and-place up front: grasp choice, placement, OMPL queries and ruckig timing.

Runs in a worker thread: it touches only Pinocchio, coal, OMPL and ruckig, never the simulator.

The strategy, in a fixed order:

1. Grasps (`grasp.grasp_candidates`, cheapest first) are filtered by the hand alone against the scene (no IK),
   then by IK of the pre-grasp pose, the arm's collisions there, and a straight collision-free descent and lift
   (solved in up to `LINE_MAX_WAYPOINTS` pieces where the joints bow away from the line); where the first IK
   answer's arm collides or cannot follow that line, `GraspParams.ik_alternatives` other arm postures (IK from
   random seeds) are tried for the same hand pose. The hand is checked, and executed, with its fingers
   pre-shaped (`preshape`): opened only as far as the widest candidate needs, so they fit between close
   neighbours. The first `GraspParams.max_goal_grasps` feasible ones form a goal set.
2. OMPL plans the approach to the goal set at once and reports which grasp it reached. A query that runs out of
   iterations is repeated with a fresh seed (`GraspParams.path_retries`) before it counts as no path.
3. Placements for that grasp: seeded spots on the observed free table area (`placement.sample_placements`; a
   box's spot comes with the yaws its rectangle fits at, which fix the hand's turn), filtered by IK above the spot
   with the object in the hand, a collision-free lowering and retreat (back up the lowering path; a side grasp
   backs out along its approach instead, as its fingers straddle the object below its top); the first
   `max_goal_placements` feasible ones form the transit's goal set; OMPL plans the transit, then the way home.
4. Fallbacks: a grasp without a feasible placement or transit is dropped and the approach is planned again to
   the other grasps (more candidates are examined as the set empties); every spot the sampler returned is tried
   before giving up on placements; then a typed failure (`PlanFailureReason`) says which stage ran out and what
   blocked it.
"""

from __future__ import annotations

import time
from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from scone_bt.config import ObjectSpec
from scone_bt.motion.collision import CollisionWorld, HandModel, Obstacle
from scone_bt.motion.grasp import (
    GraspCandidate,
    GraspFamily,
    GraspParams,
    grasp_candidates,
    lifted,
    object_pose,
    place_pose,
)
from scone_bt.motion.model import ArmModel, IKOptions
from scone_bt.motion.placement import (
    Footprint,
    PlacementOptions,
    TableRegion,
    sample_placements,
)
from scone_bt.motion.planner import PlannerOptions, plan_joint_path
from scone_bt.motion.timing import KinematicLimits, time_path
from scone_bt.motion.types import (
    FailureStage,
    MotionPhase,
    PlanFailureReason,
    PlanResult,
    PlanStatus,
    TimedTrajectory,
)
from scone_bt.perception.types import Detection

__all__ = [
    "Segment",
    "PickPlacePlan",
    "PickPlaceFailure",
    "PickPlaceRequest",
    "detected_obstacle",
    "preshape",
    "obstacle_footprint",
    "plan_pick_and_place",
    "plan_home",
]

CARRY_PADDING = 0.006
"""Safety margin (m) around obstacles while carrying: the lifted object starts close to its neighbours."""

LOCAL_IK_ITERATIONS = 40
"""Iterations of an IK solve seeded nearby (line steps, placements seeded from the lifted arm)."""

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


@dataclass(frozen=True, eq=False)
class PickPlaceRequest:
    """Inputs of one pick-and-place plan (all from perception, the catalogue and known scene geometry).

    Attributes:
        q_start: (dof,) current arm joints, radians.
        target: Detection of the object to move.
        spec: Its catalogue model.
        obstacles: Other detected objects (on the shelf) with their catalogue models.
        static: Known scene boxes (world-frame obstacles).
        home: (dof,) joints to return to.
        rng_seed: Seeds IK restarts, placement sampling and OMPL.
        table: The table's rectangle, for placement sampling (None: only `place_spots`).
        table_obstacles: What stands on the table (seen there, or remembered by the robot), world frame.
        place_spots: Explicit (x, y, table top z) spots tried in order instead of sampling.
        params: Grasp generation and approach, lift and place distances.
        placement: Placement sampling settings (its rng_seed is replaced by `rng_seed`).
        preferred_yaw: Closing-axis yaw (rad) of the home pose; grasps nearest to it cost least.
        opening: The gripper's full opening, metres (None: no span filter, no pre-shaping).
        finger_closed: Each finger's joint position when closed, metres (the opening counts from it).
    """

    q_start: np.ndarray
    target: Detection
    spec: ObjectSpec
    obstacles: tuple[tuple[Detection, ObjectSpec], ...]
    static: tuple[Obstacle, ...]
    home: np.ndarray
    rng_seed: int
    table: TableRegion | None = None
    table_obstacles: tuple[Obstacle, ...] = ()
    place_spots: tuple[tuple[float, float, float], ...] = ()
    params: GraspParams = field(default_factory=GraspParams)
    placement: PlacementOptions = field(default_factory=PlacementOptions)
    preferred_yaw: float = -np.pi / 2
    opening: float | None = None
    finger_closed: float = 0.0


def preshape(
    candidates: Sequence[GraspCandidate], opening: float | None, closed: float, params: GraspParams
) -> float | None:
    """Finger position (m) that leaves `params.preshape_margin` beside the widest span any candidate needs.

    A hand opened only that far fits between close neighbours (as a robot's pre-grasp posture does); None (fully
    open) without an opening or candidates, or when the widest span needs the full opening anyway.
    """
    if opening is None or not candidates:
        return None
    widest = max(c.span for c in candidates)
    position = closed + widest / 2 + params.preshape_margin
    return None if position >= closed + opening / 2 - 1e-9 else float(position)


def detected_obstacle(det: Detection, spec: ObjectSpec) -> Obstacle:
    """The collision shape of a detected object (its catalogue model at the detected pose)."""
    return Obstacle(det.name, spec.shape, spec.size, object_pose(det, spec))


def obstacle_footprint(ob: Obstacle) -> Footprint:
    """The table footprint of an obstacle standing upright: a box's rectangle at its yaw, else a circle."""
    sx, sy, sz = ob.size
    x, y = float(ob.pose[0, 3]), float(ob.pose[1, 3])
    if ob.shape == "box":
        yaw = float(np.arctan2(ob.pose[1, 0], ob.pose[0, 0]))
        half = (float(sx) / 2, float(sy) / 2)
        return Footprint(ob.name, x, y, float(np.hypot(*half)), float(sz), half, yaw)
    return Footprint(ob.name, x, y, float(sx) / 2, float(sz))


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
                return None, f"{what}: collides ({_pair(world, bad)})", _blockers(world, bad)
        return np.array(path), "", []

    def plan(self, qa: np.ndarray, qb: np.ndarray, world: CollisionWorld, retries: int = 0) -> PlanResult:
        """One OMPL query; repeated up to `retries` times with the next seed while it times out."""
        result = self._plan_once(qa, qb, world)
        for _ in range(retries):
            if result.status is not PlanStatus.TIMED_OUT:
                break
            result = self._plan_once(qa, qb, world)
        return result

    def _plan_once(self, qa: np.ndarray, qb: np.ndarray, world: CollisionWorld) -> PlanResult:
        opts = PlannerOptions(
            name=self.options.name,
            time_limit_s=self.options.time_limit_s,
            simplify=self.options.simplify,
            rng_seed=self.seed * 16 + self.queries,
            resolution=self.options.resolution,
            simplify_rounds=self.options.simplify_rounds,
            try_direct=self.options.try_direct,
        )
        self.queries += 1
        result = plan_joint_path(qa, qb, self.arm.lower, self.arm.upper, world.is_valid, opts)
        self.plans.append(result)
        return result

    def timed(self, phase: MotionPhase, path: np.ndarray, slow: bool = False) -> Segment:
        limits = self.limits.scaled(CARTESIAN_SPEED) if slow else self.limits
        traj, report = time_path(path, limits, self.rate_hz)
        self.ruckig_time += report.calculation_s
        self.ruckig_times.append(report.calculation_s)
        return Segment(phase, traj, np.asarray(path))


@dataclass(frozen=True, eq=False)
class _Grasp:
    cand: GraspCandidate
    q_pre: np.ndarray
    descend: np.ndarray  # (k, dof) from q_pre to the grasp
    lift: np.ndarray  # (k, dof) from the grasp up

    @property
    def q_grasp(self) -> np.ndarray:
        return self.descend[-1]

    @property
    def q_lift(self) -> np.ndarray:
        return self.lift[-1]


@dataclass(frozen=True, eq=False)
class _Placement:
    spot: tuple[float, float, float]
    ee_place: np.ndarray
    q_pp: np.ndarray
    lower: np.ndarray  # (k, dof) from above the spot down to the release
    retreat: np.ndarray  # (k, dof) from the release up

    @property
    def q_ret(self) -> np.ndarray:
        return self.retreat[-1]


class _Tally:
    """Why candidates were rejected: reachable ones, reasons and the obstacles that blocked them."""

    def __init__(self) -> None:
        self.reachable = False
        self.reasons: list[str] = []
        self.blockers: Counter[str] = Counter()

    def blocked(self, why: str, names: Sequence[str]) -> None:
        self.reasons.append(why)
        self.blockers.update(names)

    def top(self, n: int = 3) -> tuple[str, ...]:
        return tuple(name for name, _ in self.blockers.most_common(n))

    def summary(self, n: int = 3) -> str:
        return "; ".join(list(dict.fromkeys(self.reasons))[:n])


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
    t0, c0 = time.perf_counter(), time.thread_time()
    p = _Planner(arm, options, limits, rate_hz, request.rng_seed)
    req = request
    params = req.params
    name = req.target.name
    target = detected_obstacle(req.target, req.spec)
    others = [detected_obstacle(d, s) for d, s in req.obstacles if d.name != name]
    table_objs = [o for o in req.table_obstacles if o.name != name]
    fixed = [*req.static, *others, *table_objs]

    def fail(reason: PlanFailureReason, message: str, blockers: Sequence[str] = ()) -> PickPlaceFailure:
        stage = (
            FailureStage.IK
            if reason in (PlanFailureReason.NO_GRASP_IK, PlanFailureReason.NO_PLACEMENT_IK)
            else FailureStage.PLANNING
        )
        return PickPlaceFailure(
            stage,
            message,
            reason,
            tuple(blockers),
            tuple(p.plans),
            p.checks,
            time.perf_counter() - t0,
            time.thread_time() - c0,
        )

    # 1. Grasp candidates, examined lazily in cost order; the hand opens only as far as they need.
    candidates = grasp_candidates(req.target, req.spec, params, req.preferred_yaw, req.opening)
    fingers = preshape(candidates, req.opening, req.finger_closed, params)
    w_free = p.world([*fixed, target], finger_position=fingers)
    # Near the grasp the fingers come within millimetres of the supporting shelf: a thinner margin there.
    w_grasp = p.world([*fixed, target], ignore_for_hand=[name], padding=0.004, finger_position=fingers)
    hand_free = HandModel(arm, [*fixed, target], padding=0.01, finger_position=fingers)
    hand_near = HandModel(arm, [*fixed, target], padding=0.004, finger_position=fingers)

    # Lift the object until its bottom clears the tops of its neighbours: from there the straight carry towards
    # the table is usually free, and OMPL is needed far less often.
    bottom = req.target.position[2] - req.spec.height
    near_tops = [
        float(o.pose[2, 3] + o.size[2] / 2)
        for o in others
        if np.hypot(*(o.pose[:2, 3] - np.asarray(req.target.position[:2]))) < params.clear_radius
    ]
    lift = float(np.clip(max(near_tops, default=0.0) + 0.03 - bottom, params.lift, params.max_lift))

    tally = _Tally()
    examined = 0
    gap = req.opening if fingers is None else 2 * (fingers - req.finger_closed)

    def descent_tolerance(cand: GraspCandidate) -> float:
        """Sideways drift allowed on the way down: 2/3 of the room beside the object (no finger lands on it).

        A tight fit (a 7.5 cm tub in the 8 cm opening leaves 2.5 mm a side) allows less than the usual line
        tolerance; a finger that drifted onto the rim would tip the object over before the grip closes.
        """
        if gap is None:
            return LINE_TOLERANCE
        return float(np.clip((gap - cand.span) / 3, LINE_MIN_TOLERANCE, LINE_TOLERANCE))

    def next_feasible() -> _Grasp | None:
        nonlocal examined
        while examined < len(candidates):
            cand = candidates[examined]
            examined += 1
            hits = hand_free.colliding(cand.pregrasp)
            if not hits:
                for pose in (
                    _between(cand.pregrasp, cand.grasp, 0.5),
                    cand.grasp,
                    lifted(cand.grasp, lift),
                ):
                    hits = hand_near.colliding(pose, ignore=(name,))
                    if hits:
                        break
            if hits:
                tally.blocked(f"{cand.family.value} grasps: the hand collides with {hits[0]}", hits)
                continue
            if not (arm.can_reach(cand.pregrasp[:3, 3]) and arm.can_reach(cand.grasp[:3, 3])):
                tally.reasons.append(f"{cand.family.value} grasp beyond the arm's reach")
                continue
            # The arm's first IK answer may put its forearm into a tall neighbour or start a descent it cannot
            # follow; another arm posture for the same hand pose (a 7-joint arm has a family of them) may not.
            for attempt in range(1 + params.ik_alternatives):
                seed = req.q_start if attempt == 0 else p.rng.uniform(arm.lower, arm.upper)
                q_pre = p.ik(cand.pregrasp, seed, restarts=4)
                if q_pre is None:
                    if attempt == 0:
                        tally.reasons.append(f"{cand.family.value} pre-grasp out of reach")
                    break  # no posture reaches it from anywhere: another seed finds none either
                tally.reachable = True
                if not w_free.is_valid(q_pre):
                    names = _blockers(w_free, q_pre)
                    tally.blocked(f"{cand.family.value} pre-grasp collides ({_pair(w_free, q_pre)})", names)
                    continue
                descend, why, names = p.line(
                    q_pre, cand.grasp, w_grasp, f"{cand.family.value} descent", descent_tolerance(cand)
                )
                if descend is None:
                    tally.blocked(why, names)
                    continue
                up, why, names = p.line(descend[-1], lifted(cand.grasp, lift), w_grasp, "lift")
                if up is None and lift > params.lift:  # too high to reach: the plain lift, a harder transit
                    up, why, names = p.line(descend[-1], lifted(cand.grasp, params.lift), w_grasp, "lift")
                if up is None:
                    tally.blocked(why, names)
                    continue
                return _Grasp(cand, q_pre, descend, up)
        return None

    # 2. Placement spots: sampled on the observed free area of the table, or given. A box's spot comes with the
    # yaws its footprint fits at there; a round object (or a given spot) may stand at any yaw.
    base = np.asarray(arm.config.base_position, dtype=float)
    target_dir = float(np.arctan2(req.target.position[1] - base[1], req.target.position[0] - base[0]))
    spots: list[tuple[tuple[float, float, float], tuple[float, ...]]]
    if req.place_spots:
        spots = [(tuple(s), ()) for s in req.place_spots]  # type: ignore[misc]
        table_blockers: tuple[str, ...] = ()
    elif req.table is not None:
        sampled = sample_placements(
            req.table,
            [obstacle_footprint(o) for o in table_objs],
            Footprint.of(req.spec),
            req.spec.height,
            replace(req.placement, rng_seed=req.rng_seed),
            tuple(base[:2]),  # type: ignore[arg-type]
            arrival_yaw=req.target.yaw - target_dir,
        )
        spots = [(s.xyz, s.yaws) for s in sampled.spots]
        table_blockers = sampled.blockers
    else:
        spots, table_blockers = [], ()
    if not spots:
        # Nothing to try: the table has no free spot, whichever grasp is used.
        where = ", ".join(table_blockers) or "the table's edges"
        return fail(
            PlanFailureReason.NO_TABLE_SPACE,
            f"no free spot on the table for {name}: none clears {where}",
            table_blockers,
        )
    place_tally = _Tally()

    def placements_for(g: _Grasp) -> tuple[list[_Placement], CollisionWorld | None]:
        """Feasible placements with this grasp, and the carry world; None if the lifted object collides."""
        cand = g.cand
        carried = Obstacle(name, req.spec.shape, req.spec.size, cand.object_in_ee)
        w_carry = p.world(
            fixed,
            attached=carried,
            padding=CARRY_PADDING,
            max_tilt=params.max_carry_tilt,
            finger_position=fingers,
        )
        if not w_carry.is_valid(g.q_lift):
            tally.blocked(
                f"lifted {name} collides ({_pair(w_carry, g.q_lift)})", _blockers(w_carry, g.q_lift)
            )
            return [], None
        w_lower = p.world(
            fixed, attached=carried, padding=0.004, max_tilt=params.max_carry_tilt, finger_position=fingers
        )
        hand_table = HandModel(arm, fixed, padding=0.004, finger_position=fingers)
        out: list[_Placement] = []
        seed: np.ndarray | None = None
        searched = False
        misses = hits_rotated = 0  # how often the turned lifted posture seeded IK above a spot, or did not
        for spot, yaws in spots:
            if len(out) >= params.max_goal_placements:
                break
            radial = float(np.arctan2(spot[1] - base[1], spot[0] - base[0])) - target_dir
            radial = (radial + np.pi) % (2 * np.pi) - np.pi
            for turn in _place_turns(radial, yaws, req.target.yaw, cand.family is GraspFamily.TOP):
                ee_place = place_pose(spot, req.spec, cand.object_in_ee, cand.grasp, turn, params)
                where = _fmt(spot[:2])
                hits = hand_table.colliding(ee_place) or hand_table.colliding(
                    lifted(ee_place, params.retreat)
                )
                if hits:
                    place_tally.blocked(f"at {where} the hand collides with {hits[0]}", hits)
                    continue
                # Seed: the lifted arm turned by the base joint, and a top-down hand's extra turn by the wrist
                # (the last joint turns a downward-pointing hand the other way about world z).
                rotated = g.q_lift.copy()
                # The base turns the way its joint limits allow (the short way round may cross them).
                rotated[0] += min(
                    (radial + k * 2 * np.pi for k in (-1, 0, 1)),
                    key=lambda r: (not arm.lower[0] <= g.q_lift[0] + r <= arm.upper[0], abs(r)),
                )
                if cand.family is GraspFamily.TOP:
                    rotated[-1] -= turn - radial
                above = lifted(ee_place, params.approach)
                # Seeds in the order that has worked: the turned lifted posture, or the last posture found above
                # the table once the turned one stops carrying over (e.g. from a shelf behind the robot).
                seeds = (
                    [rotated]
                    if seed is None
                    else ([seed, rotated] if misses > hits_rotated else [rotated, seed])
                )
                q_pp = None
                for s0 in seeds:
                    q_pp = p.ik(above, s0, restarts=0)
                    if q_pp is not None:
                        if s0 is rotated:
                            hits_rotated += 1
                        break
                    if s0 is rotated:
                        misses += 1
                if q_pp is None and not searched:
                    # The lifted posture does not carry over: one full search from home, whose answer seeds
                    # every later spot.
                    searched = True
                    q_pp = p.ik(above, np.asarray(req.home, dtype=float), restarts=4)
                if q_pp is None:
                    place_tally.reasons.append(f"above {where} out of reach")
                    continue
                seed = q_pp
                place_tally.reachable = True
                if not w_carry.is_valid(q_pp):
                    place_tally.blocked(
                        f"above {where} collides ({_pair(w_carry, q_pp)})", _blockers(w_carry, q_pp)
                    )
                    continue
                lower, why, names = p.line(q_pp, ee_place, w_lower, f"lowering to {where}")
                if lower is None:
                    place_tally.blocked(why, names)
                    continue
                if cand.family is GraspFamily.SIDE:
                    # A side grasp's fingers straddle the object below its top: straight up they would drag it
                    # along (or stay around it); they back out along the approach, the way they came in.
                    placed_here = Obstacle(name, req.spec.shape, req.spec.size, ee_place @ cand.object_in_ee)
                    w_back = p.world(
                        [*fixed, placed_here], ignore_for_hand=[name], padding=0.004, finger_position=fingers
                    )
                    out_pose = ee_place.copy()
                    out_pose[:3, 3] -= ee_place[:3, 2] * params.retreat
                    back, why, names = p.line(lower[-1], out_pose, w_back, "retreat")
                elif abs(params.retreat - params.approach) < 1e-9:
                    # Straight back up the way it came down: free for the hand if it was with the object held.
                    back: np.ndarray | None = lower[::-1].copy()
                else:
                    w_other = p.world(fixed, padding=0.004, finger_position=fingers)
                    back, why, names = p.line(lower[-1], lifted(ee_place, params.retreat), w_other, "retreat")
                if back is None:
                    place_tally.blocked(why, names)
                    continue
                out.append(_Placement(tuple(spot), ee_place, q_pp, lower, back))  # type: ignore[arg-type]
                break
        return out, w_carry

    # 3. Approach to the goal set of grasps; placements and transit for the grasp reached; fall back.
    pool: list[_Grasp] = []
    path_failures: list[str] = []
    placement_failed = False
    while True:
        while len(pool) < params.max_goal_grasps:
            g = next_feasible()
            if g is None:
                break
            pool.append(g)
        if not pool:
            break
        approach_set = len(pool)
        approach = p.plan(req.q_start, np.array([g.q_pre for g in pool]), w_free, params.path_retries)
        if not approach.success:
            path_failures.append(f"approach: {approach.status.value} ({approach.message})")
            pool = []  # none of these grasps can be reached: examine the next candidates
            continue
        chosen = pool[approach.goal_index]
        placements, w_carry = placements_for(chosen)
        if not placements or w_carry is None:
            placement_failed = placement_failed or w_carry is not None
            pool.remove(chosen)
            continue
        transit = p.plan(
            chosen.q_lift, np.array([pl.q_pp for pl in placements]), w_carry, params.path_retries
        )
        if not transit.success:
            path_failures.append(f"transit: {transit.status.value} ({transit.message})")
            pool.remove(chosen)
            continue
        placed = placements[transit.goal_index]
        placed_obstacle = Obstacle(
            name, req.spec.shape, req.spec.size, placed.ee_place @ chosen.cand.object_in_ee
        )
        # The hand has just retreated straight up from the object: the near-object margin, as for the retreat.
        w_after = p.world([*fixed, placed_obstacle], padding=0.004, finger_position=fingers)
        home = p.plan(placed.q_ret, np.asarray(req.home, dtype=float), w_after, params.path_retries)
        if not home.success:
            # Home is the same for every grasp; another grasp would not change the way back.
            return fail(PlanFailureReason.NO_PATH, f"return home: {home.status.value} ({home.message})")
        segments = (
            p.timed(MotionPhase.APPROACH, approach.path),  # type: ignore[arg-type]
            p.timed(MotionPhase.DESCEND, chosen.descend, slow=True),
            p.timed(MotionPhase.LIFT, chosen.lift, slow=True),
            p.timed(MotionPhase.TRANSIT, transit.path),  # type: ignore[arg-type]
            p.timed(MotionPhase.LOWER, placed.lower, slow=True),
            p.timed(MotionPhase.RETREAT, placed.retreat, slow=True),
            p.timed(MotionPhase.HOME, home.path),  # type: ignore[arg-type]
        )
        return PickPlacePlan(
            segments,
            chosen.cand,
            tuple(p.plans),
            p.ik_time,
            p.checks,
            p.ruckig_time,
            time.perf_counter() - t0,
            tuple(p.ruckig_times),
            sum(w.check_time for w in p.worlds),
            placed_obstacle,
            time.thread_time() - c0,
            placed.spot,
            examined,
            (approach_set, len(placements)),
            fingers,
        )

    # 4. Out of options: say which stage ran out, and what blocked it.
    if placement_failed:
        if not place_tally.reachable and not place_tally.blockers:
            return fail(
                PlanFailureReason.NO_PLACEMENT_IK,
                f"no free table spot is within reach with {name} in the hand ({len(spots)} spots tried)",
            )
        blockers = place_tally.top()
        return fail(
            PlanFailureReason.PLACEMENTS_BLOCKED,
            f"no placement of {name} clears {', '.join(blockers) or 'the arm'}: {place_tally.summary()}",
            blockers,
        )
    if path_failures:
        return fail(PlanFailureReason.NO_PATH, f"no path to any grasp of {name}: {path_failures[-1]}")
    if not tally.reachable and not tally.blockers:
        return fail(
            PlanFailureReason.NO_GRASP_IK,
            f"no IK solution for any grasp of {name} at {_fmt(req.target.position)}",
        )
    blockers = tally.top()
    return fail(
        PlanFailureReason.GRASPS_BLOCKED,
        f"every grasp of {name} collides with {', '.join(blockers) or 'the arm itself'} "
        f"({len(candidates)} tried): {tally.summary()}",
        blockers,
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
        return p.timed(MotionPhase.HOME, np.vstack([q_start, result.path]))
    result = p.plan(q_start, np.asarray(home, dtype=float), world)
    if not result.success:
        return None
    return p.timed(MotionPhase.HOME, result.path)  # type: ignore[arg-type]


def _place_turns(radial: float, yaws: Sequence[float], object_yaw: float, top: bool) -> list[float]:
    """Turns (rad about world z) of the hand from its grasp to a placement, most natural first.

    The hand turned with the base first (`radial`): then the carry is close to a pure rotation of the first joint
    (vertical for both arms), which keeps the object upright and at its lifted height. A round object may also
    be turned by the wrist; a box must arrive at one of the yaws its footprint fits at (`yaws`, modulo a half
    turn). A top-down hand turns freely about its approach axis; other hands turn at most an eighth of a turn
    from the base's direction.
    """
    limit = np.pi / 2 if top else np.pi / 4
    if not yaws:
        steps = (0.0, np.pi / 4, -np.pi / 4, np.pi / 2, -np.pi / 2) if top else (0.0, np.pi / 4, -np.pi / 4)
        return [radial + d for d in steps]
    out: list[float] = []
    for yaw in yaws:
        d = (yaw - object_yaw - radial + np.pi / 2) % np.pi - np.pi / 2  # nearest turn modulo a half turn
        for delta in (d, d - np.pi, d + np.pi):
            if abs(delta) <= limit + 1e-9 and all(abs(radial + delta - t) > 1e-6 for t in out):
                out.append(radial + delta)
    return out


def _between(a: np.ndarray, b: np.ndarray, t: float) -> np.ndarray:
    """The pose a fraction t of the way from a to b (translation only; both share a rotation here)."""
    out = b.copy()
    out[:3, 3] = a[:3, 3] + (b[:3, 3] - a[:3, 3]) * t
    return out


def _blockers(world: CollisionWorld, q: np.ndarray) -> list[str]:
    """The obstacles (not arm links) in collision at q."""
    names = []
    for a, b in world.colliding_pairs(q):
        for n in (a, b):
            if n.startswith("obstacle:") and n[9:] not in names:
                names.append(n[9:])
    return names


def _pair(world: CollisionWorld, q: np.ndarray) -> str:
    pairs = world.colliding_pairs(q)
    return " / ".join(f"{a} ~ {b}" for a, b in pairs[:2]) or "joint limits"


def _fmt(p: Sequence[float]) -> str:
    return "(" + ", ".join(f"{v:.2f}" for v in p) + ")"
