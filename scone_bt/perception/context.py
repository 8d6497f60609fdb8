"""The execution context of a candidate action, from one tick's perception (what a grounded κ̂ sees).

For each detected target: its shelf tier (the step under the detected top face, from the scene file), the clearance
along its tier to the nearest detected product there, how many detected products stand near it, and its width,
height, depth and lid fill (round or rectangular) measured in the depth image. Everything comes from the robot's own detections and frames, never from the
simulator's state, so it is what the robot knows when it decides (and what a real robot would compute).

This is the one context function: the tree's gate calls it every tick (`ContextExtractor`), the self-confidence
dataset generator records its result for each execution's target (scone_bt.benchmarks.self_confidence.generate,
`perceived_context`), and the evaluation and the gate benchmark read those recorded columns back unchanged
(`evaldata.decision_time_context`). So κ̂ is trained, evaluated and consulted on the same definition.
The catalogue entry the detector named gives each product's footprint and height, and the detected yaw its
turn on the tier.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import replace
from typing import NamedTuple

import numpy as np

from scone_bt.config import Catalogue, SceneSpec
from scone_bt.config.footprint import footprint
from scone_bt.experience.types import ROUND_FILL_BELOW, ExecutionContext
from scone_bt.perception.types import Detection, Frame

__all__ = [
    "ALONE_CLEARANCE_M",
    "DISC_SPAN",
    "RECTANGLE_SPAN",
    "PerceivedSize",
    "ContextExtractor",
    "NEIGHBOUR_RADIUS_M",
    "execution_contexts",
    "perceived_size",
    "shelf_place",
    "size_from_frames",
    "surface_below",
]

NEIGHBOUR_RADIUS_M = 0.15
"""A product whose centre is within this of the target's (3D, metres) counts as a neighbour."""
ALONE_CLEARANCE_M = 0.5
"""Clearance recorded for a target alone on its tier (metres): more than any grasp needs."""
_LID_BAND_M = 0.01
"""Depth points within this of the detected top face (metres, vertically) belong to the lid."""
_MAX_HALF_EXTENT_M = 0.15
"""Lid points farther than this from the detected centre (horizontally, metres) belong to something else."""
_WINDOW_HALF_M = 0.06
"""Half side of the square around a detected top face whose image box frames the lid (perceived_size widens it)."""
_VISIBLE_TOLERANCE_M = 0.02
"""A top face is visible in a frame when the depth at its pixel is within this of its distance, metres."""
_SAME_PLACE_M = 0.005
"""A product detected within this of where its size was measured (metres, per axis) is not measured again."""
_TRIM = 1.0
"""The lid's width is the range between this percentile of its points and 100 minus it, across its principal
axis: a stray point at its rim does not widen it."""
RECTANGLE_SPAN = 0.98
"""The share of a rectangle's side that the 1–99 % range of points spread evenly over it spans."""
DISC_SPAN = 0.93433
"""The share of a disc's diameter that the 1–99 % range of points spread evenly over it spans: the root of
½ + (x·√(1 − x²) + asin x) / π = 0.99, the disc's cumulative share across one axis (tests/perception/test_shape.py
checks it). The range trims a round lid more than a rectangular one, so a round lid's range is scaled by
RECTANGLE_SPAN / DISC_SPAN: without it an 8.5 cm eggplant measured 7.9 cm in MuJoCo, narrower than the gripper's
8 cm opening, and the robot tried to grasp it."""
_DISC_ASPECT_AT_MOST = 1.15
"""A lid is scaled as a disc only if its two ranges are within this ratio (a cylinder's: 1.02 median, 1.04 at the
95th percentile): a box whose fill looks round (seen askew, or a neighbour's edge in its patch) is 1.25–1.85
long, and scaling it would widen a 7.5 cm tin past the gripper's opening."""


def surface_below(scene: SceneSpec, x: float, y: float, z: float) -> float | None:
    """Height of the highest shelf step under (x, y) that lies below z (metres), from the scene file."""
    place = shelf_place(scene, (x, y, z))
    if place is None:
        return None
    unit, tier = place
    return next(u for u in scene.shelves if u.name == unit).tiers[tier].top_z


