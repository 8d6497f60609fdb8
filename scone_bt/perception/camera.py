"""A fixed pinhole RGB-D camera: its model (intrinsics, pose, projection) and its frames, with the configured noise.

The images come from what the camera looks at (`perception.images.ImageSource`): the simulated kitchen renders
them (`world.camera`, PyBullet's CPU TinyRenderer), a real camera's driver streams them. The pinhole model is kept
in OpenCV's convention (x right, y down, z forward; pixel centres at integer coordinates) so the detector works the
same on a real camera's images.
"""

from __future__ import annotations

import numpy as np

from scone_bt.config import CameraSpec
from scone_bt.errors import ConfigError
from scone_bt.perception.images import ImageSource
from scone_bt.perception.types import Frame

__all__ = ["Camera", "intrinsics", "world_from_camera", "project"]


def intrinsics(spec: CameraSpec) -> np.ndarray:
    """(3, 3) pinhole matrix K in pixels; fov_deg is the vertical field of view, pixels are square."""
    fy = (spec.height / 2.0) / np.tan(np.radians(spec.fov_deg) / 2.0)
    return np.array([[fy, 0.0, (spec.width - 1) / 2.0], [0.0, fy, (spec.height - 1) / 2.0], [0.0, 0.0, 1.0]])


def world_from_camera(spec: CameraSpec) -> np.ndarray:
    """(4, 4) camera pose in the world frame, OpenCV axes (x right, y down, z toward the target)."""
    eye = np.asarray(spec.position, dtype=float)
    forward = np.asarray(spec.target, dtype=float) - eye
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, np.asarray(spec.up, dtype=float))
    right /= np.linalg.norm(right)
    down = np.cross(forward, right)
    pose = np.eye(4)
    pose[:3, 0], pose[:3, 1], pose[:3, 2], pose[:3, 3] = right, down, forward, eye
    return pose


def project(points_world: np.ndarray, k: np.ndarray, pose: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Pixel coordinates (N, 2) and depths (N,) in metres of world points (N, 3)."""
    pts = np.atleast_2d(points_world) - pose[:3, 3]
    cam = pts @ pose[:3, :3]
    z = cam[:, 2]
    uv = (cam[:, :2] / z[:, None]) * np.diag(k)[:2] + k[:2, 2]
    return uv, z


def _check(spec: CameraSpec) -> None:
    where = f"camera {spec.name!r}"
    if spec.width < 16 or spec.height < 16:
        raise ConfigError(
            f"{where}: width and height must be at least 16 pixels, got {spec.width}x{spec.height}"
        )
    if not 1.0 <= spec.fov_deg <= 170.0:
        raise ConfigError(f"{where}.fov_deg must be in 1-170 degrees, got {spec.fov_deg}")
    if not 0 < spec.near < spec.far:
        raise ConfigError(f"{where}: need 0 < near < far, got near={spec.near}, far={spec.far}")
    if spec.noise_std < 0 or spec.depth_noise_std < 0:
        raise ConfigError(f"{where}: noise_std and depth_noise_std must be >= 0")
    forward = np.subtract(spec.target, spec.position)
    if np.linalg.norm(forward) < 1e-6:
        raise ConfigError(f"{where}: position and target must differ")
    if np.linalg.norm(np.cross(forward, spec.up)) < 1e-6 * np.linalg.norm(forward):
        raise ConfigError(f"{where}: up must not be parallel to the viewing direction")


class Camera:
    """A fixed pinhole RGB-D camera. Construction is cheap; `capture` takes an image from what it looks at.

    Args:
        spec: Placement, resolution, field of view, clipping planes and noise levels (from kitchen.yaml).
    """

    def __init__(self, spec: CameraSpec) -> None:
        _check(spec)
        self.spec = spec
        self.intrinsics = intrinsics(spec)
        self.world_from_camera = world_from_camera(spec)
        self.renders = 0  # images the source made afresh for this camera
        self.reuses = 0  # images the source handed back unchanged (nothing in view had moved)

    def capture(self, source: ImageSource, rng: np.random.Generator) -> Frame:
        """One RGB-D frame: the source's noise-free image of this camera with the configured noise added.

        The frame's arrays are read-only; a source may hand back the very same arrays while nothing in view has
        moved (the simulated kitchen does), and the noise is still drawn afresh.

        Args:
            source: What the camera looks at (the simulated kitchen, or a real camera's driver).
            rng: Source of the image noise (used only when noise_std or depth_noise_std is non-zero).
        """
        s = self.spec
        image = source.camera_image(self)
        if image.fresh:
            self.renders += 1
        else:
            self.reuses += 1
        rgb, depth = image.rgb, image.depth
        if s.noise_std > 0:
            noisy = rgb.astype(np.float32) + rng.normal(0.0, s.noise_std, rgb.shape).astype(np.float32)
            rgb = np.clip(np.rint(noisy), 0, 255).astype(np.uint8)
        if s.depth_noise_std > 0:
            depth = depth + rng.normal(0.0, s.depth_noise_std, depth.shape).astype(np.float32)
        return Frame(
            rgb=rgb,
            depth=depth,
            intrinsics=self.intrinsics.copy(),
            world_from_camera=self.world_from_camera.copy(),
            sim_time=float(source.sim_time),
        )
