"""Slide and pinch: how the arm takes a flat pack wider than its gripper from a lowest tier.

A pack the fingers cannot span either way (a meat tray, a pack of pitas; `config.grasp.flat_pack`) cannot be
gripped from above or from the side. A person slides it towards themselves with a fingertip and picks it up by the
edge that then sticks out. The robot does the same, in two plans with a look between them:

1. **slide** (`plan_slide`): the fingers closed, the hand pointing down, it comes down over the pack
   ``far_inset_m`` inside its far face (`MotionPhase.APPROACH`), presses ``press_m`` into its top
   (`MotionPhase.PRESS`), moves towards the robot until the front face would stick out ``overhang_m``
   (`slide_distance`; `MotionPhase.DRAG`) and rises and backs away (`MotionPhase.RAISE`). The pads' friction on the
   pack drags it while it beats the shelf's under it. A pack that already sticks out is not slid.
2. **look again**: the cameras find the pack where the slide left it (`motion.system.PickAndPlaceTask`);
3. **pinch** (`pinch_candidates`, then the usual pick-and-place plan): the hand horizontal, square to the pack's
   front face (`front_face`), the fingers closing vertically across its thickness ``pad_inset_m`` inside that face
   (one finger above it, one under the part that sticks out), lifted and carried (as a box `PINCH_CARRY_MARGIN_M`
   larger: it droops), put down sticking out over a table edge with the hand outside the table
   (`pinch_placements`), then backed out the way it came.

Only a lowest tier (`ledge_of`): above one, the hand's lower half would cut into the tier in front of it
(`tools/edge_pinch_reach.py`). Pure geometry and planning (Pinocchio, coal, OMPL and ruckig through a
`PlanSession`); no simulator is touched here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from scone_bt.config import ObjectSpec
from scone_bt.config.catalogue import Shape
from scone_bt.config.grasp import flat_pack
from scone_bt.config.scene import SceneSpec
from scone_bt.motion.collision import CollisionWorld
from scone_bt.motion.grasp import GraspCandidate, GraspFamily, object_pose, top_down_rotation
from scone_bt.motion.ledge import Ledge, ledge_of
from scone_bt.motion.model import ArmModel
from scone_bt.motion.pick_request import PickPlaceRequest, PickScene
from scone_bt.motion.placement import TableRegion
from scone_bt.motion.plan_session import PlanSession, Segment, collision_pair
from scone_bt.motion.planner import PlannerOptions
from scone_bt.motion.timing import KinematicLimits
from scone_bt.motion.types import FailureStage, MotionPhase, PlanFailureReason
from scone_bt.perception.types import Detection

__all__ = [
    "PINCH_CARRY_MARGIN_M",
    "SLIDE_SETTINGS",
    "FrontFace",
    "SlideFailure",
    "SlidePlan",
    "SlideSettings",
    "carried_size",
    "front_face",
    "pinch_candidates",
    "pinch_placements",
    "pinch_rotation",
    "plan_slide",
    "slide_distance",
    "slide_ledge",
]


@dataclass(frozen=True)
class SlideSettings:
    """Distances of the slide and the pinch, metres (module docstring).

    Attributes:
        press_m: How far the closed fingertips press into the pack's top.
        overhang_m: How far the slide means the pack to stick out over its tier's edge (`slide_distance`).
        slide_m: The farthest the pressing hand moves towards the robot.
        min_slide_m: A pack that needs less than this is pinched as it stands, without a slide.
        keep_on_m: The pack's centre stays at least this far inside its tier's edge (it must not tip off).
        far_inset_m: Where the fingertips press: this far inside the pack's far edge.
        hover_m: Height above the pack's top the hand comes down from.
        clear_m: How far the hand rises above that, and moves towards the robot, after the drag: the cameras
            look at the pack again past it.
        pad_inset_m: The pinching pads' centre this far inside the pack's front edge as seen after the slide.
        min_overhang_m: The least the pack must stick out over its tier's edge, as seen after the slide, for a
            pinch to be tried.
        table_overhang_m: How far a pinched pack is put down sticking out over the table's edge: the hand stands
            outside the table, its lower finger under the part that sticks out (`pinch_placements`).
        edge_step_m: Spacing of the put-down spots along each edge of the table, metres.
        pinch_yaws: Turns (rad about world z) of the pinch's approach from the tier's inward direction tried.
    """

    press_m: float = 0.004
    overhang_m: float = 0.045
    slide_m: float = 0.06
    min_slide_m: float = 0.01
    keep_on_m: float = 0.015
    far_inset_m: float = 0.03
    hover_m: float = 0.05
    clear_m: float = 0.10
    pad_inset_m: float = 0.012
    min_overhang_m: float = 0.025
    table_overhang_m: float = 0.035
    edge_step_m: float = 0.06
    pinch_yaws: tuple[float, ...] = tuple(
        math.radians(d) for d in (0.0, 20.0, -20.0, 40.0, -40.0, 60.0, -60.0)
    )


SLIDE_SETTINGS = SlideSettings()
"""The defaults (the press and the pads' inset from `tools/slide_and_pinch_check.py`; the rest measured with the
generator's executions of the catalogue's flat packs, docs/motion.md)."""


@dataclass(frozen=True)
class FrontFace:
    """The pack's face that looks most towards the robot.

    Attributes:
        yaw: Its inward normal (from the robot into the pack), world yaw, radians: one of the box's axes.
        half_depth: Half the pack's extent along that normal, metres.
        centre: (3,) the face's centre, world frame (at the pack's mid-height).
        overhang: How far the face's centre sticks out over the tier's edge, metres (negative: inside it).
    """

    yaw: float
    half_depth: float
    centre: np.ndarray
    overhang: float


def front_face(target: Detection, spec: ObjectSpec, ledge: Ledge) -> FrontFace:
    """The face of a box looking most towards the robot (the stocking turns a pack a little off the tier's
    line, so its frontmost point is a corner: the pinch takes a face)."""
    pose = object_pose(target, spec)
    facing = ledge.unit.facing_yaw
    k = min(range(4), key=lambda j: abs(math.remainder(target.yaw + j * math.pi / 2 - facing, 2 * math.pi)))
    yaw = target.yaw + k * math.pi / 2
    half = spec.size[k % 2] / 2
    normal = np.array([math.cos(yaw), math.sin(yaw), 0.0])
    centre = pose[:3, 3] - half * normal
    u, _ = ledge.uv(centre)
    return FrontFace(float(yaw), float(half), centre, float(ledge.front_u - u))


def slide_ledge(target: Detection, spec: ObjectSpec, opening: float | None, scene: SceneSpec) -> Ledge | None:
    """The ledge to slide ``target`` on, where the skill takes it: a box the gripper spans neither way, flat
    (`config.grasp.flat_pack`), on a lowest tier; None otherwise (the usual grasps, or none, are planned)."""
    if spec.shape != Shape.BOX:
        return None
    if not flat_pack(min(spec.size[0], spec.size[1]), spec.height, opening):
        return None
    x, y, top = target.position
    return ledge_of(scene, (x, y, top - spec.height))


def slide_distance(
    target: Detection, spec: ObjectSpec, ledge: Ledge, settings: SlideSettings = SLIDE_SETTINGS
) -> float:
    """How far to slide the pack towards the robot, metres: until it sticks out ``overhang_m`` over its tier's
    edge, at most ``slide_m`` and never so far that its centre comes within ``keep_on_m`` of the edge; 0 where it
    needs less than ``min_slide_m`` (it is pinched as it stands: the stocking may leave it sticking out)."""
    centre_u, _ = ledge.uv(target.position)
    room = centre_u - ledge.front_u - settings.keep_on_m
    distance = min(settings.overhang_m - front_face(target, spec, ledge).overhang, settings.slide_m, room)
    return float(distance) if distance >= settings.min_slide_m else 0.0


@dataclass(frozen=True, eq=False)
class SlidePlan:
    """The slide, planned before the arm moves.

    Attributes:
        segments: approach (to above the far edge), press, drag, raise.
        ledge: The tier the pack stands on.
        planning_wall_s: Wall seconds of this plan.
        collision_checks: State validity checks made.
    """

    segments: tuple[Segment, ...]
    ledge: Ledge
    planning_wall_s: float
    collision_checks: int


@dataclass(frozen=True, eq=False)
class SlideFailure:
    """Why no slide exists: `reason` and one line naming the stage that ran out (as `PickPlaceFailure`).

    Attributes:
        stage: IK (the press is out of reach) or PLANNING.
        message: One line.
        reason: Which stage ran out of options.
        blockers: Obstacles that blocked, most frequent first.
    """

    stage: FailureStage
    message: str
    reason: PlanFailureReason
    blockers: tuple[str, ...] = ()


def plan_slide(
    arm: ArmModel,
    request: PickPlaceRequest,
    ledge: Ledge,
    distance: float,
    options: PlannerOptions,
    limits: KinematicLimits,
    rate_hz: float,
    settings: SlideSettings = SLIDE_SETTINGS,
) -> SlidePlan | SlideFailure:
    """The approach to above the pack's far strip, the press, the drag ``distance`` metres towards the robot
    (`slide_distance`) and the rise.

    The hand's closing axis is tried along the tier first, then across it; each press pose by IK from the arm's
    joints, the straight press, drag and rise among the scene with the hand allowed to touch the pack, the
    approach by OMPL among everything (the pack included).
    """
    import time

    t0 = time.perf_counter()
    session = PlanSession(arm, options, limits, rate_hz, request.rng_seed)
    scene = PickScene.of(request, arm)
    target, spec = request.target, request.spec
    face = front_face(target, spec, ledge)
    inward = np.array([math.cos(face.yaw), math.sin(face.yaw), 0.0])
    # the fingertips press on the front face's centre line, `far_inset_m` inside the far face
    far_u, v = ledge.uv(face.centre + (2 * face.half_depth - settings.far_inset_m) * inward)
    facing = ledge.unit.facing_yaw
    top = float(target.position[2])
    closed = request.finger_closed + 0.003  # the model's closed fingers touch each other: a hair apart
    around = [*scene.fixed, scene.target]
    free = session.world(around, finger_position=closed)
    touch = session.world(around, ignore_for_hand=[scene.name], padding=0.004, finger_position=closed)
    why: str = ""
    blockers: list[str] = []
    for yaw in (facing + math.pi / 2, facing - math.pi / 2, facing, facing + math.pi):
        poses = _slide_poses(ledge, top_down_rotation(yaw), far_u, v, top, distance, settings)
        q_pre = session.ik(poses[0], request.q_start, restarts=4)
        if q_pre is None:
            why = why or f"no IK solution above the {scene.name}'s far edge"
            continue
        if not free.is_valid(q_pre):
            why = f"above the {scene.name}'s far edge the arm collides ({collision_pair(free, q_pre)})"
            continue
        lines, why_line, names = _straight_lines(session, q_pre, poses[1:], touch)
        if lines is None:
            why, blockers = why_line, names
            continue
        approach = session.direct(request.q_start, q_pre, free) or session.plan(
            request.q_start, q_pre, free, 1
        )
        if not approach.success or approach.path is None:
            why = f"no path to above the {scene.name}: {approach.message}"
            continue
        segments = (
            session.timed(MotionPhase.APPROACH, approach.path),
            session.timed(MotionPhase.PRESS, lines[0], slow=True),
            session.timed(MotionPhase.DRAG, lines[1], slow=True),
            session.timed(MotionPhase.RAISE, np.vstack([lines[2], lines[3][1:]]), slow=True),
        )
        return SlidePlan(segments, ledge, time.perf_counter() - t0, session.checks)
    return _no_slide(scene.name, why, blockers)


def _slide_poses(
    ledge: Ledge,
    rot: np.ndarray,
    far_u: float,
    v: float,
    top: float,
    distance: float,
    settings: SlideSettings,
) -> list[np.ndarray]:
    """The hand's poses: above the far strip, pressed into it, dragged ``distance`` towards the robot, risen,
    then up and back towards the robot, out of the cameras' view of the pack (they look again)."""
    hover, press = top + settings.hover_m, top - settings.press_m
    near_u = far_u - distance
    return [
        _pose(rot, ledge.world(far_u, v, hover)),
        _pose(rot, ledge.world(far_u, v, press)),
        _pose(rot, ledge.world(near_u, v, press)),
        _pose(rot, ledge.world(near_u, v, hover)),
        _pose(rot, ledge.world(near_u - settings.clear_m, v, hover + settings.clear_m)),
    ]


