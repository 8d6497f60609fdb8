"""The simulated cameras' images (PyBullet adapter): the kitchen rendered with the CPU TinyRenderer.

`world.Kitchen.camera_image` is the kitchen's side of `perception.images.ImageSource`; `camera_image` renders one
camera's noise-free RGB-D image. It reuses the camera's last image while nothing in view has moved (a fresh render
would differ by under half a pixel: products creep by tenths of a millimetre in PyBullet), and when something did
move it renders only the window of the image that changed (`dirty_window`) and pastes it into a copy of the last
image: the TinyRenderer's cost is mostly per pixel, and taking one product off a shelf changes a few percent of
the shelf camera's pixels.

A window is rendered through the same camera with an off-axis projection that maps exactly those pixels to the
viewport, so it samples the scene where the whole image does: its RGB equals the whole render's but for a rare
pixel on a triangle's edge that rounds to the other side (5 pixels of 2.8 million over 15 restocked shelves), and
its depth agrees to the depth buffer's rounding (micrometres at the shelf). `tests/world/test_camera.py` checks
both against whole renders.
"""

from __future__ import annotations

import weakref
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from scone_bt.perception.camera import project
from scone_bt.perception.images import CameraImage, PinholeView

if TYPE_CHECKING:
    from scone_bt.world.parts import BulletParts

__all__ = [
    "PATCH_MARGIN_M",
    "PATCH_PAD_PX",
    "PATCH_MAX_SHARE",
    "WINDOW_COST_PX",
    "REUSE_MAX_MOVE_M",
    "REUSE_MAX_TURN_RAD",
    "Window",
    "RenderStats",
    "box_in_view",
    "camera_image",
    "dirty_window",
    "dirty_windows",
    "keep_background",
    "render_stats",
]

REUSE_MAX_MOVE_M = 5e-4
"""A render is reused while nothing in view moved more than this (about half a pixel at the shelf's distance)."""
REUSE_MAX_TURN_RAD = 5e-3
"""... nor turned more than this (0.15 mm at the edge of a 6 cm lid)."""
PATCH_MARGIN_M = 0.015
"""World margin (m) added around the bounding box of whatever changed: a lid's marker and cap stand a few
millimetres above the collision shape that `getAABB` measures."""
PATCH_PAD_PX = 2
"""Pixels added around the projected window (edge pixels that a triangle only partly covers)."""
PATCH_MAX_SHARE = 0.5
"""Windows larger than this share of the image together are not worth their fixed cost: the whole image is
rendered."""
WINDOW_COST_PX = 4000
"""A render call's fixed cost in pixels: ~1.5 ms, what ~4,000 pixels of a 640 x 480 render cost (the
TinyRenderer transforms every triangle of the scene on each call). Two windows are rendered as one rectangle
around both when that costs no more pixels than the two plus this."""


@dataclass(frozen=True)
class Window:
    """A pixel rectangle of a camera image: columns x0 .. x0 + width - 1, rows y0 .. y0 + height - 1."""

    x0: int
    y0: int
    width: int
    height: int

    @property
    def pixels(self) -> int:
        return self.width * self.height


@dataclass
class RenderStats:
    """What the kitchens' cameras rendered in this process: whole images, windows, and pixels rasterised."""

    full: int = 0
    windows: int = 0
    reused: int = 0
    pixels: int = 0
    full_pixels: int = 0  # the pixels whole images would have cost for the same renders
    backgrounds_loaded: int = 0  # empty-kitchen images read from the disk cache instead of rendered
    last_windows: tuple[Window, ...] = ()  # the windows of the latest render (none: a whole image)


_STATS = RenderStats()


def render_stats() -> RenderStats:
    """This process's render counters (benchmarks read them; they only ever grow)."""
    return _STATS


@dataclass(frozen=True)
class _View:
    """What a camera shows: the kitchen's uid, then the bodies and (robot, link) pairs whose bounding box is in
    view; their poses as rows (x, y, z, qx, qy, qz, qw) and their world bounding boxes (n, 2, 3)."""

    keys: tuple[object, ...]
    poses: np.ndarray
    boxes: np.ndarray


_CACHE: weakref.WeakKeyDictionary[PinholeView, tuple[_View, np.ndarray, np.ndarray]] = (
    weakref.WeakKeyDictionary()
)
"""Each camera's last image and what it showed, kept by the camera object (as long as the camera lives)."""
_BACKGROUNDS: dict[tuple[tuple[object, ...], tuple[object, ...]], tuple[_View, np.ndarray, np.ndarray]] = {}
"""(kitchen's static_key, camera geometry) → the camera's image of that kitchen with no product in it
(`keep_background`): the base a camera's first image of a restocked kitchen is patched over."""
_MAX_BACKGROUNDS = 16
"""Backgrounds kept (2 MB each at 640 x 480): a few scenes' cameras."""


