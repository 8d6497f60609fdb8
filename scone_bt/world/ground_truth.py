"""Ground truth a simulated kitchen reads from its own state, whatever engine runs it: what stands on the table,
on a shelf, and where the table has room (the simulated human, the outcome sensor and the test rig use it).

`GroundTruth` needs only the kitchen's configuration, its products (`specs`, `objects`) and `object_state`; the
MuJoCo kitchen (`world.mj_kitchen`) takes these from it. The rules are those of the PyBullet `world.Kitchen`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from scone_bt.config import KitchenConfig, ObjectSpec

if TYPE_CHECKING:
    from scone_bt.motion.collision import Obstacle

__all__ = ["GroundTruth", "ObjectState", "rotation_of", "yaw_of"]


@dataclass(frozen=True)
class ObjectState:
    """Ground-truth pose of one product: position (m) and quaternion (x, y, z, w)."""

    name: str
    body_id: int
    position: tuple[float, float, float]
    orientation: tuple[float, float, float, float]


def rotation_of(quaternion: tuple[float, float, float, float]) -> np.ndarray:
    """(3, 3) rotation of a unit quaternion (x, y, z, w)."""
    x, y, z, w = quaternion
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def yaw_of(quaternion: tuple[float, float, float, float]) -> float:
    """The heading (rotation about z, radians) of a quaternion (x, y, z, w), as roll-pitch-yaw angles give it."""
    x, y, z, w = quaternion
    return math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))


class GroundTruth:
    """The kitchen's ground-truth queries over ``config``, ``specs``, ``objects`` and ``object_state``."""

    config: KitchenConfig
    specs: dict[str, ObjectSpec]
    objects: Mapping[str, int]

    def object_state(self, name: str) -> ObjectState:
        raise NotImplementedError

    def is_on_table(self, name: str) -> bool:
        """True if the object rests upright on the table top (ground truth)."""
        (cx, cy, cz), (sx, sy, sz) = self.config.scene.table
        st = self.object_state(name)
        x, y, z = st.position
        spec = self.specs[name]
        inside = abs(x - cx) <= sx / 2 and abs(y - cy) <= sy / 2
        resting = abs(z - (cz + sz / 2) - spec.height / 2) < 0.03
        return inside and resting and bool(rotation_of(st.orientation)[2, 2] > 0.9)

    def objects_on_table(self) -> frozenset[str]:
        """Every product resting upright on the table top."""
        return frozenset(n for n in self.objects if self.is_on_table(n))

    def is_on_shelf(self, name: str) -> bool:
        """True if the object stands above the footprint of a shelf unit."""
        return self.config.scene.on_shelf(self.object_state(name).position, margin=0.0)

    def products_at(self, spot: Obstacle, margin: float) -> tuple[Obstacle, ...]:
        """Products standing on the table within ``margin`` (m) of the upright shape ``spot``, as obstacles."""
        from scone_bt.motion.collision import Obstacle
        from scone_bt.motion.placement import Footprint, footprint_gaps
        from scone_bt.motion.placement_search import obstacle_footprint

        shape = obstacle_footprint(spot)
        near: list[tuple[str, Footprint, ObjectState]] = []
        for n in self.objects:
            if n == spot.name:
                continue
            st = self.object_state(n)
            x, y, _z = st.position
            reach = shape.radius + float(np.hypot(*self.specs[n].size[:2])) / 2 + margin
            if (x - shape.x) ** 2 + (y - shape.y) ** 2 > reach * reach or not self.is_on_table(n):
                continue
            near.append((n, Footprint.of(self.specs[n], x, y, yaw_of(st.orientation)), st))
        if not near:
            return ()
        gaps = footprint_gaps(
            np.array([[shape.x, shape.y]]), np.array([shape.yaw]), shape, [f for _, f, _ in near]
        )[0]
        out = []
        for (n, _, st), gap in zip(near, gaps, strict=True):
            if gap < margin:
                pose = np.eye(4)
                pose[:3, :3] = rotation_of(st.orientation)
                pose[:3, 3] = st.position
                spec = self.specs[n]
                out.append(Obstacle(n, spec.shape, spec.size, pose))
        return tuple(out)

    def free_place_spot(self, spec: ObjectSpec | None = None) -> tuple[float, float, float] | None:
        """A free table spot (x, y, table top z): the configured spots first, then a 2 cm grid (`world.Kitchen`)."""
        from scone_bt.motion.placement import Footprint, TableRegion, clear_spots

        scene = self.config.scene
        table = TableRegion.from_scene(scene)
        (cx, cy), (sx, sy) = table.center, table.size
        top = table.top_z
        standing = []
        for n in self.objects:
            st = self.object_state(n)
            x, y, z = st.position
            if top - 0.05 <= z <= top + 0.3:
                standing.append(Footprint.of(self.specs[n], x, y, yaw_of(st.orientation)))
        grid = [
            (float(x), float(y))
            for x in np.arange(cx - sx / 2 + 0.04, cx + sx / 2 - 0.04 + 1e-9, 0.02)
            for y in sorted(np.arange(cy - sy / 2 + 0.04, cy + sy / 2 - 0.04 + 1e-9, 0.02), key=abs)
        ]
        points = np.array([*scene.place_spots, *grid], dtype=float)
        if spec is None:
            near = [Footprint(f.name, f.x, f.y, 0.07, f.height) for f in standing]
            clear = clear_spots(table, near, Footprint("spot", 0.0, 0.0, 0.0, 0.0), points, 0.0, 1e-9)
        else:
            clear = clear_spots(table, standing, Footprint.of(spec), points, 0.0, 0.01)
        free = np.flatnonzero(clear.free)
        if not len(free):
            return None
        x, y = points[free[0]]
        return (float(x), float(y), top)