def shelf_place(scene: SceneSpec, position: Sequence[float]) -> tuple[str, int] | None:
    """(unit name, tier index; 0 = lowest) of the highest shelf step under a point and below it, or None."""
    x, y, z = (float(c) for c in position[:3])
    best: tuple[float, str, int] | None = None
    for unit in scene.shelves:
        u, v = unit.to_unit(x, y)
        if not unit.span[0] <= v <= unit.span[1]:
            continue
        for i, tier in enumerate(unit.tiers):
            if (
                abs(u - tier.center) <= unit.tier_depth / 2
                and tier.top_z < z
                and (best is None or tier.top_z > best[0])
            ):
                best = (tier.top_z, unit.name, i)
    return None if best is None else (best[1], best[2])


class PerceivedSize(NamedTuple):
    """What the depth image says of a product's shape (metres; NaN height where no shelf step lies under it).

    Attributes:
        width: Narrowest horizontal extent of the lid (what the fingers must span).
        height: Top face above the shelf step under it.
        depth: Longest horizontal extent of the lid (its other principal axis).
        fill: The lid's area (its convex hull) over the rectangle of its principal extents: π/4 ≈ 0.79 for a
            round lid (a cylinder), about 1 for a rectangular one (a box).
    """

    width: float
    height: float
    depth: float = float("nan")
    fill: float = float("nan")


def perceived_size(frame: Frame, det: Detection, scene: SceneSpec) -> PerceivedSize | None:
    """Width, height, depth and fill (`PerceivedSize`) of a detected product from the depth image.

    The lid is the connected patch of depth points within _LID_BAND_M of the detected top face around the marker;
    its width and depth are its extents across and along its principal axes (the width as the 1–99 % range of
    its points, scaled for a round lid: DISC_SPAN), and its fill the area of its convex hull over their product.
    The height is the top face above the shelf step under it (the robot knows its shelving from the scene file).
    None if the lid cannot be measured.
    """
    import cv2  # the marker detector's library: already loaded, unlike scipy (a third of a second to import)

    h, w = frame.depth.shape
    x0, y0, x1, y1 = det.bbox
    # Half as much again around the object's box: the lid must lie inside whatever the detector's box guessed.
    mx, my = (x1 - x0) // 2 + 2, (y1 - y0) // 2 + 2
    x0, y0, x1, y1 = max(0, x0 - mx), max(0, y0 - my), min(w - 1, x1 + mx), min(h - 1, y1 + my)
    if x1 <= x0 or y1 <= y0:
        return None
    vs, us = np.mgrid[y0 : y1 + 1, x0 : x1 + 1]
    z = frame.depth[y0 : y1 + 1, x0 : x1 + 1].astype(np.float64)
    rays = np.stack([us, vs, np.ones_like(us)], axis=-1).reshape(-1, 3) @ np.linalg.inv(frame.intrinsics).T
    cam = rays * z.reshape(-1, 1)
    world = cam @ frame.world_from_camera[:3, :3].T + frame.world_from_camera[:3, 3]
    top = np.asarray(det.position, dtype=float)
    horizontal = np.hypot(world[:, 0] - top[0], world[:, 1] - top[1])
    lid = (
        (np.abs(world[:, 2] - top[2]) <= _LID_BAND_M)
        & (horizontal <= _MAX_HALF_EXTENT_M)
        & (z.reshape(-1) > 0)
    )
    # 4-connected patches, as scipy.ndimage.label's default (only the partition matters, not the numbering).
    count, labels = cv2.connectedComponents(lid.reshape(z.shape).astype(np.uint8), connectivity=4)
    if count <= 1:  # label 0 is the background
        return None
    flat = labels.reshape(-1)
    # The patch that holds the point nearest the detected centre.
    candidates = np.flatnonzero(flat > 0)
    label = flat[candidates[np.argmin(horizontal[candidates])]]
    pts = world[flat == label, :2]
    if len(pts) < 10:
        return None
    centred = pts - pts.mean(axis=0)
    _, _, vt = np.linalg.svd(centred, full_matrices=False)
    proj = centred @ vt.T
    extents = np.percentile(proj, 100 - _TRIM, axis=0) - np.percentile(proj, _TRIM, axis=0)
    # The longer axis from the outermost points (the 1–99 % range cuts a few millimetres off a long lid); the
    # patch is one connected component of the lid band, so there are no strays to trim.
    depth = float(max(proj.max(axis=0) - proj.min(axis=0)))
    hull = cv2.convexHull(proj.astype(np.float32))
    box = float(np.prod(proj.max(axis=0) - proj.min(axis=0)))
    fill = float(cv2.contourArea(hull)) / box if box > 0 else float("nan")
    round_lid = fill < ROUND_FILL_BELOW and max(extents) <= _DISC_ASPECT_AT_MOST * min(extents)
    width = float(min(extents)) * (RECTANGLE_SPAN / DISC_SPAN if round_lid else 1.0)
    surface = surface_below(scene, float(top[0]), float(top[1]), float(top[2]))
    height = float(top[2] - surface) if surface is not None else float("nan")
    return PerceivedSize(round(width, 4), round(height, 4), round(depth, 4), round(fill, 3))


