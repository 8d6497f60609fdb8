"""The MuJoCo kitchen's camera images (MuJoCo adapter): `mujoco.Renderer` RGB and depth, headless through EGL.

Each image is rendered through a model camera placed at the view's pose with its vertical field of view and clip
planes, so any `perception.images.PinholeView` gets its own pinhole image (principal point at the image centre, as
`perception.camera.intrinsics` assumes). A camera's last image is handed back while nothing in its view moved by
more than `world.camera`'s reuse limits (half a pixel at the shelf): software rendering costs tens of milliseconds
per image, and most ticks of an episode look at an unchanged shelf.
"""

from __future__ import annotations

import weakref
from typing import TYPE_CHECKING, Any

import numpy as np

from scone_bt.errors import ConfigError
from scone_bt.perception.images import CameraImage, PinholeView
from scone_bt.world.camera import REUSE_MAX_MOVE_M, REUSE_MAX_TURN_RAD, box_in_view
from scone_bt.world.mj_model import EGL_PACKAGES

if TYPE_CHECKING:
    from scone_bt.world.parts import MjParts

__all__ = ["MjCameras", "check_rendering"]


def check_rendering(mujoco: Any) -> None:
    """Make one tiny offscreen context, or raise one line naming the Debian packages headless rendering needs."""
    try:
        context = mujoco.GLContext(8, 8)
        context.make_current()
        context.free()
    except Exception as exc:  # noqa: BLE001 (EGL reports failures as several exception types)
        raise ConfigError(
            f"MuJoCo cannot render headless ({type(exc).__name__}: {str(exc).strip().splitlines()[0] if str(exc).strip() else 'no EGL display'}); "
            f"install Mesa's EGL: apt-get install {EGL_PACKAGES}"
        ) from None


