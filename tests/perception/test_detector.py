"""The detector on synthetic frames: a marker drawn on a flat lid under a camera looking straight down."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from scone_bt.errors import ConfigError
from scone_bt.perception import UNTRACKED, Detector, DetectorOptions, Frame
from scone_bt.world.visuals import DICTIONARY_SIZE, MARKER_CELLS, lid_marker, marker_cells

W, H, F = 640, 480, 600.0
CAMERA_HEIGHT = 0.6  # metres above the floor (z = 0)


def _camera() -> tuple[np.ndarray, np.ndarray]:
    k = np.array([[F, 0, (W - 1) / 2], [0, F, (H - 1) / 2], [0, 0, 1]])
    pose = np.eye(4)
    pose[:3, :3] = np.diag([1.0, -1.0, -1.0])  # x right = world x, y down = world -y, looking down
    pose[:3, 3] = (0.0, 0.0, CAMERA_HEIGHT)
    return k, pose


def _frame_with_lid(
    top: tuple[float, float, float], yaw: float, marker_id: int, side: float, lift: float, lid_size: float
) -> Frame:
    """White floor; a square lid of lid_size at `top`; the marker's cells drawn on it, `lift` above the lid."""
    k, pose = _camera()
    rgb = np.full((H, W, 3), 200, np.uint8)
    depth = np.full((H, W), CAMERA_HEIGHT, np.float32)
    c, s = np.cos(yaw), np.sin(yaw)
    x_axis, y_axis = np.array([c, s, 0.0]), np.array([-s, c, 0.0])

    def to_pixels(points: np.ndarray) -> np.ndarray:
        cam = (points - pose[:3, 3]) @ pose[:3, :3]
        return (cam[:, :2] / cam[:, 2:3]) * F + k[:2, 2]

    centre = np.asarray(top) + [0.0, 0.0, lift]
    lid = [
        centre + a * lid_size / 2 * x_axis + b * lid_size / 2 * y_axis
        for a, b in ((-1, 1), (1, 1), (1, -1), (-1, -1))
    ]
    lid_px = to_pixels(np.array(lid))
    cv2.fillConvexPoly(depth, np.rint(lid_px).astype(np.int32), float(CAMERA_HEIGHT - centre[2]))
    cv2.fillConvexPoly(rgb, np.rint(lid_px).astype(np.int32), (245, 245, 245))
    # Marker image corners: top-left, top-right, bottom-right, bottom-left = (-x,+y), (+x,+y), (+x,-y), (-x,-y).
    quad = np.array(
        [
            centre + a * side / 2 * x_axis + b * side / 2 * y_axis
            for a, b in ((-1, 1), (1, 1), (1, -1), (-1, -1))
        ]
    )
    cells = np.where(marker_cells(marker_id), 10, 245).astype(np.uint8)
    scale = 20
    image = cv2.resize(cells, None, fx=scale, fy=scale, interpolation=cv2.INTER_NEAREST)
    n = MARKER_CELLS * scale
    homography = cv2.getPerspectiveTransform(
        np.float32([[0, 0], [n, 0], [n, n], [0, n]]), to_pixels(quad).astype(np.float32) + 0.5
    )
    warped = cv2.warpPerspective(image, homography, (W, H), flags=cv2.INTER_AREA, borderValue=0)
    inside = cv2.warpPerspective(np.full_like(image, 255), homography, (W, H), borderValue=0) > 127
    rgb[inside] = warped[inside][:, None]
    return Frame(rgb=rgb, depth=depth, intrinsics=k, world_from_camera=pose, sim_time=0.0)


def test_marker_gives_top_centre_and_yaw(kitchen_cfg):
    spec = kitchen_cfg.catalogue.get("sugar")
    marker = lid_marker(spec)
    top, yaw = (0.05, 0.02, 0.10), 0.4
    frame = _frame_with_lid(top, yaw, spec.marker_id, marker.side, marker.lift, 0.06)
    (det,) = Detector(kitchen_cfg.catalogue).detect(frame)
    assert det.name == "sugar" and det.track_id == UNTRACKED
    assert np.linalg.norm(np.subtract(det.position, top)) < 0.003
    assert abs(det.yaw - yaw) < np.radians(2)
    assert 0.5 < det.confidence <= 1.0


def test_marker_of_the_wrong_printed_size_is_rejected(kitchen_cfg):
    spec = kitchen_cfg.catalogue.get("sugar")
    marker = lid_marker(spec)
    frame = _frame_with_lid((0.0, 0.0, 0.1), 0.0, spec.marker_id, 1.5 * marker.side, marker.lift, 0.1)
    assert Detector(kitchen_cfg.catalogue).detect(frame) == []
    loose = Detector(kitchen_cfg.catalogue, DetectorOptions(size_tolerance=0.6))
    assert [d.name for d in loose.detect(frame)] == ["sugar"]


def test_marker_outside_the_catalogue_is_ignored(kitchen_cfg):
    unused = next(i for i in range(DICTIONARY_SIZE) if kitchen_cfg.catalogue.by_marker(i) is None)
    frame = _frame_with_lid((0.0, 0.0, 0.1), 0.0, unused, 0.05, 0.003, 0.07)
    assert Detector(kitchen_cfg.catalogue).detect(frame) == []


def test_a_lid_without_depth_is_not_located(kitchen_cfg):
    spec = kitchen_cfg.catalogue.get("sugar")
    marker = lid_marker(spec)
    frame = _frame_with_lid((0.0, 0.0, 0.1), 0.0, spec.marker_id, marker.side, marker.lift, 0.06)
    frame.depth[:] = np.nan  # e.g. a depth sensor that returned nothing
    assert Detector(kitchen_cfg.catalogue).detect(frame) == []


def test_empty_image_gives_no_detections(kitchen_cfg):
    k, pose = _camera()
    frame = Frame(np.zeros((H, W, 3), np.uint8), np.ones((H, W), np.float32), k, pose, 0.0)
    assert Detector(kitchen_cfg.catalogue).detect(frame) == []


@pytest.mark.parametrize(
    "options",
    [{"size_tolerance": 0.0}, {"max_tilt_deg": 0.0}, {"error_correction_rate": 1.5}, {"min_depth_pixels": 1}],
)
def test_bad_options_are_one_line_errors(options):
    with pytest.raises(ConfigError, match="detector"):
        DetectorOptions(**options)


def test_products_past_the_apriltag_range_are_detected_by_their_own_id(kitchen_cfg):
    # AprilTag 36h11 has 587 ids; the catalogue outgrew it, so ids above 586 must decode to their own product.
    high = [o for o in kitchen_cfg.catalogue.objects if o.marker_id >= 587]
    assert len(high) > 200
    detector = Detector(kitchen_cfg.catalogue)
    for spec in (high[0], high[len(high) // 2], high[-1]):
        marker = lid_marker(spec)
        frame = _frame_with_lid(
            (0.0, 0.0, 0.1), 0.2, spec.marker_id, marker.side, marker.lift, 1.2 * marker.side
        )
        assert [d.name for d in detector.detect(frame)] == [spec.name], spec.marker_id
