"""A simulated RGB-D camera (PyBullet adapter): renders the kitchen with the CPU TinyRenderer.

The pinhole model is kept in OpenCV's convention (x right, y down, z forward; pixel centres at integer
coordinates) so the detector works the same on a real camera's images.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from scone_bt.config import CameraSpec
from scone_bt.errors import ConfigError
from scone_bt.perception.types import Frame

if TYPE_CHECKING:
    from scone_bt.world import Kitchen

__all__ = ["Camera", "intrinsics", "world_from_camera", "project", "REUSE_MAX_MOVE_M", "REUSE_MAX_TURN_RAD"]

REUSE_MAX_MOVE_M = 5e-4
"""A render is reused while nothing in view moved more than this (about half a pixel at the shelf's distance)."""
REUSE_MAX_TURN_RAD = 5e-3
"""... nor turned more than this (0.15 mm at the edge of a 6 cm lid)."""


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
    """A fixed pinhole RGB-D camera. Construction is cheap; `capture` renders.

    Args:
        spec: Placement, resolution, field of view, clipping planes and noise levels (from kitchen.yaml).
    """

    def __init__(self, spec: CameraSpec) -> None:
        _check(spec)
        self.spec = spec
        self.intrinsics = intrinsics(spec)
        self.world_from_camera = world_from_camera(spec)
        self.renders = 0
        self.reuses = 0
        # The last noise-free render and what it showed: while nothing in view has moved, a new render would give
        # the same pixels, so it is reused (the noise is still drawn afresh).
        self._cached: tuple[tuple[tuple[object, ...], np.ndarray], np.ndarray, np.ndarray] | None = None

    def capture(self, kitchen: Kitchen, rng: np.random.Generator) -> Frame:
        """Render one RGB-D frame of the kitchen with TinyRenderer (CPU only) and add the configured noise.

        The frame's arrays are read-only. The render is reused while no object or robot link in view has moved
        by more than REUSE_MAX_MOVE_M or turned by more than REUSE_MAX_TURN_RAD since it was made (a fresh render
        would differ by under half a pixel: products creep by tenths of a millimetre in PyBullet).

        Args:
            kitchen: The simulated world to look at.
            rng: Source of the image noise (used only when noise_std or depth_noise_std is non-zero).
        """
        s = self.spec
        rgb, depth = self._render(kitchen)
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
            sim_time=float(kitchen.sim_time),
        )

    def _sees(self, lo: Sequence[float], hi: Sequence[float]) -> bool:
        """True if an axis-aligned box (world, metres) may show in the image (its corners' bounding rectangle)."""
        corners = np.array(
            [(x, y, z) for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]
        )
        uv, depth = project(corners, self.intrinsics, self.world_from_camera)
        if np.all(depth <= self.spec.near):
            return False
        if np.any(depth <= self.spec.near):
            return True  # straddles the camera plane: assume it shows
        return bool(
            uv[:, 0].max() >= 0
            and uv[:, 0].min() <= self.spec.width - 1
            and uv[:, 1].max() >= 0
            and uv[:, 1].min() <= self.spec.height - 1
        )

    def _view(self, kitchen: Kitchen) -> tuple[tuple[object, ...], np.ndarray]:
        """What this camera would show: which objects and robot links have their bounding box in view, and their
        poses as rows (x, y, z, qx, qy, qz, qw). The static scene never changes."""
        bc = kitchen.bc
        shown: list[object] = [kitchen.uid]
        poses: list[list[float]] = []
        for body in kitchen.objects.values():
            lo, hi = bc.getAABB(body)
            if self._sees(lo, hi):
                pos, orn = bc.getBasePositionAndOrientation(body)
                shown.append(body)
                poses.append([*pos, *orn])
        rid = kitchen.robot_id
        links = list(range(bc.getNumJoints(rid)))
        for link, state in zip(links, bc.getLinkStates(rid, links), strict=True):
            lo, hi = bc.getAABB(rid, link)
            if self._sees(lo, hi):
                shown.append((rid, link))
                poses.append([*state[4], *state[5]])
        return tuple(shown), np.asarray(poses, dtype=float).reshape(-1, 7)

    def _unchanged(self, view: tuple[tuple[object, ...], np.ndarray]) -> bool:
        """True if the cached render shows the same bodies, none moved or turned beyond the reuse limits."""
        if self._cached is None or self._cached[0][0] != view[0]:
            return False
        before, now = self._cached[0][1], view[1]
        if not len(now):
            return True
        moved = np.abs(now[:, :3] - before[:, :3]).max()
        # Angle between unit quaternions q1, q2: 2 acos |q1 . q2|.
        dots = np.clip(np.abs(np.sum(now[:, 3:] * before[:, 3:], axis=1)), 0.0, 1.0)
        turned = float(2 * np.arccos(dots).max())
        return bool(moved <= REUSE_MAX_MOVE_M and turned <= REUSE_MAX_TURN_RAD)

    def _render(self, kitchen: Kitchen) -> tuple[np.ndarray, np.ndarray]:
        """Noise-free RGB (H, W, 3) uint8 and metric depth (H, W) float32 of the kitchen as it is now."""
        shown = self._view(kitchen)
        if self._cached is not None and self._unchanged(shown):
            self.reuses += 1
            return self._cached[1], self._cached[2]
        import pybullet as p

        s = self.spec
        view = p.computeViewMatrix(s.position, s.target, s.up)
        proj = p.computeProjectionMatrixFOV(s.fov_deg, s.width / s.height, s.near, s.far)
        _, _, rgba, depth_buffer, _ = kitchen.bc.getCameraImage(
            s.width,
            s.height,
            view,
            proj,
            renderer=p.ER_TINY_RENDERER,
            flags=p.ER_NO_SEGMENTATION_MASK,
            shadow=0,
            # A soft, mostly ambient light without highlights, like a diffuse kitchen ceiling light: specular
            # glints on white lids would otherwise bleach marker cells.
            lightDirection=(0.3, 0.2, 1.0),
            lightAmbientCoeff=0.6,
            lightDiffuseCoeff=0.4,
            lightSpecularCoeff=0.0,
        )
        rgb = np.ascontiguousarray(np.asarray(rgba, dtype=np.uint8).reshape(s.height, s.width, 4)[:, :, :3])
        buffer = np.asarray(depth_buffer, dtype=np.float64).reshape(s.height, s.width)
        # OpenGL's non-linear depth buffer to metric depth along the optical axis.
        depth = (s.far * s.near / (s.far - (s.far - s.near) * buffer)).astype(np.float32)
        rgb.setflags(write=False)
        depth.setflags(write=False)
        self._cached = (shown, rgb, depth)
        self.renders += 1
        return rgb, depth
