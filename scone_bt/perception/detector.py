"""Finds the catalogue's objects in an RGB-D frame by the ArUco markers on their lids (OpenCV).

The detector sees only the frame and the catalogue (names, sizes, marker ids: what a real robot knows about the
tags it printed). Each marker is decoded in the colour image, its lid plane is fitted to the depth pixels inside
it, and its corners are intersected with that plane. Misses come from the image alone: a marker that is partly
hidden, too small, seen at a grazing angle or drowned in noise does not decode or fails the geometry checks.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from scone_bt.config import Catalogue, ObjectSpec
from scone_bt.config.markers import ARUCO_DICTIONARY, MARKER_CELLS, LidMarker, lid_marker
from scone_bt.errors import ConfigError
from scone_bt.perception.camera import project
from scone_bt.perception.types import Detection, Frame

__all__ = ["DetectorOptions", "Detector", "UNTRACKED"]

UNTRACKED = -1
"""track_id of a detection that has not been through a Tracker."""


@dataclass(frozen=True)
class DetectorOptions:
    """Thresholds of the marker detector.

    Attributes:
        max_tilt_deg: Largest angle between a lid's fitted normal and world up, degrees; steeper planes are
            rejected (a marker is only printed on lids).
        max_view_deg: Largest angle between the lid normal and the line of sight, degrees (grazing views).
        size_tolerance: Largest relative difference between the measured marker side (from depth) and the side
            printed on that object; guards against misread ids.
        min_depth_pixels: Fewest valid depth pixels inside a marker needed to fit its plane.
        depth_outlier_m: Depth pixels farther than this from the marker's median depth are ignored, metres.
        error_correction_rate: ArUco bit-error correction (0-1); lower is stricter.
        full_confidence_cell_px: Marker cell size in pixels at which the resolution no longer limits confidence.
    """

    max_tilt_deg: float = 35.0
    max_view_deg: float = 75.0
    size_tolerance: float = 0.2
    min_depth_pixels: int = 12
    depth_outlier_m: float = 0.015
    error_correction_rate: float = 0.35
    full_confidence_cell_px: float = 5.0

    def __post_init__(self) -> None:
        if not 0 < self.max_tilt_deg <= 90 or not 0 < self.max_view_deg <= 90:
            raise ConfigError("detector: max_tilt_deg and max_view_deg must be in (0, 90]")
        if not 0 < self.size_tolerance < 1:
            raise ConfigError("detector: size_tolerance must be in (0, 1)")
        if not 0 <= self.error_correction_rate <= 1:
            raise ConfigError("detector: error_correction_rate must be in [0, 1]")
        if self.min_depth_pixels < 3 or self.depth_outlier_m <= 0 or self.full_confidence_cell_px <= 0:
            raise ConfigError(
                "detector: min_depth_pixels >= 3, depth_outlier_m > 0, full_confidence_cell_px > 0"
            )


@dataclass(frozen=True)
class _Lid:
    """A marker's lid plane and corners in the camera frame (metres)."""

    normal: np.ndarray  # unit, pointing toward the camera
    centre: np.ndarray
    corners: np.ndarray  # (4, 3)


class Detector:
    """Names catalogue objects in a frame and locates the centre of each one's top face in the world frame.

    Args:
        catalogue: The objects that may appear, with their marker ids and sizes.
        options: Detection thresholds.
    """

    def __init__(self, catalogue: Catalogue, options: DetectorOptions | None = None) -> None:
        self.options = options or DetectorOptions()
        self.catalogue = catalogue
        self._by_id: dict[int, tuple[ObjectSpec, LidMarker]] = {
            spec.marker_id: (spec, lid_marker(spec)) for spec in catalogue.objects
        }
        params = cv2.aruco.DetectorParameters()
        params.cornerRefinementMethod = cv2.aruco.CORNER_REFINE_SUBPIX
        params.errorCorrectionRate = self.options.error_correction_rate
        # Small, aliased markers (three or four pixels per cell): more threshold windows and finer bit sampling
        # find most of the markers that OpenCV's defaults miss.
        params.adaptiveThreshWinSizeStep = 4
        params.perspectiveRemovePixelPerCell = 8
        dictionary = cv2.aruco.getPredefinedDictionary(getattr(cv2.aruco, ARUCO_DICTIONARY))
        self._aruco = cv2.aruco.ArucoDetector(dictionary, params)

    def detect(self, frame: Frame) -> list[Detection]:
        """Detections in this frame, one per object at most, sorted by name; track_id is UNTRACKED."""
        gray = cv2.cvtColor(frame.rgb, cv2.COLOR_RGB2GRAY)
        best: dict[str, Detection] = {}
        for quad, marker_id in self._find_markers(gray):
            entry = self._by_id.get(marker_id)
            if entry is None:
                continue
            detection = self._locate(frame, quad, *entry)
            if detection is not None and (
                detection.name not in best or detection.confidence > best[detection.name].confidence
            ):
                best[detection.name] = detection
        return [best[name] for name in sorted(best)]

    def _find_markers(self, gray: np.ndarray) -> list[tuple[np.ndarray, int]]:
        """Decoded markers as ((4, 2) corner pixels, id)."""
        corners, ids, _ = self._aruco.detectMarkers(gray)
        if ids is None:
            return []
        return [
            (q.reshape(4, 2).astype(np.float64), int(i)) for q, i in zip(corners, ids.ravel(), strict=True)
        ]

    # ----------------------------------------------------------------------------------------- geometry
    def _locate(
        self, frame: Frame, quad: np.ndarray, spec: ObjectSpec, marker: LidMarker
    ) -> Detection | None:
        opt = self.options
        lid = _fit_lid(frame, quad, opt.min_depth_pixels, opt.depth_outlier_m)
        if lid is None:
            return None
        rot, origin = frame.world_from_camera[:3, :3], frame.world_from_camera[:3, 3]
        up = rot @ lid.normal
        tilt = np.degrees(np.arccos(np.clip(up[2], -1.0, 1.0)))
        sight = lid.centre / np.linalg.norm(lid.centre)
        view = np.degrees(np.arccos(np.clip(-sight @ lid.normal, -1.0, 1.0)))
        if tilt > opt.max_tilt_deg or view > opt.max_view_deg:
            return None
        sides = np.linalg.norm(lid.corners - np.roll(lid.corners, -1, axis=0), axis=1)
        size_error = abs(float(np.mean(sides)) / marker.side - 1.0)
        if size_error > opt.size_tolerance:
            return None

        top = rot @ lid.centre + origin - marker.lift * up
        c = lid.corners @ rot.T
        x_axis = (c[1] - c[0]) + (c[2] - c[3])  # the marker's x axis is the body's +x axis
        yaw = float(np.arctan2(x_axis[1], x_axis[0]))

        cell_px = np.sqrt(cv2.contourArea(quad.astype(np.float32))) / MARKER_CELLS
        resolution = min(1.0, cell_px / opt.full_confidence_cell_px)
        obliqueness = min(1.0, np.cos(np.radians(view)) / np.cos(np.radians(60.0)))
        agreement = 1.0 - size_error / opt.size_tolerance
        confidence = float(np.clip(resolution * obliqueness * (0.5 + 0.5 * agreement), 0.0, 1.0))

        return Detection(
            name=spec.name,
            track_id=UNTRACKED,
            position=(float(top[0]), float(top[1]), float(top[2])),
            yaw=yaw,
            confidence=confidence,
            bbox=_object_bbox(frame, spec, top, yaw, up),
        )


