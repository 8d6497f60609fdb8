"""Where the gripper goes: grasp candidates and place poses from a detection and the object's catalogue model.

Pure geometry (numpy only). Convention for every robot's end-effector frame: z points from the hand towards the
fingertips (the approach direction) and y is the axis along which the fingers close.

Grasp generation follows what manipulation frameworks do (MoveIt Task Constructor's yaw sampling,
pybullet-planning's top and side grasp generators), in three families:

- **top**: the hand points straight down; cylinders over a sweep of closing yaws (`GraspParams.yaw_step`), boxes
  across each pair of faces; each with the wrist half-turned as well (same grasp, other wrist angle); each also
  at a shallow depth (`GraspParams.shallow_depth`), whose palm clears a neighbour a little taller than the object;
- a box's top grasps also **off-centre** along the box (`GraspParams.offsets`, perpendicular to the closing axis):
  the palm's end then passes beside a neighbour that stands in line with the box's centre;
- **tilted**: the top grasps leaned about their closing axis by `GraspParams.tilts` (never towards the robot),
  for objects at the edge of reach or under a low obstacle;
- **side**: the hand approaches horizontally from the faces that look towards the robot (within
  `GraspParams.side_max_angle` of the direction from the robot), gripping the object at
  `side_height_fraction` of its height; for objects too tall to be gripped from above between tall neighbours.

Candidates whose span (the object's extent between the fingers) does not fit the opening are dropped, unless no
candidate fits at all: then the narrowest ones are kept, the robot tries, and the physics decides (an object wider
than the gripper is a failure of the robot's proficiency, not of its planner).

The **cost** that orders them (lower first) is

    cost = family_cost[family] + wrist_weight * |closing yaw - preferred yaw| / (pi/2)
           + tilt_weight * |tilt| + span_weight * span / opening + shallow_cost * (shallow)
           + offset_weight * |offset| / (half the box's length along the offset)

with the wrist term taken over the nearest symmetric yaw (a parallel gripper is symmetric under half turns, the
arm is not), so the pose nearest the arm's home wrist comes first, top before tilted before side, and among equal
poses the one that leaves the fingers most room.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace
from enum import Enum
from typing import Any

import numpy as np

from scone_bt.config import ObjectSpec, RobotConfig
from scone_bt.errors import ConfigError
from scone_bt.perception.types import Detection

__all__ = [
    "GraspFamily",
    "GraspCandidate",
    "GraspParams",
    "grasp_candidates",
    "top_down_rotation",
    "side_rotation",
    "place_pose",
    "object_pose",
    "lifted",
]


class GraspFamily(str, Enum):  # noqa: UP042 (str() of members is used in messages)
    """How the hand approaches the object."""

    TOP = "top"
    TILTED = "tilted"
    SIDE = "side"


@dataclass(frozen=True)
class GraspParams:
    """Grasp generation and the distances of a pick, metres and radians.

    The robot file's `grasp:` section sets any of these (angles there in degrees, keys ending in `_deg`).

    Attributes:
        approach: Distance of the pre-grasp pose from the grasp pose, along the approach.
        lift: How far the object is lifted straight up before carrying it, at least.
        max_lift: How far at most: the lift is raised until the object clears its neighbours within
            `clear_radius`, up to this.
        clear_radius: Horizontal distance (m) of the neighbours the lifted object must clear.
        max_depth: Deepest a top grasp point goes below the object's top face.
        min_clearance: Minimum height of a top grasp point above the supporting surface.
        shallow_depth: Depth of the shallow top grasps below the top face (0: none); the finger pads still
            cover this plus their own overhang below the grasp point.
        shallow_cost: Extra cost of a shallow top grasp (less of the pads on the object).
        place_drop: Gap between the object's bottom and the table when it is released.
        retreat: How far the hand backs off upwards after releasing.
        max_carry_tilt: Largest tilt of the carried object from upright, radians.
        yaw_step: Spacing of the closing yaws swept for cylinders, radians.
        tilts: Leans (rad) of the tilted approaches, about the closing axis.
        offsets: Distances (m) a box's top grasp point is also moved off its centre, both ways along the box
            perpendicular to the closing axis (the fingers still close across the same faces).
        offset_margin: Least distance (m) between an off-centre grasp point and the box's end (the finger pads'
            half width and some room).
        offset_weight: Cost of an offset reaching the box's end (the farther from the centre of mass, the more
            the object turns in the grip).
        side_grasps: Generate side grasps at all.
        side_max_angle: Largest angle (rad) between a side approach and the direction from the robot.
        side_depth: How far past the object's near face the side grasp point goes at most.
        side_shallow_depth: A second, shallower side grasp point this far past the near face (0: none), costing
            `shallow_cost` more: the hand stays farther from what stands behind the object.
        side_height_fraction: Height of the side grasp point as a fraction of the object's height.
        side_min_height: Lowest side grasp point above the support (the palm must clear it).
        side_top_margin: Lowest distance of a side grasp point below the object's top.
        opening_margin: Room (m) the fingers need beyond the object's span.
        preshape_margin: Room (m) left beside the object on each side by the fingers pre-shaped for the
            approach (the hand opens only as far as the widest candidate needs, to fit between neighbours).
        family_cost: Cost of the top, tilted and side families (see the module docstring).
        wrist_weight: Cost per quarter turn of the wrist from the preferred yaw.
        tilt_weight: Cost per radian of tilt.
        span_weight: Cost of a span equal to the opening.
        max_goal_grasps: Feasible grasps handed to the planner together as a goal set.
        max_goal_placements: Feasible placements per grasp handed to the planner together.
        ik_alternatives: Other arm postures (IK from random seeds) tried for a grasp whose first IK answer collides
            with the scene or cannot follow the straight descent and lift.
        path_retries: OMPL queries repeated with a fresh seed (same budget) when one runs out of iterations
            before "no path" is the answer: a sampling planner's miss on one seed is not the scene's verdict.
    """

    approach: float = 0.10
    lift: float = 0.10
    max_lift: float = 0.25
    clear_radius: float = 0.25
    max_depth: float = 0.03
    min_clearance: float = 0.015
    shallow_depth: float = 0.012
    shallow_cost: float = 0.45
    place_drop: float = 0.006
    retreat: float = 0.10
    max_carry_tilt: float = 0.35
    yaw_step: float = math.pi / 8
    tilts: tuple[float, ...] = (0.45, 0.8)
    offsets: tuple[float, ...] = ()
    offset_margin: float = 0.015
    offset_weight: float = 0.5
    side_grasps: bool = True
    side_max_angle: float = math.pi / 2
    side_depth: float = 0.03
    side_shallow_depth: float = 0.0
    side_height_fraction: float = 0.6
    side_min_height: float = 0.045
    side_top_margin: float = 0.015
    opening_margin: float = 0.004
    preshape_margin: float = 0.01
    family_cost: tuple[float, float, float] = (0.0, 0.6, 0.9)
    wrist_weight: float = 0.3
    tilt_weight: float = 0.2
    span_weight: float = 0.1
    max_goal_grasps: int = 4
    max_goal_placements: int = 4
    ik_alternatives: int = 0
    path_retries: int = 1

    @classmethod
    def of(cls, robot: RobotConfig) -> GraspParams:
        """The robot file's grasp settings (validated when the file was loaded), or the defaults."""
        return robot.grasp if robot.grasp is not None else cls()

    @classmethod
    def from_section(cls, section: dict[str, Any] | None, where: str) -> GraspParams:
        """Parameters from a robot file's `grasp:` section (angles in degrees under `<name>_deg` keys).

        Raises:
            ConfigError: an unknown key or a value of the wrong type or sign, naming the key and the valid keys.
        """
        if not section:
            return cls()
        if not isinstance(section, dict):
            raise ConfigError(f"{where}: grasp must be a mapping of settings")
        valid = {f.name: f for f in fields(cls)}
        angles = {"max_carry_tilt", "yaw_step", "tilts", "side_max_angle"}
        names = sorted([*(n for n in valid if n not in angles), *(f"{n}_deg" for n in angles)])
        values: dict[str, Any] = {}
        for key, raw in section.items():
            name = key[: -len("_deg")] if key.endswith("_deg") and key[: -len("_deg")] in angles else key
            if name not in valid or (name in angles) != key.endswith("_deg"):
                shown = key if str(key).isprintable() else repr(key)  # a key with a line break stays one line
                raise ConfigError(f"{where}: grasp.{shown} is not a grasp setting; valid: {', '.join(names)}")
            default = getattr(cls(), name)
            try:
                if isinstance(default, bool):
                    if not isinstance(raw, bool):
                        raise TypeError
                    value: Any = raw
                elif isinstance(default, tuple):
                    value = tuple(float(v) for v in raw)
                    if name == "family_cost" and len(value) != 3:
                        raise TypeError
                elif isinstance(default, int):
                    if isinstance(raw, bool) or int(raw) != raw:
                        raise TypeError
                    value = int(raw)
                else:
                    value = float(raw)
            except (TypeError, ValueError):
                raise ConfigError(
                    f"{where}: grasp.{key} must be {type(default).__name__} like {default!r}, got {raw!r}"
                ) from None
            numbers = value if isinstance(value, tuple) else (value,)
            if not isinstance(value, bool) and any(not math.isfinite(v) or v < 0 for v in numbers):
                raise ConfigError(f"{where}: grasp.{key} must be non-negative and finite, got {raw!r}")
            if name in angles:
                value = (
                    tuple(math.radians(v) for v in value) if isinstance(value, tuple) else math.radians(value)
                )
            values[name] = value
        params = replace(cls(), **values)
        if params.yaw_step <= 0 or params.max_goal_grasps < 1 or params.max_goal_placements < 1:
            raise ConfigError(f"{where}: grasp.yaw_step_deg and grasp.max_goal_* must be positive")
        return params


