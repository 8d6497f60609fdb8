"""How much room a product takes on a shelf tier: pure geometry of the catalogue's sizes.

Stocking the shelf (`stocking.place`), the test rig and the robot's own perceived context (`perception.context`)
all measure a product's footprint the same way.
"""

from __future__ import annotations

import numpy as np

from scone_bt.config.catalogue import ObjectSpec, Shape

__all__ = ["footprint"]


def footprint(spec: ObjectSpec, yaw: float) -> tuple[float, float]:
    """Extent of the product along a unit's (u, v) axes when turned by `yaw` from facing the robot, metres."""
    sx, sy, _ = spec.size
    if spec.shape != Shape.BOX:
        return sx, sx
    c, s = abs(np.cos(yaw)), abs(np.sin(yaw))
    return sx * c + sy * s, sx * s + sy * c