class MjCameras:
    """Renderers (one per image size) and each camera's last image, for one kitchen model.

    Args:
        kitchen: The MuJoCo kitchen whose model and state are rendered.
    """

    def __init__(self, kitchen: MjParts) -> None:
        self.kitchen = kitchen
        self.mujoco = kitchen.mujoco
        self.model = kitchen.model
        self.renders = 0
        self.reused = 0
        self._renderers: dict[tuple[int, int], Any] = {}
        self._last: weakref.WeakKeyDictionary[
            Any, tuple[tuple[object, ...], np.ndarray, np.ndarray, np.ndarray]
        ] = weakref.WeakKeyDictionary()
        m = self.model
        radius = np.zeros(m.nbody)
        for g in range(m.ngeom):
            b = int(m.geom_bodyid[g])
            radius[b] = max(radius[b], float(np.linalg.norm(m.geom_pos[g]) + m.geom_rbound[g]))
        self._radius = radius
        self._bodies = np.array(sorted({*kitchen.objects.values(), *kitchen.robot_bodies}), dtype=int)
        self._camera = 0  # the model camera every view is rendered through (placed anew for each)

    def _renderer(self, width: int, height: int) -> Any:
        key = (width, height)
        if key not in self._renderers:
            try:
                renderer = self.mujoco.Renderer(self.model, height, width)
            except Exception as exc:  # noqa: BLE001
                check_rendering(self.mujoco)
                import os

                gl = os.environ.get("MUJOCO_GL", "")
                hint = (
                    f"; MUJOCO_GL={gl!r}: headless needs egl or osmesa (glfw needs a display)" if gl else ""
                )
                raise ConfigError(
                    f"MuJoCo renderer failed ({str(exc).strip().splitlines()[0]}){hint}"
                ) from None
            flags = renderer.scene.flags
            for flag in ("mjRND_SHADOW", "mjRND_REFLECTION", "mjRND_SKYBOX", "mjRND_FOG", "mjRND_HAZE"):
                flags[getattr(self.mujoco.mjtRndFlag, flag)] = 0
            self._renderers[key] = renderer
        return self._renderers[key]

    def _view(self, camera: PinholeView) -> tuple[tuple[object, ...], np.ndarray, np.ndarray]:
        """Which bodies the camera may see (their ids with the kitchen's uid) and their poses (n, 7)."""
        d = self.kitchen.data
        ids = self._bodies
        pos = d.xpos[ids]
        r = self._radius[ids][:, None]
        shown = [
            i for i, (lo, hi) in enumerate(zip(pos - r, pos + r, strict=True)) if box_in_view(camera, lo, hi)
        ]
        sel = ids[shown]
        poses = np.hstack([d.xpos[sel], d.xquat[sel]])
        return (self.kitchen.uid, self.kitchen.model_version, *sel.tolist()), poses, sel

    def image(self, camera: PinholeView) -> CameraImage:
        """The camera's noise-free image now (reused while nothing in view moved beyond the reuse limits)."""
        keys, poses, _ = self._view(camera)
        last = self._last.get(camera)
        if last is not None and last[0] == keys and not _moved(last[1], poses):
            self.reused += 1
            return CameraImage(last[2], last[3], fresh=False)
        rgb, depth = self._render(camera)
        self._last[camera] = (keys, poses, rgb, depth)
        return CameraImage(rgb, depth, fresh=True)

    def _render(self, camera: PinholeView) -> tuple[np.ndarray, np.ndarray]:
        spec = camera.spec
        m, d = self.model, self.kitchen.data
        renderer = self._renderer(spec.width, spec.height)
        pose = camera.world_from_camera
        c = self._camera
        m.cam_fovy[c] = spec.fov_deg
        extent = float(m.stat.extent)
        m.vis.map.znear = spec.near / extent
        m.vis.map.zfar = spec.far / extent
        d.cam_xpos[c] = pose[:3, 3]
        # OpenCV's camera axes (x right, y down, z forward) to OpenGL's (x right, y up, looking along -z).
        d.cam_xmat[c] = (pose[:3, :3] @ np.diag([1.0, -1.0, -1.0])).flatten()
        renderer.update_scene(d, camera=c)
        # One pass for both images (`mujoco.Renderer` draws the scene twice for RGB and depth).
        mj = self.mujoco
        renderer._gl_context.make_current()
        rgb = np.empty((spec.height, spec.width, 3), dtype=np.uint8)
        buffer = np.empty((spec.height, spec.width), dtype=np.float32)
        mj.mjr_render(renderer._rect, renderer._scene, renderer._mjr_context)
        mj.mjr_readPixels(rgb, buffer, renderer._rect, renderer._mjr_context)
        rgb = np.ascontiguousarray(np.flipud(rgb))
        depth = _metric_depth(np.flipud(buffer), m.vis.map.znear * extent, m.vis.map.zfar * extent)
        self.renders += 1
        rgb.setflags(write=False)
        depth.setflags(write=False)
        return rgb, depth

    def close(self) -> None:
        for renderer in self._renderers.values():
            renderer.close()
        self._renderers.clear()


def _metric_depth(buffer: np.ndarray, near: float, far: float) -> np.ndarray:
    """MuJoCo's reversed-Z depth buffer to metric depth along the optical axis (as `mujoco.Renderer` converts it)."""
    zfar, znear = np.float32(far), np.float32(near)
    c = -(zfar + znear) / (zfar - znear)
    d = -(np.float32(2) * zfar * znear) / (zfar - znear)
    c = np.float32(-0.5) * c - np.float32(0.5)
    d = np.float32(-0.5) * d
    return np.ascontiguousarray(d / (buffer.astype(np.float64) + c), dtype=np.float32)


def _moved(before: np.ndarray, now: np.ndarray) -> bool:
    """Some body moved beyond REUSE_MAX_MOVE_M or turned beyond REUSE_MAX_TURN_RAD (pose rows, same bodies)."""
    if not len(now):
        return False
    if np.abs(now[:, :3] - before[:, :3]).max() > REUSE_MAX_MOVE_M:
        return True
    dots = np.clip(np.abs(np.sum(now[:, 3:] * before[:, 3:], axis=1)), 0.0, 1.0)
    return bool((2 * np.arccos(dots)).max() > REUSE_MAX_TURN_RAD)