@dataclass(frozen=True, eq=False)
class GraspCandidate:
    """One way to grasp the target.

    Attributes:
        closing_yaw: World direction of the fingers' closing axis, radians.
        grasp: (4, 4) end-effector pose at the grasp, world frame.
        pregrasp: (4, 4) end-effector pose `approach` metres back along the approach.
        object_in_ee: (4, 4) pose of the object's centre in the end-effector frame while held.
        span: Object extent between the fingers, metres.
        tilt: Rotation (rad) of a top approach about the closing axis, away from vertical (0: top-down).
        family: Top, tilted or side.
        cost: Ordering cost (module docstring); lower is tried first.
    """

    closing_yaw: float
    grasp: np.ndarray
    pregrasp: np.ndarray
    object_in_ee: np.ndarray
    span: float
    tilt: float = 0.0
    family: GraspFamily = GraspFamily.TOP
    cost: float = 0.0

    @property
    def label(self) -> str:
        """Short description for messages, e.g. 'side grasp at yaw 90°'."""
        return f"{self.family.value} grasp at yaw {math.degrees(self.closing_yaw):.0f}°"


def top_down_rotation(closing_yaw: float, tilt: float = 0.0) -> np.ndarray:
    """End-effector rotation pointing down with the fingers closing along `closing_yaw`.

    A non-zero `tilt` turns the approach about the closing axis towards the end-effector's x axis, (-sin, cos, 0)
    of the closing yaw; the fingers still close horizontally.
    """
    c, s = np.cos(closing_yaw), np.sin(closing_yaw)
    rot = np.array([[-s, c, 0.0], [c, s, 0.0], [0.0, 0.0, -1.0]])
    if tilt == 0.0:
        return rot
    ct, st = np.cos(tilt), np.sin(tilt)
    return rot @ np.array([[ct, 0.0, st], [0.0, 1.0, 0.0], [-st, 0.0, ct]])


