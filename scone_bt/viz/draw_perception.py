"""Draws what the robot perceives: the camera's pose and lens, its colour and depth images, and the detections in
the image and in the world."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
import rerun as rr

from scone_bt.perception.camera import intrinsics, world_from_camera
from scone_bt.viz import paths as P
from scone_bt.viz.colours import PALETTE
from scone_bt.viz.sinks import Sinks

if TYPE_CHECKING:
    from scone_bt.config.scene import CameraSpec
    from scone_bt.perception.types import Detection, Frame

__all__ = ["DEPTH_UNITS_PER_METRE", "PerceptionDrawer", "depth_millimetres"]

DEPTH_UNITS_PER_METRE = 1000.0
"""The logged depth image is in millimetres (uint16)."""


class PerceptionDrawer:
    """The camera (when it moved or its lens changed) and each captured frame with its detections.

    Args:
        sinks: The recording's streams.
        jpeg_quality: RGB images are stored as JPEG of this quality (1-100); None stores raw pixels.
    """

    def __init__(self, sinks: Sinks, jpeg_quality: int | None) -> None:
        self._sinks = sinks
        self._jpeg_quality = jpeg_quality
        self._camera_pose: np.ndarray | None = None
        self._camera_k: np.ndarray | None = None
        self._camera_res: tuple[int, int] | None = None

    def log_static(self) -> None:
        """The depth image's unit and colour map (static: sent once, not with every frame)."""
        self._sinks.rec.log(
            P.DEPTH, rr.DepthImage.from_fields(meter=DEPTH_UNITS_PER_METRE, colormap="turbo"), static=True
        )

    def log_configured_camera(self, cam: CameraSpec) -> None:
        """The kitchen's camera as configured, before it captured anything."""
        self._log_camera(world_from_camera(cam), intrinsics(cam), (cam.width, cam.height))

    def log_frame(self, frame: Frame, detections: Sequence[Detection]) -> None:
        """One captured frame: the camera it came from, the colour and depth images, the detections."""
        h, w = frame.rgb.shape[:2]
        self._log_camera(frame.world_from_camera, frame.intrinsics, (w, h))
        rec = self._sinks.rec
        rec.log(P.RGB, self._rgb_image(frame.rgb))
        depth = depth_millimetres(frame.depth)
        # The pixels as raw bytes with their format: rerun's own image conversion costs as much again.
        dh, dw = depth.shape[:2]
        fmt = rr.components.ImageFormat(width=dw, height=dh, channel_datatype=rr.ChannelDatatype.U16)
        rec.log(P.DEPTH, rr.DepthImage.from_fields(buffer=depth.reshape(-1).view(np.uint8), format=fmt))
        if not detections:
            rec.log(P.DETECTIONS_2D, rr.Boxes2D.cleared())
            rec.log(P.DETECTIONS_3D, rr.Points3D.cleared())
            return
        boxes = np.array([d.bbox for d in detections], dtype=float)
        colours = [PALETTE[d.track_id % len(PALETTE)] for d in detections]
        labels = [
            f"{d.name} #{d.track_id} ({d.confidence:.2f})"
            if d.track_id >= 0
            else f"{d.name} ({d.confidence:.2f})"
            for d in detections
        ]
        rec.log(
            P.DETECTIONS_2D,
            rr.Boxes2D(array=boxes, array_format=rr.Box2DFormat.XYXY, labels=labels, colors=colours),
        )
        rec.log(
            P.DETECTIONS_3D,
            rr.Points3D(
                [d.position for d in detections],
                labels=[d.name for d in detections],
                colors=colours,
                radii=[0.01],
            ),
        )

    def _log_camera(self, world_from_camera: np.ndarray, k: np.ndarray, resolution: tuple[int, int]) -> None:
        rec = self._sinks.rec
        if self._camera_pose is None or not np.allclose(self._camera_pose, world_from_camera, atol=1e-6):
            self._camera_pose = np.array(world_from_camera, dtype=float)
            rot = self._camera_pose[:3, :3]
            rec.log(
                P.CAMERA,
                rr.Transform3D(translation=self._camera_pose[:3, 3], mat3x3=rot),
            )
        if self._camera_k is None or not np.allclose(self._camera_k, k) or self._camera_res != resolution:
            self._camera_k, self._camera_res = np.array(k, dtype=float), resolution
            rec.log(
                P.IMAGE,
                rr.Pinhole(
                    image_from_camera=self._camera_k,
                    resolution=resolution,
                    camera_xyz=rr.ViewCoordinates.RDF,
                    image_plane_distance=0.25,
                ),
            )

    def _rgb_image(self, rgb: np.ndarray) -> Any:
        if self._jpeg_quality is None:
            return rr.Image(rgb, color_model="RGB")
        import cv2

        # cvtColor, not rgb[..., ::-1]: numpy's copy of a reversed channel axis cost twice the JPEG encoding.
        bgr = cv2.cvtColor(np.ascontiguousarray(rgb), cv2.COLOR_RGB2BGR)
        ok, buf = cv2.imencode(".jpg", bgr, [cv2.IMWRITE_JPEG_QUALITY, self._jpeg_quality])
        if not ok:  # pragma: no cover - OpenCV refuses only malformed arrays
            return rr.Image(rgb, color_model="RGB")
        return rr.EncodedImage(contents=buf.tobytes(), media_type="image/jpeg")


def depth_millimetres(depth_m: np.ndarray) -> np.ndarray:
    """A depth image in metres as uint16 millimetres, no reading (NaN, ±inf, ≤ 0) as 0, far readings as 65535.

    Millimetres in uint16: a quarter of the bytes of float32 metres, and cheaper to log. The common case, every
    reading finite, takes one multiply, one clip and one cast.
    """
    mm = np.asarray(depth_m, dtype=np.float32) * np.float32(DEPTH_UNITS_PER_METRE)
    if not np.isfinite(mm).all():
        mm[~np.isfinite(mm)] = 0.0
    np.clip(mm, 0, 65535, out=mm)
    return mm.astype(np.uint16)
