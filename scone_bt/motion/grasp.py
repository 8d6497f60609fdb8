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
from dataclasses import dataclass
from enum import Enum
from functools import cached_property

import numpy as np

from scone_bt.config import ObjectSpec
from scone_bt.config.catalogue import Shape
from scone_bt.config.grasp import DEFAULT_OPENING_M, GraspParams
from scone_bt.geometry import wrap_angle
from scone_bt.motion.model import inverse_small
from scone_bt.perception.types import Detection

__all__ = [
    "GraspFamily",
    "GraspCandidate",
    "grasp_candidates",
    "top_down_rotation",
    "side_rotation",
    "place_pose",
    "object_pose",
    "lifted",
]


_DEFAULT_PARAMS = GraspParams()
"""The defaults (frozen, so one instance serves every call)."""


class GraspFamily(str, Enum):  # noqa: UP042 (str() of members is used in messages)
    """How the hand approaches the object."""

    TOP = "top"
    TILTED = "tilted"
    SIDE = "side"
    PINCH = "pinch"  # a flat pack's edge, the fingers closing vertically (motion.slide; no cost of its own)


@dataclass(frozen=True, eq=False)
class GraspCandidate:
    """One way to grasp the target.

    Its poses (`grasp`, `pregrasp`, `object_in_ee`) are made when first asked for: a plan examines a few of the
    ~50 candidates it generates (they took a millisecond a plan, made up front).

    Attributes:
        closing_yaw: World direction of the fingers' closing axis, radians.
        rotation: (3, 3) end-effector orientation at the grasp, world frame.
        point: (3,) end-effector position at the grasp, world frame, metres.
        approach: Distance (m) back along the approach from the grasp to the pre-grasp.
        object_pose: (4, 4) pose of the object's centre, world frame.
        span: Object extent between the fingers, metres.
        tilt: Rotation (rad) of a top approach about the closing axis, away from vertical (0: top-down).
        family: Top, tilted or side.
        cost: Ordering cost (module docstring); lower is tried first.
    """

    closing_yaw: float
    rotation: np.ndarray
    point: np.ndarray
    approach: float
    object_pose: np.ndarray
    span: float
    tilt: float = 0.0
    family: GraspFamily = GraspFamily.TOP
    cost: float = 0.0

    @cached_property
    def grasp(self) -> np.ndarray:
        """(4, 4) end-effector pose at the grasp, world frame."""
        return _pose(self.rotation, self.point)

    @cached_property
    def pregrasp(self) -> np.ndarray:
        """(4, 4) end-effector pose `approach` metres back along the approach."""
        out = self.grasp.copy()
        out[:3, 3] -= self.grasp[:3, 2] * self.approach
        return out

    @cached_property
    def object_in_ee(self) -> np.ndarray:
        """(4, 4) pose of the object's centre in the end-effector frame while held."""
        return inverse_small(self.grasp) @ self.object_pose

    @property
    def label(self) -> str:
        """Short description for messages, e.g. 'side grasp at yaw 90°'."""
        return f"{self.family.value} grasp at yaw {math.degrees(self.closing_yaw):.0f}°"


_FAMILY_INDEX: dict[GraspFamily, int] = {
    family: k for k, family in enumerate(GraspFamily) if family is not GraspFamily.PINCH
}
"""Each family's place in `GraspParams.family_cost`."""


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
    c, s = float(np.cos(closing_yaw)), float(np.sin(closing_yaw))
    y = (c, s, 0.0)
    z = (s, -c, 0.0)
    x = _cross(y, z)
    return np.array([[x[0], y[0], z[0]], [x[1], y[1], z[1]], [x[2], y[2], z[2]]])


def _cross(a: tuple[float, float, float], b: tuple[float, float, float]) -> tuple[float, float, float]:
    """a x b with np.cross's products and differences, on plain floats (np.cross took 20 us per candidate)."""
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


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


def _wrap_near(angle: float, reference: float) -> float:
    """The angle ± kπ closest to the reference (a parallel gripper is symmetric under half turns)."""
    return reference + wrap_angle(angle - reference, np.pi)