def _fit_lid(frame: Frame, quad: np.ndarray, min_pixels: int, outlier_m: float) -> _Lid | None:
    """Fit the lid plane to the depth pixels inside the marker and intersect the corner rays with it."""
    h, w = frame.depth.shape
    centre_px = _diagonal_intersection(quad)
    if centre_px is None:
        return None
    # Shrink the quad toward its centre: pixels on the marker's edge may belong to whatever is behind it.
    inner = centre_px + 0.8 * (quad - centre_px)
    x0, y0 = np.floor(inner.min(axis=0)).astype(int)
    x1, y1 = np.ceil(inner.max(axis=0)).astype(int)
    x0, y0, x1, y1 = max(x0, 0), max(y0, 0), min(x1, w - 1), min(y1, h - 1)
    if x1 < x0 or y1 < y0:
        return None
    mask = np.zeros((y1 - y0 + 1, x1 - x0 + 1), np.uint8)
    cv2.fillConvexPoly(mask, np.rint(inner - (x0, y0)).astype(np.int32), 1)
    vs, us = np.nonzero(mask)
    us, vs = us + x0, vs + y0
    z = frame.depth[vs, us].astype(np.float64)
    keep = np.isfinite(z) & (z > 0)
    if keep.sum() < min_pixels:
        return None
    keep &= np.abs(z - np.median(z[keep])) < outlier_m
    if keep.sum() < min_pixels:
        return None
    k_inv = np.linalg.inv(frame.intrinsics)
    pts = (k_inv @ np.stack([us[keep], vs[keep], np.ones(keep.sum())])).T * z[keep, None]
    mean = pts.mean(axis=0)
    _, _, vt = np.linalg.svd(pts - mean, full_matrices=False)
    normal = vt[2]
    if normal @ mean > 0:  # face the camera
        normal = -normal

    def on_plane(pixels: np.ndarray) -> np.ndarray | None:
        rays = (k_inv @ np.column_stack([pixels, np.ones(len(pixels))]).T).T
        denom = rays @ normal
        if np.any(np.abs(denom) < 1e-6):
            return None
        return rays * ((mean @ normal) / denom)[:, None]

    corners = on_plane(quad)
    centre = on_plane(centre_px[None, :])
    if corners is None or centre is None:
        return None
    return _Lid(normal=normal, centre=centre[0], corners=corners)


def _diagonal_intersection(quad: np.ndarray) -> np.ndarray | None:
    """Image of the marker's centre: where its diagonals cross (exact under perspective)."""
    p, r = quad[0], quad[2] - quad[0]
    q, s = quad[1], quad[3] - quad[1]
    denom = r[0] * s[1] - r[1] * s[0]
    if abs(denom) < 1e-9:
        return None
    t = ((q - p)[0] * s[1] - (q - p)[1] * s[0]) / denom
    return p + t * r


def _object_bbox(
    frame: Frame, spec: ObjectSpec, top: np.ndarray, yaw: float, up: np.ndarray
) -> tuple[int, int, int, int]:
    """Pixel box of the object's catalogue shape hanging below the detected lid, clipped to the image."""
    sx, sy, sz = spec.size
    c, s = np.cos(yaw), np.sin(yaw)
    x_axis, y_axis = np.array([c, s, 0.0]), np.array([-s, c, 0.0])
    corners = [
        top + a * sx / 2 * x_axis + b * sy / 2 * y_axis - d * sz * up
        for a in (-1, 1)
        for b in (-1, 1)
        for d in (0, 1)
    ]
    uv, _ = project(np.array(corners), frame.intrinsics, frame.world_from_camera)
    h, w = frame.depth.shape
    x0, y0 = np.clip(np.floor(uv.min(axis=0)), 0, (w - 1, h - 1)).astype(int)
    x1, y1 = np.clip(np.ceil(uv.max(axis=0)), 0, (w - 1, h - 1)).astype(int)
    return int(x0), int(y0), int(x1), int(y1)
