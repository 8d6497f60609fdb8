"""Scoring detections against the simulator's ground truth (benchmarks and tests only).

This module reads ground truth from the kitchen (PyBullet's, or another engine's given its ray test, e.g.
`world.mj_truth.first_bodies`); the robot's own stages never import it. An object counts as
unoccluded when rays from the camera reach every sample point of its marker (corners and centre) on the object's
own collision shape, and every sample point projects inside the image.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, cast

import numpy as np

from scone_bt.config.markers import lid_marker
from scone_bt.geometry import wrap_angle
from scone_bt.perception.camera import Camera, project
from scone_bt.perception.types import Detection

if TYPE_CHECKING:
    from scone_bt.world import Kitchen

__all__ = ["GroundTruth", "FrameScore", "ground_truth", "score_frame", "summarise"]

MATCH_RADIUS_M = 0.03
"""A detection further than this from its object's true top centre counts as a false positive."""


@dataclass(frozen=True)
class GroundTruth:
    """One spawned object as the simulator knows it.

    Attributes:
        name: Catalogue name.
        top_centre: Centre of the top face in the world frame, metres.
        yaw: Rotation about world z, radians.
        visible_fraction: Share of the marker's sample points that the camera sees (0-1).
        in_view: Whether every sample point projects inside the image.
    """

    name: str
    top_centre: tuple[float, float, float]
    yaw: float
    visible_fraction: float
    in_view: bool

    @property
    def unoccluded(self) -> bool:
        return self.in_view and self.visible_fraction >= 1.0


@dataclass(frozen=True)
class FrameScore:
    """Detections of one frame matched to the truth.

    Attributes:
        true_positives: Names detected within MATCH_RADIUS_M of their true top centre.
        false_positives: Detections of absent objects or too far from the truth.
        missed_unoccluded: Unoccluded objects that were not correctly detected.
        unoccluded: Number of unoccluded objects.
        objects: Number of objects in the kitchen.
        position_errors: Euclidean 3D error of each true positive, metres.
        yaw_errors: Absolute yaw error of each true positive, radians.
    """

    true_positives: tuple[str, ...]
    false_positives: tuple[str, ...]
    missed_unoccluded: tuple[str, ...]
    unoccluded: int
    objects: int
    position_errors: tuple[float, ...]
    yaw_errors: tuple[float, ...]


RayTest = Callable[[Any, np.ndarray, np.ndarray], list[int]]
"""(kitchen, eye, (n, 3) points) → the body each segment from the eye to a point hits first (-1: none)."""


def _first_bodies(kitchen: Kitchen, eye: np.ndarray, points: np.ndarray, rays: RayTest | None) -> list[int]:
    """The body each ray from ``eye`` to a point hits first (-1: none): PyBullet's, or the engine's ``rays``."""
    if rays is not None:
        return rays(kitchen, eye, points)
    bc = kitchen.bc
    return [hit[0] for hit in bc.rayTestBatch([eye.tolist()] * len(points), points.tolist())]


def _rotation(quaternion: Sequence[float]) -> np.ndarray:
    """(3, 3) rotation of a unit quaternion (x, y, z, w)."""
    x, y, z, w = (float(c) for c in quaternion)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def _pose(kitchen: Kitchen, name: str) -> tuple[np.ndarray, np.ndarray]:
    """A product's position and rotation matrix now (ground truth, either engine)."""
    bc = getattr(kitchen, "bc", None)
    if bc is None:  # another engine's kitchen: its ground-truth pose (world.ground_truth.ObjectState)
        state = kitchen.object_state(name)
        return np.asarray(state.position, dtype=float), _rotation(state.orientation)
    pos, orn = bc.getBasePositionAndOrientation(kitchen.objects[name])
    return np.asarray(pos, dtype=float), np.array(bc.getMatrixFromQuaternion(orn)).reshape(3, 3)


