"""The context of one execution: where the target stood, how crowded it was, and what the camera made of it.

Two kinds of figures. Where it stands (unit, tier, slot, clearance, neighbours) is read from the stocking plan and
the settled simulation: it describes the situation, the dataset's reader may use it as a feature. What was
perceived (detected, detected width and height) comes from the robot's own depth image, as a grounded
self-confidence estimator on a real robot would get it: `perceived_size` and `surface_below` are the episode's own
(scone_bt.perception.context), re-exported here.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from scone_bt.config import ObjectSpec, SceneSpec
from scone_bt.perception.context import ALONE_CLEARANCE_M, NEIGHBOUR_RADIUS_M, perceived_size, surface_below
from scone_bt.world.stocking import Placement, footprint

__all__ = [
    "NEIGHBOUR_RADIUS_M",
    "ALONE_CLEARANCE_M",
    "ShelfContext",
    "shelf_context",
    "perceived_size",
    "surface_below",
]


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
