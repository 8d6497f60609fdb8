"""Ground truth the benchmarks read from a MuJoCo kitchen (MuJoCo adapter): what a camera's rays reach first.

`perception.evaluation.ground_truth` counts a product's marker as unoccluded when rays from the camera reach each of
its sample points on the product itself; on PyBullet it asks ``rayTestBatch``, on MuJoCo this module's `first_bodies`
(``mujoco.mj_ray`` over every geom, the products' drawn caps and markers included, as PyBullet's visual shapes are
not: the drawn boxes sit on the product's own body, so the body that is hit is the same).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

__all__ = ["first_bodies"]


def first_bodies(kitchen: Any, eye: Sequence[float], points: np.ndarray) -> list[int]:
    """For each segment from ``eye`` to a point (world, metres), the body it hits first, or -1 when none.

    Args:
        kitchen: A `world.mj_kitchen.MjKitchen` (its model, data and mujoco module).
        eye: Where the rays start (the camera), metres.
        points: (n, 3) where each ray ends, metres.
    """
    mj, model, data = kitchen.mujoco, kitchen.model, kitchen.data
    start = np.asarray(eye, dtype=np.float64)
    geom = np.zeros(1, dtype=np.int32)
    out = []
    for point in np.asarray(points, dtype=np.float64):
        # The distance comes back in units of the vector's length: a hit beyond 1 lies past the point.
        distance = mj.mj_ray(model, data, start, point - start, None, 1, -1, geom)
        out.append(int(model.geom_bodyid[geom[0]]) if 0 <= distance <= 1.0 and geom[0] >= 0 else -1)
    return out
