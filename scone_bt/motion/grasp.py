"""Where the gripper goes: top-down grasp and place poses from a detection and the object's catalogue model.

Pure geometry (numpy only). Convention for every robot's end-effector frame: z points from the hand towards the
fingertips (the approach direction) and y is the axis along which the fingers close.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from scone_bt.config import ObjectSpec
from scone_bt.perception.types import Detection

__all__ = [
    "GraspCandidate",
    "GraspParams",
    "grasp_candidates",
    "top_down_rotation",
    "place_pose",
    "object_pose",
    "lifted",
]


@dataclass(frozen=True)
class GraspParams:
    """Distances of a top-down pick, metres.

    Attributes:
        approach: Height of the pre-grasp pose above the grasp pose.
        lift: How far the object is lifted straight up before carrying it.
        max_depth: Deepest the grasp point goes below the object's top face.
        min_clearance: Minimum height of the grasp point above the supporting surface.
        place_drop: Gap between the object's bottom and the table when it is released.
        retreat: How far the hand backs off upwards after releasing.
        max_carry_tilt: Largest tilt of the carried object from upright, radians.
        reach_tilts: Tilts (rad) of the approach away from the robot, tried after the top-down grasps: a tilted
            hand reaches objects at the back of the shelf that a vertical one cannot.
    """

    approach: float = 0.10
    lift: float = 0.10
    max_depth: float = 0.03
    min_clearance: float = 0.015
    place_drop: float = 0.006
    retreat: float = 0.10
    max_carry_tilt: float = 0.35
    reach_tilts: tuple[float, ...] = (0.45, 0.8)


@dataclass(frozen=True, eq=False)
class GraspCandidate:
    """One way to grasp the target.

    Attributes:
        closing_yaw: World direction of the fingers' closing axis, radians.
        grasp: (4, 4) end-effector pose at the grasp, world frame.
        pregrasp: (4, 4) end-effector pose above the grasp.
        object_in_ee: (4, 4) pose of the object's centre in the end-effector frame while held.
        span: Object extent between the fingers, metres.
        tilt: Rotation (rad) of the approach about the closing axis, away from vertical (0: top-down).
    """

    closing_yaw: float
    grasp: np.ndarray
    pregrasp: np.ndarray
    object_in_ee: np.ndarray
    span: float
    tilt: float = 0.0


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
    return reference + (angle - reference + np.pi / 2) % np.pi - np.pi / 2


def grasp_candidates(
    detection: Detection,
    spec: ObjectSpec,
    params: GraspParams = GraspParams(),
    preferred_yaw: float = -np.pi / 2,
) -> list[GraspCandidate]:
    """Top-down grasps of a detected object, best first.

    Boxes are grasped across their narrow side; cylinders across any diameter, preferring the closing axis along
    world x so that the fingers stay clear of the neighbours on the shelf row (which runs along y).
    `preferred_yaw` picks among symmetric yaws the one nearest the arm's home wrist orientation.
    """
    sx, sy, height = spec.size
    if spec.shape == "box":
        yaws = [detection.yaw if sx <= sy else detection.yaw + np.pi / 2]
        span = min(sx, sy)
    else:
        yaws = [0.0, np.pi / 4, -np.pi / 4, np.pi / 2]
        span = sx
    top = np.asarray(detection.position, dtype=float)
    depth = float(np.clip(height - params.min_clearance, 0.0, params.max_depth))
    grasp_point = top - np.array([0.0, 0.0, depth])
    obj_world = object_pose(detection, spec)
    out = []
    # The yaw nearest the home wrist first; the half-turned one (same grasp, other wrist angle) as a fallback for
    # wrist joint limits.
    ordered = [_wrap_near(y, preferred_yaw) for y in yaws]
    ordered += [y + np.pi if y < preferred_yaw else y - np.pi for y in ordered]
    poses = [(yaw, 0.0) for yaw in ordered]
    # Tilted approaches, away from the robot, for objects at the limit of the arm's reach: the fingers close across
    # the direction from the robot, so only cylinders and boxes whose narrow side lies that way qualify.
    radial = float(np.arctan2(top[1], top[0]))
    tangential = radial - np.pi / 2  # closing yaw whose x axis points away from the robot
    if spec.shape == "cylinder" or abs(np.cos(yaws[0] - tangential)) > np.cos(0.3):
        # A box keeps closing across its narrow side; the lean then follows the box, within 0.3 rad of radial.
        closing = tangential if spec.shape == "cylinder" else _wrap_near(yaws[0], tangential)
        for tilt in params.reach_tilts:
            poses += [(closing, tilt), (closing + np.pi, -tilt)]
    for yaw, tilt in poses:
        grasp = _pose(top_down_rotation(yaw, tilt), grasp_point)
        approach = grasp[:3, 2]
        pregrasp = grasp.copy()
        pregrasp[:3, 3] -= approach * params.approach
        out.append(
            GraspCandidate(
                closing_yaw=float(yaw),
                grasp=grasp,
                pregrasp=pregrasp,
                object_in_ee=np.linalg.inv(grasp) @ obj_world,
                span=span,
                tilt=float(tilt),
            )
        )
    return out


def place_pose(
    spot: tuple[float, float, float],
    spec: ObjectSpec,
    object_in_ee: np.ndarray,
    closing_yaw: float,
    params: GraspParams = GraspParams(),
    tilt: float = 0.0,
) -> np.ndarray:
    """End-effector pose that holds the object upright just above the table at `spot` (x, y, table top z).

    `closing_yaw` and `tilt` orient the hand as in `top_down_rotation`; use the grasp's tilt so the object stays
    upright.
    """
    x, y, top = spot
    ee = _pose(top_down_rotation(closing_yaw, tilt), np.zeros(3))
    # Where the object's centre would be with the hand at the origin, then shift so it lands on the spot.
    centre = (ee @ object_in_ee)[:3, 3]
    target_centre = np.array([x, y, top + params.place_drop + spec.height / 2])
    ee[:3, 3] = target_centre - centre
    return ee