def side_rotation(closing_yaw: float) -> np.ndarray:
    """End-effector rotation approaching horizontally, fingers closing along `closing_yaw`.

    The approach is the closing axis turned a quarter turn clockwise seen from above: (sin, -cos, 0).
    """
    c, s = np.cos(closing_yaw), np.sin(closing_yaw)
    y = np.array([c, s, 0.0])
    z = np.array([s, -c, 0.0])
    return np.column_stack([np.cross(y, z), y, z])


def _rz(yaw: float) -> np.ndarray:
    c, s = np.cos(yaw), np.sin(yaw)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _pose(rotation: np.ndarray, translation: np.ndarray) -> np.ndarray:
    out = np.eye(4)
    out[:3, :3] = rotation
    out[:3, 3] = translation
    return out


def lifted(pose: np.ndarray, dz: float) -> np.ndarray:
    """The pose moved by dz metres along world z."""
    out = pose.copy()
    out[2, 3] += dz
    return out


def object_pose(detection: Detection, spec: ObjectSpec) -> np.ndarray:
    """(4, 4) world pose of the object's centre from its detected top face and its catalogue height."""
    x, y, z = detection.position
    return _pose(_rz(detection.yaw), np.array([x, y, z - spec.height / 2]))


def _wrap(angle: float) -> float:
    """Angle in [-pi, pi)."""
    return (angle + np.pi) % (2 * np.pi) - np.pi