def _extent_along(spec: ObjectSpec, obj_yaw: float, direction_yaw: float) -> float:
    """The object's full horizontal extent along a world direction (boxes: projected; cylinders: diameter)."""
    if spec.shape != Shape.BOX:
        return float(spec.size[0])
    d = direction_yaw - obj_yaw
    return float(abs(np.cos(d)) * spec.size[0] + abs(np.sin(d)) * spec.size[1])


@dataclass(frozen=True, eq=False)
class _CandidateMaker:
    """Makes the candidates of one detected object, each costed as the module docstring says.

    Attributes:
        spec: The object's catalogue model.
        object_yaw: Its detected yaw, radians.
        object_pose: (4, 4) pose of its centre, world frame.
        params: Generation settings and cost weights.
        preferred_yaw: Closing-axis yaw (rad) of the arm's home pose.
        opening: The gripper's full opening (m); None costs spans against DEFAULT_OPENING_M (the Panda's).
    """

    spec: ObjectSpec
    object_yaw: float
    object_pose: np.ndarray
    params: GraspParams
    preferred_yaw: float
    opening: float | None

    def __call__(
        self,
        rotation: np.ndarray,
        point: np.ndarray,
        yaw: float,
        tilt: float,
        family: GraspFamily,
        extra: float = 0.0,
    ) -> GraspCandidate:
        params = self.params
        span = _extent_along(self.spec, self.object_yaw, yaw)
        wrist = abs(wrap_angle(yaw - self.preferred_yaw)) / (np.pi / 2)
        fc = params.family_cost[_FAMILY_INDEX[family]]
        cost = fc + params.wrist_weight * wrist + params.tilt_weight * abs(tilt)
        cost += params.span_weight * span / (self.opening or DEFAULT_OPENING_M) + extra
        return GraspCandidate(
            closing_yaw=float(yaw),
            rotation=rotation,
            point=np.asarray(point, dtype=float),
            approach=params.approach,
            object_pose=self.object_pose,
            span=span,
            tilt=float(tilt),
            family=family,
            cost=float(cost),
        )