def _straight_lines(
    session: PlanSession, q: np.ndarray, poses: list[np.ndarray], touch: CollisionWorld
) -> tuple[list[np.ndarray] | None, str, list[str]]:
    """The press, the drag and the two pieces of the rise as straight hand lines from ``q`` (None, why and the
    blockers where one is out of reach or collides)."""
    lines: list[np.ndarray] = []
    for pose, what in zip(poses, ("press", "drag", "rise", "rise"), strict=True):
        path, why, names = session.line(q, pose, touch, f"slide {what}")
        if path is None:
            return None, why, names
        lines.append(path)
        q = path[-1]
    return lines, "", []


def _no_slide(name: str, why: str, blockers: list[str]) -> SlideFailure:
    """Why no slide was found, as a typed failure (no IK: IK; else planning)."""
    if why.startswith("no IK"):
        return SlideFailure(FailureStage.IK, f"no slide of the {name}: {why}", PlanFailureReason.NO_GRASP_IK)
    reason = PlanFailureReason.NO_PATH if why.startswith("no path") else PlanFailureReason.GRASPS_BLOCKED
    return SlideFailure(
        FailureStage.PLANNING, f"no slide of the {name}: {why}", reason, tuple(dict.fromkeys(blockers))
    )


def _pose(rotation: np.ndarray, point: np.ndarray) -> np.ndarray:
    out = np.eye(4)
    out[:3, :3] = rotation
    out[:3, 3] = point
    return out


