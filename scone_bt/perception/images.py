"""Where a camera's images come from (`ImageSource`): perception consumes them, a backend makes them.

The simulated kitchen renders them (`world.camera`, behind ``--robot sim``); a real robot's backend hands over the
latest image of the camera's driver. Perception never imports either: `perception.camera.Camera` asks its source
for a noise-free image of itself and turns it into a `Frame`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np

from scone_bt.config import CameraSpec

__all__ = ["CameraImage", "ImageSource", "PinholeView"]


@dataclass(frozen=True, eq=False)
class CameraImage:
    """One noise-free RGB-D image of one camera.

    Attributes:
        rgb: (H, W, 3) uint8, read-only.
        depth: (H, W) float32 metric depth along the optical axis, metres, read-only.
        fresh: False when the source handed back the arrays of its previous image of this camera (nothing in view
            had moved), True when it made them now.
    """

    rgb: np.ndarray
    depth: np.ndarray
    fresh: bool


class PinholeView(Protocol):
    """The camera a source makes an image for: its settings, intrinsics K (3, 3) and pose (4, 4, OpenCV axes)."""

    @property
    def spec(self) -> CameraSpec: ...

    @property
    def intrinsics(self) -> np.ndarray: ...

    @property
    def world_from_camera(self) -> np.ndarray: ...


@runtime_checkable
class ImageSource(Protocol):
    """What a camera looks at: it makes the camera's image now, on the source's clock.

    Attributes:
        sim_time: The source's clock when the image is taken, seconds (simulated time in simulation).
    """

    sim_time: float

    def camera_image(self, camera: PinholeView) -> CameraImage:
        """The camera's noise-free image of the scene as it is now (the same camera object each time: a source
        may keep what it needs to reuse an image by it)."""
        ...
