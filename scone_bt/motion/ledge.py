"""The lowest tier a product stands on (`Ledge`): where a flat pack is slid to, and pinched from (`motion.slide`).

Pure geometry over the kitchen file's shelf units; it sits apart from `motion.slide` because a pick request names
the ledge its pinch is planned for (`motion.pick_request.PickPlaceRequest.pinch`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from scone_bt.config.scene import SceneSpec, ShelfTier, ShelfUnit

__all__ = ["Ledge", "ledge_of"]


@dataclass(frozen=True)
class Ledge:
    """The lowest tier a product stands on, and where its front edge is.

    Attributes:
        unit: The shelf unit.
        tier: Its lowest tier.
    """

    unit: ShelfUnit
    tier: ShelfTier

    @property
    def front_u(self) -> float:
        """The tier's front edge (the side towards the robot) along the unit's u axis, metres."""
        return self.tier.center - self.unit.tier_depth / 2

    @property
    def inward(self) -> np.ndarray:
        """(3,) horizontal unit vector along the unit's u axis: from the robot into the shelf."""
        yaw = self.unit.facing_yaw
        return np.array([math.cos(yaw), math.sin(yaw), 0.0])

    def uv(self, point: np.ndarray | tuple[float, ...]) -> tuple[float, float]:
        """The unit-frame (u, v) of a world point."""
        return self.unit.to_unit(float(point[0]), float(point[1]))

    def world(self, u: float, v: float, z: float) -> np.ndarray:
        """(3,) the world point at (u, v) in the unit's frame and height z."""
        x, y = self.unit.to_world(u, v)
        return np.array([x, y, z])


def ledge_of(scene: SceneSpec, bottom: tuple[float, float, float], margin: float = 0.02) -> Ledge | None:
    """The lowest tier whose top the point ``bottom`` (a product's bottom centre, world frame) stands on, within
    ``margin`` metres; None on a higher tier, the table or nowhere."""
    for unit in scene.shelves:
        lowest = min(unit.tiers, key=lambda t: t.top_z)
        u, v = unit.to_unit(bottom[0], bottom[1])
        on_top = abs(bottom[2] - lowest.top_z) <= margin
        across = abs(u - lowest.center) <= unit.tier_depth / 2 + margin
        along = unit.span[0] - margin <= v <= unit.span[1] + margin
        if on_top and across and along:
            return Ledge(unit, lowest)
    return None