def _geometry(camera: PinholeView) -> tuple[object, ...]:
    """What a render depends on in a camera's settings (not its noise levels or name)."""
    s = camera.spec
    return (s.position, s.target, s.up, s.width, s.height, s.fov_deg, s.near, s.far)


def keep_background(kitchen: BulletParts, camera: PinholeView) -> None:
    """Render the camera's image of the kitchen while it holds no product, once per static scene (a kitchen's
    ``static_key``: kitchens of one scene share it) and camera geometry, as the base of later first images
    (`camera_image`).

    Raises:
        ValueError: the kitchen holds products.
    """
    if kitchen.objects:
        raise ValueError("keep_background: the kitchen must hold no product")
    key = (kitchen.static_key, _geometry(camera))
    if key in _BACKGROUNDS:
        return
    while len(_BACKGROUNDS) >= _MAX_BACKGROUNDS:
        del _BACKGROUNDS[next(iter(_BACKGROUNDS))]  # the oldest (a scene with a cover that came or went, ...)
    from scone_bt.world import render_cache

    shown = _view(kitchen, camera)
    # Kept on disk too, but not a covered scene's (its static_key is its own, `Kitchen.uid`).
    digest = None
    if kitchen.static_key[0] != "covered" and render_cache.render_cache_dir() is not None:
        digest = render_cache.background_digest(kitchen, _geometry(camera), __file__)
    stored = (
        None
        if digest is None
        else render_cache.load_background(digest, camera.spec.width, camera.spec.height)
    )
    if stored is not None:
        rgb, depth = stored
        _STATS.backgrounds_loaded += 1
    else:
        rgb, depth = _render(kitchen, camera)
        _STATS.full += 1
        _STATS.pixels += rgb.shape[0] * rgb.shape[1]
        _STATS.full_pixels += rgb.shape[0] * rgb.shape[1]
        if digest is not None:
            render_cache.save_background(digest, rgb, depth)
    _BACKGROUNDS[key] = (shown, rgb, depth)


def camera_image(kitchen: BulletParts, camera: PinholeView) -> CameraImage:
    """The camera's noise-free image of the kitchen as it is now (arrays read-only).

    A camera's last image is handed back while the same kitchen (``Kitchen.uid``) shows it the same bodies and
    robot links, none moved by more than REUSE_MAX_MOVE_M or turned by more than REUSE_MAX_TURN_RAD since. When
    some did, only `dirty_windows` are rendered anew, unless they are over PATCH_MAX_SHARE of the image. A new
    kitchen (or a cover that came or went, or a restocked one) has a new uid: its first image is rendered whole, or
    patched over the empty kitchen's image where `keep_background` made one (the products in view, rendered anew).
    """
    spec = camera.spec
    shown = _view(kitchen, camera)
    cached = _CACHE.get(camera)
    if cached is not None and cached[0].keys[0] != shown.keys[0]:
        cached = None  # another kitchen, restocked, or a cover came or went
    base = cached if cached is not None else _BACKGROUNDS.get((kitchen.static_key, _geometry(camera)))
    windows: list[Window] | None = None
    if base is not None:
        changed = _changed_boxes(base[0], shown)
        if not len(changed):
            if base is cached:
                _STATS.reused += 1
                return CameraImage(base[1], base[2], fresh=False)
            _CACHE[camera] = (shown, base[1], base[2])  # nothing but the empty kitchen in view
            return CameraImage(base[1], base[2], fresh=True)
        windows = dirty_windows(camera, changed)
        if (
            windows is not None
            and sum(w.pixels for w in windows) > PATCH_MAX_SHARE * spec.width * spec.height
        ):
            windows = None
    _STATS.full_pixels += spec.width * spec.height
    _STATS.last_windows = tuple(windows or ())
    if windows is None or base is None:
        rgb, depth = _render(kitchen, camera)
        _STATS.full += 1
        _STATS.pixels += spec.width * spec.height
    else:
        rgb, depth = _patched(kitchen, camera, windows, base[1], base[2])
        _STATS.windows += len(windows)
        _STATS.pixels += sum(w.pixels for w in windows)
    _CACHE[camera] = (shown, rgb, depth)
    return CameraImage(rgb, depth, fresh=True)


def _corners(lo: Sequence[float] | np.ndarray, hi: Sequence[float] | np.ndarray) -> np.ndarray:
    return np.array([(x, y, z) for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])


