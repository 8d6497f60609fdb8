"""Data that leaves the perception stage."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Frame", "Detection"]


@dataclass(frozen=True, eq=False)
class Frame:
    """One RGB-D capture.

    Attributes:
        rgb: (H, W, 3) uint8 image.
        depth: (H, W) float32 metric depth along the optical axis, metres.
        intrinsics: (3, 3) pinhole matrix K, pixels.
        world_from_camera: (4, 4) pose of the camera (OpenCV convention: x right, y down, z forward), metres.
        sim_time: Simulated time of the capture, seconds.
    """

    rgb: np.ndarray
    depth: np.ndarray
    intrinsics: np.ndarray
    world_from_camera: np.ndarray
    sim_time: float


@dataclass(frozen=True)
class Detection:
    """One object seen in a frame and named from the catalogue.

    Attributes:
        name: Catalogue name.
        track_id: Stable id of this object across ticks.
        position: Centre of the object's top face in the world frame, metres (x, y, z).
        yaw: Rotation about world z, radians (from the marker's orientation).
        confidence: Detection confidence in [0, 1].
        bbox: (x0, y0, x1, y1) pixel box in the frame.
    """

    name: str
    track_id: int
    position: tuple[float, float, float]
    yaw: float
    confidence: float
    bbox: tuple[int, int, int, int]
