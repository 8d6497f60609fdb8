"""The simulated cameras' images (PyBullet adapter): the kitchen rendered with the CPU TinyRenderer.

`world.Kitchen.camera_image` is the kitchen's side of `perception.images.ImageSource`; `camera_image` renders one
camera's noise-free RGB-D image and reuses it while nothing in view has moved (a fresh render would differ by under
half a pixel: products creep by tenths of a millimetre in PyBullet).
"""

from __future__ import annotations

import weakref
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from scone_bt.perception.camera import project
from scone_bt.perception.images import CameraImage, PinholeView

if TYPE_CHECKING:
    from scone_bt.world.kitchen import Kitchen

__all__ = ["REUSE_MAX_MOVE_M", "REUSE_MAX_TURN_RAD", "camera_image"]

REUSE_MAX_MOVE_M = 5e-4
"""A render is reused while nothing in view moved more than this (about half a pixel at the shelf's distance)."""
REUSE_MAX_TURN_RAD = 5e-3
"""... nor turned more than this (0.15 mm at the edge of a 6 cm lid)."""

_View = tuple[tuple[object, ...], np.ndarray]
"""What a camera shows: the kitchen's uid, the bodies and links in view, and their poses (x, y, z, qx, qy, qz, qw)."""


_CACHE: weakref.WeakKeyDictionary[PinholeView, tuple[_View, np.ndarray, np.ndarray]] = (
    weakref.WeakKeyDictionary()
)
"""Each camera's last render and what it showed, kept by the camera object (as long as the camera lives)."""


def camera_image(kitchen: Kitchen, camera: PinholeView) -> CameraImage:
    """The camera's noise-free image of the kitchen as it is now (arrays read-only).

    A camera's render is reused while the same kitchen (``Kitchen.uid``) shows it the same bodies and robot links,
    none moved by more than REUSE_MAX_MOVE_M or turned by more than REUSE_MAX_TURN_RAD since it was made. A new
    kitchen has a new uid, so its first image is always rendered.
    """
    shown = _view(kitchen, camera)
    cached = _CACHE.get(camera)
    if cached is not None and _unchanged(cached[0], shown):
        return CameraImage(cached[1], cached[2], fresh=False)
    rgb, depth = _render(kitchen, camera)
    _CACHE[camera] = (shown, rgb, depth)
    return CameraImage(rgb, depth, fresh=True)


def _sees(camera: PinholeView, lo: Sequence[float], hi: Sequence[float]) -> bool:
    """True if an axis-aligned box (world, metres) may show in the image (its corners' bounding rectangle)."""
    corners = np.array([(x, y, z) for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    uv, depth = project(corners, camera.intrinsics, camera.world_from_camera)
    spec = camera.spec
    if np.all(depth <= spec.near):
        return False
    if np.any(depth <= spec.near):
        return True  # straddles the camera plane: assume it shows
    return bool(
        uv[:, 0].max() >= 0
        and uv[:, 0].min() <= spec.width - 1
        and uv[:, 1].max() >= 0
        and uv[:, 1].min() <= spec.height - 1
    )


def _view(kitchen: Kitchen, camera: PinholeView) -> _View:
    """What the camera would show: which objects and robot links have their bounding box in view, and their poses
    as rows (x, y, z, qx, qy, qz, qw). The static scene never changes."""
    bc = kitchen.bc
    shown: list[object] = [kitchen.uid]
    poses: list[list[float]] = []
    for body in kitchen.objects.values():
        lo, hi = bc.getAABB(body)
        if _sees(camera, lo, hi):
            pos, orn = bc.getBasePositionAndOrientation(body)
            shown.append(body)
            poses.append([*pos, *orn])
    rid = kitchen.robot_id
    links = list(range(bc.getNumJoints(rid)))
    for link, state in zip(links, bc.getLinkStates(rid, links), strict=True):
        lo, hi = bc.getAABB(rid, link)
        if _sees(camera, lo, hi):
            shown.append((rid, link))
            poses.append([*state[4], *state[5]])
    return tuple(shown), np.asarray(poses, dtype=float).reshape(-1, 7)


def _unchanged(before_view: _View, view: _View) -> bool:
    """True if the cached render shows the same bodies, none moved or turned beyond the reuse limits."""
    if before_view[0] != view[0]:
        return False
    before, now = before_view[1], view[1]
    if not len(now):
        return True
    moved = np.abs(now[:, :3] - before[:, :3]).max()
    # Angle between unit quaternions q1, q2: 2 acos |q1 . q2|.
    dots = np.clip(np.abs(np.sum(now[:, 3:] * before[:, 3:], axis=1)), 0.0, 1.0)
    turned = float(2 * np.arccos(dots).max())
    return bool(moved <= REUSE_MAX_MOVE_M and turned <= REUSE_MAX_TURN_RAD)


def _render(kitchen: Kitchen, camera: PinholeView) -> tuple[np.ndarray, np.ndarray]:
    """Noise-free RGB (H, W, 3) uint8 and metric depth (H, W) float32 of the kitchen as it is now."""
    import pybullet as p

    s = camera.spec
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
    return rgb, depth