PINCH_CARRY_MARGIN_M = 0.015
"""A pinched pack is carried (in the transit) as a box this much longer and wider on every side (metres): held by
one edge, it droops and turns a little in the fingers under its own weight, which a rigid grasp's 1 mm of
clearance does not allow for."""


def carried_size(spec: ObjectSpec, cand: GraspCandidate) -> tuple[float, float, float]:
    """The size the planner carries ``spec`` as when held by ``cand`` (`PINCH_CARRY_MARGIN_M` for a pinch)."""
    if cand.family is not GraspFamily.PINCH:
        return spec.size
    m = 2 * PINCH_CARRY_MARGIN_M
    return (spec.size[0] + m, spec.size[1] + m, spec.size[2])


def pinch_rotation(inward: np.ndarray, up: bool = True) -> np.ndarray:
    """End-effector rotation approaching horizontally along ``inward``, the fingers closing vertically (world z;
    ``up`` False: the wrist half-turned, the same pinch)."""
    z = inward / np.linalg.norm(inward)
    y = np.array([0.0, 0.0, 1.0 if up else -1.0])
    x = np.cross(y, z)
    return np.column_stack([x, y, z])


def pinch_candidates(
    target: Detection,
    spec: ObjectSpec,
    ledge: Ledge,
    approach: float,
    settings: SlideSettings = SLIDE_SETTINGS,
) -> list[GraspCandidate]:
    """Pinches of the pack's front face (`front_face`) where its centre sticks out over the tier by at least
    ``min_overhang_m``, the pads ``pad_inset_m`` inside it: the approach square to the face first, then turned
    by ``pinch_yaws``, each at both wrist angles; empty where it does not stick out that far."""
    pose = object_pose(target, spec)
    face = front_face(target, spec, ledge)
    if face.overhang < settings.min_overhang_m:
        return []
    inward = np.array([math.cos(face.yaw), math.sin(face.yaw), 0.0])
    point = face.centre + settings.pad_inset_m * inward  # the pads' centre, on the face's centre line
    out: list[GraspCandidate] = []
    for k, turn in enumerate(settings.pinch_yaws):
        yaw = face.yaw + turn
        approach_dir = np.array([math.cos(yaw), math.sin(yaw), 0.0])
        for up in (True, False):
            out.append(
                GraspCandidate(
                    closing_yaw=float(yaw + math.pi / 2),
                    rotation=pinch_rotation(approach_dir, up),
                    point=point,
                    approach=approach,
                    object_pose=pose,
                    span=float(spec.height),
                    family=GraspFamily.PINCH,
                    cost=float(k) + (0.0 if up else 0.5),
                )
            )
    out.sort(key=lambda c: c.cost)
    return out