def box_in_view(camera: PinholeView, lo: Sequence[float], hi: Sequence[float]) -> bool:
    """True if an axis-aligned box (world, metres) may show in the image (its corners' bounding rectangle)."""
    uv, depth = project(_corners(lo, hi), camera.intrinsics, camera.world_from_camera)
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


def _view(kitchen: BulletParts, camera: PinholeView) -> _View:
    """What the camera would show: which objects and robot links have their bounding box in view, their poses
    and boxes. The static scene never changes (covers renew the kitchen's uid)."""
    bc = kitchen.bc
    shown: list[object] = [kitchen.uid]
    poses: list[list[float]] = []
    boxes: list[tuple[Sequence[float], Sequence[float]]] = []
    for body in kitchen.objects.values():
        lo, hi = bc.getAABB(body)
        if box_in_view(camera, lo, hi):
            pos, orn = bc.getBasePositionAndOrientation(body)
            shown.append(body)
            poses.append([*pos, *orn])
            boxes.append((lo, hi))
    rid = kitchen.robot_id
    links = list(range(bc.getNumJoints(rid)))
    for link, state in zip(links, bc.getLinkStates(rid, links), strict=True):
        lo, hi = bc.getAABB(rid, link)
        if box_in_view(camera, lo, hi):
            shown.append((rid, link))
            poses.append([*state[4], *state[5]])
            boxes.append((lo, hi))
    return _View(
        tuple(shown),
        np.asarray(poses, dtype=float).reshape(-1, 7),
        np.asarray(boxes, dtype=float).reshape(-1, 2, 3),
    )


def _moved(before: np.ndarray, now: np.ndarray) -> np.ndarray:
    """Per row: moved beyond REUSE_MAX_MOVE_M or turned beyond REUSE_MAX_TURN_RAD (pose rows, same bodies)."""
    moved = np.abs(now[:, :3] - before[:, :3]).max(axis=1)
    # Angle between unit quaternions q1, q2: 2 acos |q1 . q2|.
    dots = np.clip(np.abs(np.sum(now[:, 3:] * before[:, 3:], axis=1)), 0.0, 1.0)
    return (moved > REUSE_MAX_MOVE_M) | (2 * np.arccos(dots) > REUSE_MAX_TURN_RAD)


def _changed_boxes(before: _View, now: _View) -> np.ndarray:
    """World boxes (n, 2, 3) of what changed between two views of one kitchen: what left the view (where it was),
    what came into it (where it is), and what moved or turned beyond the reuse limits (both)."""
    old = {key: i for i, key in enumerate(before.keys[1:])}
    new = {key: i for i, key in enumerate(now.keys[1:])}
    out = [before.boxes[i] for key, i in old.items() if key not in new]
    out += [now.boxes[i] for key, i in new.items() if key not in old]
    both = [(old[key], i) for key, i in new.items() if key in old]
    if both:
        b, n = (np.array(ix) for ix in zip(*both, strict=True))
        moved = _moved(before.poses[b], now.poses[n])
        out += [before.boxes[j] for j in b[moved]] + [now.boxes[j] for j in n[moved]]
    return np.asarray(out, dtype=float).reshape(-1, 2, 3)


def dirty_window(camera: PinholeView, boxes: np.ndarray) -> Window | None:
    """The one pixel window around every world box (n, 2, 3) grown by PATCH_MARGIN_M, padded by PATCH_PAD_PX and
    clipped to the image (`dirty_windows` together); None when a box reaches behind the camera's near plane.
    A window of zero pixels (all boxes out of view) is returned as a 1 x 1 window at the origin."""
    windows = dirty_windows(camera, boxes)
    if windows is None:
        return None
    if not windows:
        return Window(0, 0, 1, 1)
    around = windows[0]
    for w in windows[1:]:
        around = _around(around, w)
    return around


def _rectangle(camera: PinholeView, lo: np.ndarray, hi: np.ndarray) -> Window | None:
    """The pixel window of one world box grown by PATCH_MARGIN_M and padded by PATCH_PAD_PX, clipped to the
    image; a 0 x 0 window when it is out of view; None when it reaches behind the near plane."""
    spec = camera.spec
    uv, depth = project(
        _corners(lo - PATCH_MARGIN_M, hi + PATCH_MARGIN_M), camera.intrinsics, camera.world_from_camera
    )
    if np.any(depth <= spec.near):
        return None
    x0 = max(0, int(np.floor(uv[:, 0].min())) - PATCH_PAD_PX)
    y0 = max(0, int(np.floor(uv[:, 1].min())) - PATCH_PAD_PX)
    x1 = min(spec.width, int(np.ceil(uv[:, 0].max())) + 1 + PATCH_PAD_PX)
    y1 = min(spec.height, int(np.ceil(uv[:, 1].max())) + 1 + PATCH_PAD_PX)
    return Window(x0, y0, max(0, x1 - x0), max(0, y1 - y0))