def _sample_points(kitchen: Kitchen, name: str) -> tuple[np.ndarray, np.ndarray, float]:
    """Marker corners and centre slightly inside the lid (world), the top centre, and the yaw."""
    spec = kitchen.specs[name]
    marker = lid_marker(spec)
    pos, rot = _pose(kitchen, name)
    half = 0.45 * marker.side
    local = np.array(
        [[0, 0, 0], [-half, half, 0], [half, half, 0], [half, -half, 0], [-half, -half, 0]], float
    )
    local[:, 2] = marker.top_z - 1e-3  # just below the lid, so a ray that reaches it hits this body first
    points = local @ rot.T + np.asarray(pos)
    top = rot @ np.array([0.0, 0.0, marker.top_z]) + np.asarray(pos)
    return points, top, float(np.arctan2(rot[1, 0], rot[0, 0]))


def ground_truth(kitchen: Kitchen, camera: Camera, rays: RayTest | None = None) -> list[GroundTruth]:
    """Truth for every object in the kitchen, as seen from `camera`.

    Args:
        kitchen: The simulated kitchen (PyBullet's, or another engine's with ``rays``).
        camera: The camera whose view is scored.
        rays: The engine's ray test (e.g. `world.mj_truth.first_bodies`); None: PyBullet's.
    """
    out = []
    eye = np.asarray(camera.spec.position, dtype=float)
    for name, body in kitchen.objects.items():
        points, top, yaw = _sample_points(kitchen, name)
        seen = sum(1 for hit in _first_bodies(kitchen, eye, points, rays) if hit == body)
        uv, z = project(points, camera.intrinsics, camera.world_from_camera)
        in_view = bool(
            np.all(z > 0)
            and np.all(uv[:, 0] >= 0)
            and np.all(uv[:, 0] <= camera.spec.width - 1)
            and np.all(uv[:, 1] >= 0)
            and np.all(uv[:, 1] <= camera.spec.height - 1)
        )
        out.append(
            GroundTruth(
                name,
                cast("tuple[float, float, float]", tuple(float(v) for v in top)),
                yaw,
                seen / len(points),
                in_view,
            )
        )
    return out


def _angle_diff(a: float, b: float) -> float:
    return float(abs(wrap_angle(a - b)))


def score_frame(detections: Sequence[Detection], truth: Sequence[GroundTruth]) -> FrameScore:
    """Match detections to the truth by name and distance."""
    by_name = {t.name: t for t in truth}
    tp, fp, errors, yaw_errors = [], [], [], []
    for det in detections:
        t = by_name.get(det.name)
        error = None if t is None else float(np.linalg.norm(np.subtract(det.position, t.top_centre)))
        if t is None or error is None or error > MATCH_RADIUS_M:
            fp.append(det.name)
            continue
        tp.append(det.name)
        errors.append(error)
        yaw_errors.append(_angle_diff(det.yaw, t.yaw))
    unoccluded = [t.name for t in truth if t.unoccluded]
    missed = tuple(n for n in unoccluded if n not in tp)
    return FrameScore(
        tuple(tp), tuple(fp), missed, len(unoccluded), len(truth), tuple(errors), tuple(yaw_errors)
    )


def summarise(scores: Sequence[FrameScore]) -> dict[str, float | int]:
    """Precision, recall (on unoccluded objects and on all objects) and position errors over many frames."""
    tp = sum(len(s.true_positives) for s in scores)
    fp = sum(len(s.false_positives) for s in scores)
    unoccluded = sum(s.unoccluded for s in scores)
    objects = sum(s.objects for s in scores)
    missed = sum(len(s.missed_unoccluded) for s in scores)
    errors = np.array([e for s in scores for e in s.position_errors])
    yaw = np.array([e for s in scores for e in s.yaw_errors])
    return {
        "frames": len(scores),
        "detections": tp + fp,
        "objects": objects,
        "unoccluded_objects": unoccluded,
        "recall_unoccluded": (unoccluded - missed) / unoccluded if unoccluded else float("nan"),
        "recall_all": tp / objects if objects else float("nan"),
        "precision": tp / (tp + fp) if tp + fp else float("nan"),
        "position_error_median_m": float(np.median(errors)) if errors.size else float("nan"),
        "position_error_p95_m": float(np.percentile(errors, 95)) if errors.size else float("nan"),
        "yaw_error_median_deg": float(np.degrees(np.median(yaw))) if yaw.size else float("nan"),
    }