def _project(frame: Frame, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Pixel (u, v) and camera depth of world points (n, 3)."""
    camera_from_world = np.linalg.inv(frame.world_from_camera)
    cam = points @ camera_from_world[:3, :3].T + camera_from_world[:3, 3]
    z = cam[:, 2]
    uv = cam @ frame.intrinsics.T
    with np.errstate(divide="ignore", invalid="ignore"):
        return uv[:, :2] / uv[:, 2:3], z


def size_from_frames(det: Detection, frames: Sequence[Frame], scene: SceneSpec) -> PerceivedSize | None:
    """perceived_size from the nearest frame in which the detected top face is visible, or None.

    A merged detection does not say which camera saw it, so its box is rebuilt per frame: the image box of a
    square of ±_WINDOW_HALF_M around the top face, in each frame where the depth at the face's pixel agrees with
    its distance (not hidden, inside the image); the nearest such camera measures first.
    """
    top = np.asarray(det.position, dtype=float)
    d = _WINDOW_HALF_M
    corners = top + np.array([[dx, dy, 0.0] for dx in (-d, d) for dy in (-d, d)])
    views: list[tuple[float, Frame, tuple[int, int, int, int]]] = []
    for frame in frames:
        (uv,), (z,) = _project(frame, top[None])
        h, w = frame.depth.shape
        if not z > 0 or not (0 <= uv[0] < w and 0 <= uv[1] < h):
            continue
        if abs(float(frame.depth[int(uv[1]), int(uv[0])]) - z) > _VISIBLE_TOLERANCE_M:
            continue
        box_uv, box_z = _project(frame, corners)
        if not np.all(box_z > 0):
            continue
        x0, y0 = np.floor(box_uv.min(axis=0)).astype(int)
        x1, y1 = np.ceil(box_uv.max(axis=0)).astype(int)
        views.append((float(z), frame, (int(x0), int(y0), int(x1), int(y1))))
    for _, frame, bbox in sorted(views, key=lambda v: v[0]):
        size = perceived_size(frame, replace(det, bbox=bbox), scene)
        if size is not None:
            return size
    return None


SizeMeasure = Callable[[Detection, Sequence[Frame], SceneSpec], PerceivedSize | None]
"""Width, height, depth and fill of a detected product from the frames (None: not measurable)."""


def execution_contexts(
    targets: Sequence[Detection],
    detections: Sequence[Detection],
    frames: Mapping[str, Frame] | Sequence[Frame],
    scene: SceneSpec,
    catalogue: Catalogue,
    measure: SizeMeasure = size_from_frames,
) -> dict[str, ExecutionContext]:
    """The ExecutionContext of each target (by name) from one tick's detections and camera frames.

    Args:
        targets: The detections the robot might act on (its candidates).
        detections: Everything detected this tick (the targets' neighbours); products on the table are ignored.
        frames: The tick's camera frames (by camera name, or a sequence) for the perceived size.
        scene: The kitchen's shelving.
        catalogue: Names each detection's product (its footprint and height).
        measure: Measures a target's width and height in the frames (default: size_from_frames).

    `detected` is True for every target: a candidate exists only because its marker was seen.
    """
    frame_list = list(frames.values()) if isinstance(frames, Mapping) else list(frames)
    shelf = [d for d in detections if not scene.on_table(d.position)]
    units = {u.name: u for u in scene.shelves}
    places = {d.name: shelf_place(scene, d.position) for d in shelf}

    def centre(det: Detection) -> np.ndarray:
        top = np.asarray(det.position, dtype=float)
        return top - np.array([0.0, 0.0, catalogue.get(det.name).height / 2])

    def along(det: Detection, unit_name: str) -> tuple[float, float]:
        """Centre along the tier (v) and half the footprint along it, metres."""
        unit = units[unit_name]
        _, v = unit.to_unit(float(det.position[0]), float(det.position[1]))
        return v, footprint(catalogue.get(det.name), det.yaw - unit.facing_yaw)[1] / 2

    out: dict[str, ExecutionContext] = {}
    for target in targets:
        place = places.get(target.name) or shelf_place(scene, target.position)
        clearance = None
        if place is not None:
            v0, half0 = along(target, place[0])
            gaps = [
                abs(v - v0) - half - half0
                for d in shelf
                if d.name != target.name and places.get(d.name) == place
                for v, half in [along(d, place[0])]
            ]
            clearance = round(float(max(0.0, min(gaps))), 4) if gaps else ALONE_CLEARANCE_M
        c0 = centre(target)
        neighbours = sum(
            1
            for d in shelf
            if d.name != target.name and float(np.linalg.norm(centre(d) - c0)) <= NEIGHBOUR_RADIUS_M
        )
        size = measure(target, frame_list, scene)
        out[target.name] = ExecutionContext(
            shelf_tier=None if place is None else place[1],
            clearance_m=clearance,
            neighbours=neighbours,
            detected=True,
            detected_width_m=None if size is None else size[0],
            detected_height_m=None if size is None else (None if np.isnan(size[1]) else size[1]),
            detected_depth_m=_known(size, "depth"),
            detected_fill=_known(size, "fill"),
        )
    return out


def _known(size: PerceivedSize | tuple[float, ...] | None, field: str) -> float | None:
    """A field of a measured size, None when unmeasured or NaN (a measure that gives width and height only)."""
    value = getattr(size, field, None)
    return None if value is None or np.isnan(value) else float(value)


class ContextExtractor:
    """execution_contexts for one kitchen, measuring a product's size once per place it is detected at.

    The depth measurement is the costly part (milliseconds per product); a product that has not moved keeps its
    size, so it is measured again only when it is detected more than _SAME_PLACE_M away from where it was
    measured. A failed measurement is not kept (the arm may have hidden the lid for one look). Tier, clearance
    and neighbours are recomputed every call (neighbours come and go).

    Args:
        scene: The kitchen's shelving.
        catalogue: Names each detection's product.
    """

    def __init__(self, scene: SceneSpec, catalogue: Catalogue) -> None:
        self.scene = scene
        self.catalogue = catalogue
        self._sizes: dict[str, tuple[np.ndarray, PerceivedSize]] = {}
        self.measured = 0  # depth measurements made (the cache's misses)

    def _measure(self, det: Detection, frames: Sequence[Frame], scene: SceneSpec) -> PerceivedSize | None:
        where = np.asarray(det.position, dtype=float)
        known = self._sizes.get(det.name)
        if known is not None and np.all(np.abs(known[0] - where) <= _SAME_PLACE_M):
            return known[1]
        size = size_from_frames(det, frames, scene)
        self.measured += 1
        if size is not None:
            self._sizes[det.name] = (where, size)
        return size

    def __call__(
        self,
        targets: Sequence[Detection],
        detections: Sequence[Detection],
        frames: Mapping[str, Frame] | Sequence[Frame],
    ) -> dict[str, ExecutionContext]:
        """The ExecutionContext of each target by name (see execution_contexts)."""
        return execution_contexts(targets, detections, frames, self.scene, self.catalogue, self._measure)