def _around(a: Window, b: Window) -> Window:
    x0, y0 = min(a.x0, b.x0), min(a.y0, b.y0)
    x1, y1 = max(a.x0 + a.width, b.x0 + b.width), max(a.y0 + a.height, b.y0 + b.height)
    return Window(x0, y0, x1 - x0, y1 - y0)


def dirty_windows(camera: PinholeView, boxes: np.ndarray) -> list[Window] | None:
    """Disjoint-enough pixel windows covering every world box (n, 2, 3), each grown as in `dirty_window`: a
    window per box, two merged into the rectangle around both wherever that costs at most WINDOW_COST_PX more
    pixels than rendering them apart (windows that still overlap are each rendered: the later one is pasted over
    the earlier). None when a box reaches behind the near plane (render the whole image); an empty list when no
    box is in view."""
    windows: list[Window] = []
    for lo, hi in np.asarray(boxes, dtype=float):
        w = _rectangle(camera, lo, hi)
        if w is None:
            return None
        if w.pixels:
            windows.append(w)
    merged = True
    while merged:
        merged = False
        for i in range(len(windows)):
            for j in range(i + 1, len(windows)):
                around = _around(windows[i], windows[j])
                if around.pixels <= windows[i].pixels + windows[j].pixels + WINDOW_COST_PX:
                    windows[i] = around
                    del windows[j]
                    merged = True
                    break
            if merged:
                break
    return windows


def _patched(
    kitchen: BulletParts, camera: PinholeView, windows: Sequence[Window], rgb: np.ndarray, depth: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """A copy of the last image (rgb, depth) with each of `windows` rendered anew (read-only arrays)."""
    rgb, depth = rgb.copy(), depth.copy()
    for window in windows:
        part_rgb, part_depth = _render(kitchen, camera, window)
        rows = slice(window.y0, window.y0 + window.height)
        cols = slice(window.x0, window.x0 + window.width)
        rgb[rows, cols] = part_rgb
        depth[rows, cols] = part_depth
    rgb.setflags(write=False)
    depth.setflags(write=False)
    return rgb, depth


def _window_projection(projection: Sequence[float], width: int, height: int, window: Window) -> list[float]:
    """PyBullet's (column-major) projection matrix narrowed to `window`: an off-axis frustum that maps the
    window's pixels to the whole viewport, so each pixel samples the scene exactly where the full image does."""
    P = np.asarray(projection, dtype=np.float64).reshape(4, 4).T
    # Normalised device coordinates of the window's edges (image row 0 is the top: NDC y = +1).
    left, right = -1 + 2 * window.x0 / width, -1 + 2 * (window.x0 + window.width) / width
    top, bottom = 1 - 2 * window.y0 / height, 1 - 2 * (window.y0 + window.height) / height
    A = np.eye(4)
    A[0, 0], A[0, 3] = 2 / (right - left), -(right + left) / (right - left)
    A[1, 1], A[1, 3] = 2 / (top - bottom), -(top + bottom) / (top - bottom)
    return (A @ P).T.flatten().tolist()


def _render(
    kitchen: BulletParts, camera: PinholeView, window: Window | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Noise-free RGB (h, w, 3) uint8 and metric depth (h, w) float32 of the kitchen as it is now: the whole image,
    or only `window` of it."""
    import pybullet as p

    s = camera.spec
    view = p.computeViewMatrix(s.position, s.target, s.up)
    proj = p.computeProjectionMatrixFOV(s.fov_deg, s.width / s.height, s.near, s.far)
    w, h = s.width, s.height
    if window is not None:
        proj = _window_projection(proj, s.width, s.height, window)
        w, h = window.width, window.height
    _, _, rgba, depth_buffer, _ = kitchen.bc.getCameraImage(
        w,
        h,
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
    rgb = np.ascontiguousarray(np.asarray(rgba, dtype=np.uint8).reshape(h, w, 4)[:, :, :3])
    buffer = np.asarray(depth_buffer, dtype=np.float64).reshape(h, w)
    # OpenGL's non-linear depth buffer to metric depth along the optical axis.
    depth = (s.far * s.near / (s.far - (s.far - s.near) * buffer)).astype(np.float32)
    rgb.setflags(write=False)
    depth.setflags(write=False)
    return rgb, depth
