"""The context of one execution: where the target stood, how crowded it was, and what the camera made of it.

Two kinds of figures. Where it stands (unit, tier, slot, clearance, neighbours) is read from the stocking plan and
the settled simulation: it describes the situation, the dataset's reader may use it as a feature. What was
perceived (detected, detected width and height) comes from the robot's own depth image, as a grounded
self-confidence estimator on a real robot would get it.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from scone_bt.config import ObjectSpec, SceneSpec
from scone_bt.perception.types import Detection, Frame
from scone_bt.world.stocking import Placement, footprint

__all__ = [
    "NEIGHBOUR_RADIUS_M",
    "ALONE_CLEARANCE_M",
    "ShelfContext",
    "shelf_context",
    "perceived_size",
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


@dataclass(frozen=True)
class ShelfContext:
    """Where the target stood when the robot looked.

    Attributes:
        unit: Shelf unit name.
        tier: Tier of that unit, 0 = lowest.
        slot: Index of the nearest slot in SceneSpec.slots() (0-based over all units).
        clearance_m: Gap between the target's side and the nearest product on its tier along the tier, metres
            (ALONE_CLEARANCE_M when alone on the tier).
        neighbours: Products whose centre is within NEIGHBOUR_RADIUS_M of the target's.
    """

    unit: str
    tier: int
    slot: int
    clearance_m: float
    neighbours: int


def shelf_context(
    scene: SceneSpec,
    target: str,
    placements: Mapping[str, Placement],
    specs: Mapping[str, ObjectSpec],
    positions: Mapping[str, Sequence[float]],
) -> ShelfContext:
    """The target's shelf context from the stocking plan (unit, tier, yaw) and the settled positions (m)."""
    here = placements[target]
    units = {u.name: u for u in scene.shelves}
    unit = units[here.unit]
    slots = scene.slots()
    p = np.asarray(positions[target], dtype=float)
    slot = int(np.argmin([np.hypot(s.position[0] - p[0], s.position[1] - p[1]) for s in slots]))

    def along(name: str) -> tuple[float, float]:
        """Centre along the tier (v) and half the footprint along it, metres."""
        q = positions[name]
        _, v = unit.to_unit(float(q[0]), float(q[1]))
        # The yaw the product stands at relative to the unit (a quarter-turned box is wider along v).
        yaw = placements[name].yaw - unit.facing_yaw
        return v, footprint(specs[name], yaw)[1] / 2

    v0, half0 = along(target)
    gaps = [
        abs(v - v0) - half - half0
        for name, pl in placements.items()
        if name != target and pl.unit == here.unit and pl.tier == here.tier
        for v, half in [along(name)]
    ]
    clearance = max(0.0, min(gaps)) if gaps else ALONE_CLEARANCE_M
    neighbours = sum(
        1
        for name, q in positions.items()
        if name != target and float(np.linalg.norm(np.asarray(q, dtype=float) - p)) <= NEIGHBOUR_RADIUS_M
    )
    return ShelfContext(here.unit, here.tier, slot, round(float(clearance), 4), neighbours)


def surface_below(scene: SceneSpec, x: float, y: float, z: float) -> float | None:
    """Height of the highest shelf step under (x, y) that lies below z (metres), from the scene file."""
    best = None
    for unit in scene.shelves:
        u, v = unit.to_unit(x, y)
        if not unit.span[0] <= v <= unit.span[1]:
            continue
        for tier in unit.tiers:
            if (
                abs(u - tier.center) <= unit.tier_depth / 2
                and tier.top_z < z
                and (best is None or tier.top_z > best)
            ):
                best = tier.top_z
    return best


def perceived_size(frame: Frame, det: Detection, scene: SceneSpec) -> tuple[float, float] | None:
    """Width (narrowest horizontal extent of the lid) and height of a detected product from the depth image, m.

    The lid is the connected patch of depth points within _LID_BAND_M of the detected top face around the marker;
    its width is its extent across the narrower principal axis. The height is the top face above the shelf step
    under it (the robot knows its shelving from the scene file). None if the lid cannot be measured.
    """
    from scipy import ndimage

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
    labels, count = ndimage.label(lid.reshape(z.shape))
    if count == 0:
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
    extents = np.percentile(proj, 99, axis=0) - np.percentile(proj, 1, axis=0)
    width = float(min(extents))
    surface = surface_below(scene, float(top[0]), float(top[1]), float(top[2]))
    height = float(top[2] - surface) if surface is not None else float("nan")
    return round(width, 4), round(height, 4)
