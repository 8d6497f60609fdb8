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
        max_carry_tilt: Largest tilt of the hand from vertical while carrying, radians.
    """

    approach: float = 0.10
    lift: float = 0.10
    max_depth: float = 0.03
    min_clearance: float = 0.015
    place_drop: float = 0.006
    retreat: float = 0.10
    max_carry_tilt: float = 0.35


@dataclass(frozen=True, eq=False)
class GraspCandidate:
    """One way to grasp the target.

    Attributes:
        closing_yaw: World direction of the fingers' closing axis, radians.
        grasp: (4, 4) end-effector pose at the grasp, world frame.
        pregrasp: (4, 4) end-effector pose above the grasp.
        object_in_ee: (4, 4) pose of the object's centre in the end-effector frame while held.
        span: Object extent between the fingers, metres.
    """

    closing_yaw: float
    grasp: np.ndarray
    pregrasp: np.ndarray
    object_in_ee: np.ndarray
    span: float


def top_down_rotation(closing_yaw: float) -> np.ndarray:
    """End-effector rotation pointing straight down with the fingers closing along `closing_yaw`."""
    c, s = np.cos(closing_yaw), np.sin(closing_yaw)
    return np.array([[-s, c, 0.0], [c, s, 0.0], [0.0, 0.0, -1.0]])


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
    for yaw in ordered:
        grasp = _pose(top_down_rotation(yaw), grasp_point)
        out.append(
            GraspCandidate(
                closing_yaw=float(yaw),
                grasp=grasp,
                pregrasp=lifted(grasp, params.approach),
                object_in_ee=np.linalg.inv(grasp) @ obj_world,
                span=span,
            )
        )
    return out


def place_pose(
    spot: tuple[float, float, float],
    spec: ObjectSpec,
    object_in_ee: np.ndarray,
    closing_yaw: float,
    params: GraspParams = GraspParams(),
) -> np.ndarray:
    """End-effector pose that holds the object upright just above the table at `spot` (x, y, table top z)."""
    x, y, top = spot
    ee = _pose(top_down_rotation(closing_yaw), np.zeros(3))
    # Where the object's centre would be with the hand at the origin, then shift so it lands on the spot.
    centre = (ee @ object_in_ee)[:3, 3]
    target_centre = np.array([x, y, top + params.place_drop + spec.height / 2])
    ee[:3, 3] = target_centre - centre
    return ee