def grasp_candidates(
    detection: Detection,
    spec: ObjectSpec,
    params: GraspParams = _DEFAULT_PARAMS,
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
    make = _CandidateMaker(spec, detection.yaw, object_pose(detection, spec), params, preferred_yaw, opening)
    radial = float(np.arctan2(top[1], top[0]))  # from the robot towards the object
    out = _top_grasps(make, top, _top_axes(detection, spec, params, radial))
    if params.side_grasps:
        out += _side_grasps(make, top, radial)
    out = _fitting(out, opening, params)
    out.sort(key=lambda c: c.cost)
    return out


def _top_axes(detection: Detection, spec: ObjectSpec, params: GraspParams, radial: float) -> list[float]:
    """Closing axes of the top family (modulo half turns): cylinders over the sweep, boxes across each face pair."""
    if spec.shape == Shape.BOX:
        return [detection.yaw, detection.yaw + np.pi / 2]
    n = max(1, int(round(np.pi / params.yaw_step)))
    return [radial + np.pi / 2 + k * np.pi / n for k in range(n)]


def _top_grasps(make: _CandidateMaker, top: np.ndarray, axes: list[float]) -> list[GraspCandidate]:
    """Top grasps about each axis at both wrist angles: centred, shallow, off-centre (boxes), then tilted."""
    spec, params = make.spec, make.params
    depth = float(np.clip(spec.height - params.min_clearance, 0.0, params.max_depth))
    top_point = top - np.array([0.0, 0.0, depth])
    shallow = params.shallow_depth > 0 and params.shallow_depth < depth - 0.005
    shallow_point = top - np.array([0.0, 0.0, params.shallow_depth])
    out: list[GraspCandidate] = []
    for axis in axes:
        for yaw in (wrap_angle(axis), wrap_angle(axis + np.pi)):  # both wrist angles
            out.append(make(top_down_rotation(yaw), top_point, yaw, 0.0, GraspFamily.TOP))
            if shallow:
                out.append(
                    make(
                        top_down_rotation(yaw), shallow_point, yaw, 0.0, GraspFamily.TOP, params.shallow_cost
                    )
                )
            lean = np.array([-np.sin(yaw), np.cos(yaw), 0.0])  # where a positive tilt points the approach
            if spec.shape == Shape.BOX:
                out += _offset_grasps(make, top_point, yaw, lean)
            for t in params.tilts:
                for tilt in (t, -t):
                    # Never lean towards the robot: the hand would come from behind the object.
                    if np.sign(tilt) * (lean[:2] @ top[:2]) < -1e-9:
                        continue
                    out.append(make(top_down_rotation(yaw, tilt), top_point, yaw, tilt, GraspFamily.TILTED))
    return out


def _offset_grasps(
    make: _CandidateMaker, top_point: np.ndarray, yaw: float, lean: np.ndarray
) -> list[GraspCandidate]:
    """A box's top grasps at `yaw` moved off its centre both ways along `lean` (perpendicular to the closing)."""
    params = make.params
    half = _extent_along(make.spec, make.object_yaw, yaw + np.pi / 2) / 2
    out: list[GraspCandidate] = []
    for off in params.offsets:
        if off <= 0 or off > half - params.offset_margin:
            continue
        for sign in (1.0, -1.0):
            point = top_point + sign * off * lean
            extra = params.offset_weight * off / half
            out.append(make(top_down_rotation(yaw), point, yaw, 0.0, GraspFamily.TOP, extra))
    return out


def _side_grasps(make: _CandidateMaker, top: np.ndarray, radial: float) -> list[GraspCandidate]:
    """Horizontal grasps from the faces that look towards the robot, at both wrist angles and each depth."""
    spec, params = make.spec, make.params
    height = spec.height
    support = top[2] - height
    z_lo = support + params.side_min_height
    z_hi = top[2] - params.side_top_margin
    if z_lo > z_hi:
        return []
    z = float(np.clip(support + params.side_height_fraction * height, z_lo, z_hi))
    if spec.shape == Shape.BOX:
        approaches = [make.object_yaw + k * np.pi / 2 for k in range(4)]
    else:
        n = max(1, int(round(params.side_max_angle / params.yaw_step)))
        approaches = [radial + k * params.side_max_angle / n for k in range(-n, n + 1)]
    out: list[GraspCandidate] = []
    for phi in approaches:
        if np.cos(phi - radial) < np.cos(params.side_max_angle) - 1e-9:
            continue
        d = np.array([np.cos(phi), np.sin(phi), 0.0])
        half = _extent_along(spec, make.object_yaw, phi) / 2
        depths = [(min(half, params.side_depth), 0.0)]
        if 0 < params.side_shallow_depth < depths[0][0] - 1e-9:
            depths.append((params.side_shallow_depth, params.shallow_cost))
        closing = phi + np.pi / 2  # side_rotation(closing) approaches along (sin, -cos) = d
        for depth_in, extra in depths:
            point = np.array([top[0], top[1], z]) - d * (half - depth_in)
            for yaw in (wrap_angle(closing), wrap_angle(closing + np.pi)):
                rot = side_rotation(wrap_angle(closing))
                if yaw != wrap_angle(closing):  # the other wrist angle: fingers swapped, x axis flipped
                    rot = rot @ np.diag([-1.0, -1.0, 1.0])
                out.append(make(rot, point, yaw, 0.0, GraspFamily.SIDE, extra))
    return out


def _fitting(cands: list[GraspCandidate], opening: float | None, params: GraspParams) -> list[GraspCandidate]:
    """The candidates whose span fits the opening; if none does, the narrowest (the physics decides)."""
    if opening is None:
        return cands
    limit = opening - params.opening_margin
    fitting = [c for c in cands if c.span <= limit]
    if fitting:
        return fitting
    narrowest = min(c.span for c in cands)
    return [c for c in cands if c.span <= narrowest + 1e-6]


def place_pose(
    spot: tuple[float, float, float],
    spec: ObjectSpec,
    object_in_ee: np.ndarray,
    grasp: np.ndarray,
    turn: float,
    params: GraspParams = _DEFAULT_PARAMS,
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