def _wrap_near(angle: float, reference: float) -> float:
    """The angle ± kπ closest to the reference (a parallel gripper is symmetric under half turns)."""
    return reference + (angle - reference + np.pi / 2) % np.pi - np.pi / 2


def _extent_along(spec: ObjectSpec, obj_yaw: float, direction_yaw: float) -> float:
    """The object's full horizontal extent along a world direction (boxes: projected; cylinders: diameter)."""
    if spec.shape != "box":
        return float(spec.size[0])
    d = direction_yaw - obj_yaw
    return float(abs(np.cos(d)) * spec.size[0] + abs(np.sin(d)) * spec.size[1])


def grasp_candidates(
    detection: Detection,
    spec: ObjectSpec,
    params: GraspParams = GraspParams(),
    preferred_yaw: float = -np.pi / 2,
    opening: float | None = None,
) -> list[GraspCandidate]:
    """Top, tilted and side grasps of a detected object, cheapest first (see the module docstring).

    Args:
        detection: The object's top-face centre and yaw.
        spec: Its catalogue model.
        params: Generation settings and distances.
        preferred_yaw: Closing-axis yaw (rad) of the arm's home pose.
        opening: The gripper's full opening (m); None keeps every span.
    """
    top = np.asarray(detection.position, dtype=float)
    height = spec.height
    support = top[2] - height
    obj_world = object_pose(detection, spec)
    radial = float(np.arctan2(top[1], top[0]))  # from the robot towards the object
    out: list[GraspCandidate] = []

    # Closing axes of the top family (modulo half turns): cylinders over the sweep, boxes across each face pair.
    if spec.shape == "box":
        axes = [detection.yaw, detection.yaw + np.pi / 2]
    else:
        n = max(1, int(round(np.pi / params.yaw_step)))
        axes = [radial + np.pi / 2 + k * np.pi / n for k in range(n)]
    depth = float(np.clip(height - params.min_clearance, 0.0, params.max_depth))
    top_point = top - np.array([0.0, 0.0, depth])
    shallow = params.shallow_depth > 0 and params.shallow_depth < depth - 0.005
    shallow_point = top - np.array([0.0, 0.0, params.shallow_depth])

    def add(
        rotation: np.ndarray,
        point: np.ndarray,
        yaw: float,
        tilt: float,
        family: GraspFamily,
        extra: float = 0.0,
    ) -> None:
        grasp = _pose(rotation, point)
        pregrasp = grasp.copy()
        pregrasp[:3, 3] -= grasp[:3, 2] * params.approach
        span = _extent_along(spec, detection.yaw, yaw)
        wrist = abs(_wrap(yaw - preferred_yaw)) / (np.pi / 2)
        fc = params.family_cost[list(GraspFamily).index(family)]
        cost = fc + params.wrist_weight * wrist + params.tilt_weight * abs(tilt)
        cost += params.span_weight * span / (opening or 0.08) + extra
        out.append(
            GraspCandidate(
                closing_yaw=float(yaw),
                grasp=grasp,
                pregrasp=pregrasp,
                object_in_ee=np.linalg.inv(grasp) @ obj_world,
                span=span,
                tilt=float(tilt),
                family=family,
                cost=float(cost),
            )
        )

    for axis in axes:
        for yaw in (_wrap(axis), _wrap(axis + np.pi)):  # both wrist angles
            add(top_down_rotation(yaw), top_point, yaw, 0.0, GraspFamily.TOP)
            if shallow:
                add(top_down_rotation(yaw), shallow_point, yaw, 0.0, GraspFamily.TOP, params.shallow_cost)
            lean = np.array([-np.sin(yaw), np.cos(yaw), 0.0])  # where a positive tilt points the approach
            if spec.shape == "box":
                half = _extent_along(spec, detection.yaw, yaw + np.pi / 2) / 2
                for off in params.offsets:
                    if off <= 0 or off > half - params.offset_margin:
                        continue
                    for sign in (1.0, -1.0):
                        point = top_point + sign * off * lean
                        extra = params.offset_weight * off / half
                        add(top_down_rotation(yaw), point, yaw, 0.0, GraspFamily.TOP, extra)
            for t in params.tilts:
                for tilt in (t, -t):
                    # Never lean towards the robot: the hand would come from behind the object.
                    if np.sign(tilt) * (lean[:2] @ top[:2]) < -1e-9:
                        continue
                    add(top_down_rotation(yaw, tilt), top_point, yaw, tilt, GraspFamily.TILTED)

    if params.side_grasps:
        z_lo = support + params.side_min_height
        z_hi = top[2] - params.side_top_margin
        if z_lo <= z_hi:
            z = float(np.clip(support + params.side_height_fraction * height, z_lo, z_hi))
            if spec.shape == "box":
                approaches = [detection.yaw + k * np.pi / 2 for k in range(4)]
            else:
                n = max(1, int(round(params.side_max_angle / params.yaw_step)))
                approaches = [radial + k * params.side_max_angle / n for k in range(-n, n + 1)]
            for phi in approaches:
                if np.cos(phi - radial) < np.cos(params.side_max_angle) - 1e-9:
                    continue
                d = np.array([np.cos(phi), np.sin(phi), 0.0])
                half = _extent_along(spec, detection.yaw, phi) / 2
                depths = [(min(half, params.side_depth), 0.0)]
                if 0 < params.side_shallow_depth < depths[0][0] - 1e-9:
                    depths.append((params.side_shallow_depth, params.shallow_cost))
                closing = phi + np.pi / 2  # side_rotation(closing) approaches along (sin, -cos) = d
                for depth_in, extra in depths:
                    point = np.array([top[0], top[1], z]) - d * (half - depth_in)
                    for yaw in (_wrap(closing), _wrap(closing + np.pi)):
                        rot = side_rotation(_wrap(closing))
                        if yaw != _wrap(closing):  # the other wrist angle: fingers swapped, x axis flipped
                            rot = rot @ np.diag([-1.0, -1.0, 1.0])
                        add(rot, point, yaw, 0.0, GraspFamily.SIDE, extra)

    limit = None if opening is None else opening - params.opening_margin
    if limit is not None:
        fitting = [c for c in out if c.span <= limit]
        if fitting:
            out = fitting
        else:
            narrowest = min(c.span for c in out)
            out = [c for c in out if c.span <= narrowest + 1e-6]
    out.sort(key=lambda c: c.cost)
    return out


def place_pose(
    spot: tuple[float, float, float],
    spec: ObjectSpec,
    object_in_ee: np.ndarray,
    grasp: np.ndarray,
    turn: float,
    params: GraspParams = GraspParams(),
) -> np.ndarray:
    """End-effector pose that holds the object upright just above the table at `spot` (x, y, table top z).

    The hand keeps its grasp orientation (`grasp`, a (4, 4) or (3, 3) pose) turned by `turn` rad about world z,
    so the object, upright when grasped, stays upright.
    """
    x, y, top = spot
    ee = _pose(_rz(turn) @ np.asarray(grasp)[:3, :3], np.zeros(3))
    # Where the object's centre would be with the hand at the origin, then shift so it lands on the spot.
    centre = (ee @ object_in_ee)[:3, 3]
    target_centre = np.array([x, y, top + params.place_drop + spec.height / 2])
    ee[:3, 3] = target_centre - centre
    return ee