def pinch_placements(
    table: TableRegion,
    spec: ObjectSpec,
    cand: GraspCandidate,
    base: np.ndarray,
    settings: SlideSettings = SLIDE_SETTINGS,
) -> list[tuple[tuple[float, float, float], float]]:
    """Where a pinched pack can be put down, nearest the arm's base first: (spot, turn) with the spot the pack's
    centre (x, y, table top z) and the turn (rad about world z) of the hand from its pinch.

    The hand's lower half reaches below the pack (the fingers close vertically), so it cannot stand over the
    table: it puts the pack down at an edge, the pads' centre ``table_overhang_m - pad_inset_m`` outside it (the
    fingers and the hand outside the table, the pack sticking out about ``table_overhang_m``) and its approach
    square to the edge, into the table. Each of the table's four edges is tried every ``edge_step_m``; a spot is
    kept where the pack's footprint lies within the edge's length and its centre at least ``keep_on_m`` inside.
    """
    approach = cand.grasp[:3, 2]
    approach_yaw = math.atan2(approach[1], approach[0])
    held = cand.object_in_ee
    half = np.asarray(spec.size, dtype=float) / 2
    corners = np.array([[sx_ * half[0], sy_ * half[1], 0.0] for sx_ in (-1, 1) for sy_ in (-1, 1)])
    (cx, cy), (sx, sy) = table.center, table.size
    pads_out = settings.table_overhang_m - settings.pad_inset_m
    out: list[tuple[tuple[float, float, float], float]] = []
    for nx, ny in ((1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0)):  # each edge's outward normal
        normal, along = np.array([nx, ny]), np.array([-ny, nx])
        edge = np.array([cx + nx * sx / 2, cy + ny * sy / 2])
        half_len = sy / 2 if nx else sx / 2
        turn = math.atan2(-ny, -nx) - approach_yaw  # the approach points into the table, across the edge
        c, s_ = math.cos(turn), math.sin(turn)
        turned = np.array([[c, -s_, 0.0], [s_, c, 0.0], [0.0, 0.0, 1.0]]) @ cand.grasp[:3, :3]
        centre_from_pads = (turned @ held[:3, 3])[:2]
        footprint = (turned @ held[:3, :3] @ corners.T).T[:, :2]
        for k in range(-int(half_len // settings.edge_step_m), int(half_len // settings.edge_step_m) + 1):
            pads = edge + normal * pads_out + along * k * settings.edge_step_m
            centre = pads + centre_from_pads
            if (edge - centre) @ normal < settings.keep_on_m:
                continue
            span = (centre + footprint - edge) @ along
            if span.min() < -half_len or span.max() > half_len:
                continue
            out.append(((float(centre[0]), float(centre[1]), float(table.top_z)), float(turn)))
    out.sort(key=lambda p: math.hypot(p[0][0] - base[0], p[0][1] - base[1]))
    return out
