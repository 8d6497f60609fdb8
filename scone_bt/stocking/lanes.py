"""The lane a product takes along a shelf tier: its footprint along the tier plus room for a finger on each side.

Pure geometry (numpy only), so it is tested without a simulator and usable by capacity figures. A lane is at least
one slot pitch (`LANE_MIN_M`). A box deeper than its tier whose other side fits is turned a quarter (`turn`); a
product deeper than its tier by more than MAX_OVERHANG_M (`too_deep`) stands against the riser, on a lowest tier
when one has room (`scone_bt.stocking.place`).
"""

from __future__ import annotations

import numpy as np

from scone_bt.config.catalogue import ObjectSpec, Shape
from scone_bt.config.footprint import footprint
from scone_bt.config.scene import SceneSpec, ShelfUnit

__all__ = [
    "FINGER_ROOM_M",
    "LANE_MIN_M",
    "MAX_OVERHANG_M",
    "TierKey",
    "fits_shelf",
    "lane_width",
    "lowest_first",
    "segment",
    "tier_length",
    "too_deep",
    "turn",
]

LANE_MIN_M = 0.10
"""The narrowest lane: the slot pitch of perception/kitchen.yaml."""
FINGER_ROOM_M = 0.03
"""Free space beside a product for a finger (both sides together), metres."""
MAX_OVERHANG_M = 0.03
"""How far a product may stick out over the front edge of its tier, metres."""

TierKey = tuple[str, int]
"""(shelf unit name, tier index): one tier of the shelving."""


def turn(spec: ObjectSpec, depth: float) -> float:
    """0, or a quarter turn (radians) for a box too deep for the tier (``depth``, metres) whose other side fits."""
    sx, sy, _ = spec.size
    if spec.shape == Shape.BOX and sx > depth + MAX_OVERHANG_M and sy < sx:
        return np.pi / 2
    return 0.0


def segment(unit: ShelfUnit, tier: int) -> tuple[float, float]:
    """The stretch of a tier products may occupy (along the tier, metres): from half a pitch before its first
    slot to after its last."""
    slots = unit.tiers[tier].slots
    return min(slots) - LANE_MIN_M / 2, max(slots) + LANE_MIN_M / 2


def tier_length(unit: ShelfUnit, tier: int) -> float:
    """How much lane a tier holds, metres."""
    a, b = segment(unit, tier)
    return b - a


def lane_width(spec: ObjectSpec, unit: ShelfUnit) -> float:
    """The lane a product facing the robot takes along a tier of ``unit`` (finger room included), metres."""
    _, v = footprint(spec, turn(spec, unit.tier_depth))
    return max(LANE_MIN_M, v + FINGER_ROOM_M)


def fits_shelf(spec: ObjectSpec, scene: SceneSpec) -> bool:
    """True if the product can stand on some tier (depth with the allowed overhang, width within the tier)."""
    for unit in scene.shelves:
        u, v = footprint(spec, turn(spec, unit.tier_depth))
        if u <= unit.tier_depth + 2 * MAX_OVERHANG_M and any(
            max(LANE_MIN_M, v + FINGER_ROOM_M) <= tier_length(unit, i) for i in range(len(unit.tiers))
        ):
            return True
    return False


def too_deep(spec: ObjectSpec, scene: SceneSpec) -> bool:
    """True if the product, square to the riser, sticks out over the front edge of a tier by more than allowed."""
    return any(
        footprint(spec, turn(spec, unit.tier_depth))[0] > unit.tier_depth + MAX_OVERHANG_M
        for unit in scene.shelves
    )


def lowest_first(scene: SceneSpec) -> list[TierKey]:
    """Every (unit, tier), lowest tier first (units in file order at equal heights)."""
    keys = [(u.name, i, t.top_z) for u in scene.shelves for i, t in enumerate(u.tiers)]
    return [(name, i) for name, i, _ in sorted(keys, key=lambda k: k[2])]
