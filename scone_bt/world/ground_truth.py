"""What every simulated kitchen shares, whatever engine runs it: the ground truth it reads from its own state (what
stands on the table, on a shelf, where the table has room), and what is done to it from outside (stocking the
shelf, a person putting a product on the table or taking it away).

`GroundTruth` needs only the kitchen's configuration, its products (`specs`, `objects`), `object_state`,
`spawn_planned` and `place_object`; the PyBullet `world.Kitchen` and the MuJoCo `world.mj_kitchen.MjKitchen` take
the rest from it.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from scone_bt.config import KitchenConfig, ObjectSpec, RobotConfig
from scone_bt.errors import ConfigError, UnknownNameError
from scone_bt.stocking import Placement, plan_stocking

if TYPE_CHECKING:
    from scone_bt.config.robot import GripperSpec
    from scone_bt.motion.collision import Obstacle

__all__ = ["GroundTruth", "ObjectState", "rotation_of", "yaw_of"]

TABLE_BAND_M = (0.05, 0.3)
"""Metres below and above the table top a product's centre may be to count as on the table (standing, lying, or
just set down) for the looks at it (`free_place_spot`, `table_products`)."""


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
    """The kitchen's ground-truth queries and outside changes over ``config``, ``specs``, ``objects``,
    ``object_state``, ``spawn_planned`` and ``place_object``."""

    config: KitchenConfig
    robot_config: RobotConfig
    specs: dict[str, ObjectSpec]
    objects: Mapping[str, int]

    PARK_Y_M = 3.0
    """Products taken out of the kitchen stand on the floor this far from the robot (out of every camera's view)."""

    def object_state(self, name: str) -> ObjectState:
        raise NotImplementedError

    def spawn_planned(
        self, specs: Sequence[ObjectSpec], places: Sequence[Placement]
    ) -> dict[str, tuple[float, float, float]]:
        raise NotImplementedError

    def place_object(self, name: str, surface: Sequence[float], yaw: float = 0.0) -> None:
        raise NotImplementedError

    # An engine may read a quaternion its own way: PyBullet's conversions differ from these in the last bit, and a
    # seeded PyBullet run must repeat exactly (`world.Kitchen` overrides both).
    def _yaw(self, orientation: tuple[float, float, float, float]) -> float:
        """The heading of an orientation (x, y, z, w): its rotation about z, radians (roll-pitch-yaw)."""
        return yaw_of(orientation)

    def _rotation(self, orientation: tuple[float, float, float, float]) -> np.ndarray:
        """The (3, 3) rotation of an orientation (x, y, z, w)."""
        return rotation_of(orientation)

    # ----------------------------------------------------------------------------------------- stocking
    def spawn(
        self, specs: Sequence[ObjectSpec], rng: np.random.Generator
    ) -> dict[str, tuple[float, float, float]]:
        """Stock the shelving (`plan_stocking`: heaviest lowest, facing the robot) and let the objects settle.

        Returns:
            name → surface point under the object's centre (x, y, z), metres.
        """
        self._refuse_present(specs)
        return self.spawn_planned(specs, plan_stocking(self.config.scene, specs, rng))

    def _refuse_present(self, specs: Sequence[ObjectSpec]) -> None:
        """The one-line error for a product already in the kitchen (`spawn_planned` calls it first)."""
        for spec in specs:
            if spec.name in self.objects:
                raise ConfigError(f"object {spec.name!r} is already in the kitchen")

    def _body(self, name: str) -> int:
        try:
            return self.objects[name]
        except KeyError:
            raise UnknownNameError("object in the kitchen", name, self.objects) from None

    def object_yaw(self, name: str) -> float:
        """The object's heading now: its rotation about z, radians (roll-pitch-yaw)."""
        return float(self._yaw(self.object_state(name).orientation))

    # ----------------------------------------------------------------------------------------- by hand
    def place_on_table(self, name: str) -> bool:
        """Put the object on a free table spot by hand (not by the robot); False when the table is full."""
        spot = self.free_place_spot(self.specs[name])
        if spot is None:
            return False
        self.place_object(name, spot, 0.0)
        return True

    def human_place_on_table(self, name: str) -> bool:
        """The simulated human carries the object to a free table spot (by hand, not by the robot)."""
        return self.place_on_table(name)

    def put_away(self, name: str) -> None:
        """The simulated human takes a product the recipe has used off the table, out of the kitchen."""
        self.park_object(name)

    def park_object(self, name: str) -> None:
        """Take the product out of the kitchen: it stands on the floor far from the shelving, table and cameras."""
        self._body(name)  # the one-line error for an unknown name
        index = list(self.objects).index(name)
        self.place_object(name, (0.5 * index, self.PARK_Y_M, self.config.scene.floor_z))

    def _replace_gripper(self, max_force: float | None, finger_friction: float | None) -> GripperSpec:
        """Set the robot file's gripper force limit (N per finger) and pad friction, ``None`` keeping a value
        (`set_gripper_properties`: a worn motor, greasy pads); returns the new gripper for the engine to apply."""
        import dataclasses

        g = self.robot_config.gripper
        g = dataclasses.replace(
            g,
            max_force=g.max_force if max_force is None else float(max_force),
            finger_friction=g.finger_friction if finger_friction is None else float(finger_friction),
        )
        self.robot_config = dataclasses.replace(self.robot_config, gripper=g)
        return g

    # ----------------------------------------------------------------------------------------- ground truth
    def is_on_table(self, name: str) -> bool:
        """True if the object rests upright on the table top (ground truth)."""
        (cx, cy, cz), (sx, sy, sz) = self.config.scene.table
        st = self.object_state(name)
        x, y, z = st.position
        spec = self.specs[name]
        inside = abs(x - cx) <= sx / 2 and abs(y - cy) <= sy / 2
        resting = abs(z - (cz + sz / 2) - spec.height / 2) < 0.03
        return inside and resting and bool(self._rotation(st.orientation)[2, 2] > 0.9)

    def standing_position(self, name: str) -> tuple[float, float, float] | None:
        """Where the product stands upright (its centre, world frame, metres), wherever that is; None when it lies
        or leans more than about 25° (ground truth, as `is_on_table`: the outcome sensor's look at it)."""
        st = self.object_state(name)
        return st.position if bool(self._rotation(st.orientation)[2, 2] > 0.9) else None

    def objects_on_table(self) -> frozenset[str]:
        """Every product resting upright on the table top (ground truth, as `is_on_table`)."""
        return frozenset(n for n in self.objects if self.is_on_table(n))

    def is_on_shelf(self, name: str) -> bool:
        """True if the object stands above the footprint of a shelf unit."""
        return self.config.scene.on_shelf(self.object_state(name).position, margin=0.0)

    def products_at(self, spot: Obstacle, margin: float) -> tuple[Obstacle, ...]:
        """Products standing on the table within ``margin`` (m) of the upright shape ``spot``, as obstacles where
        they stand (ground truth: the simulation's look at the spot)."""
        from scone_bt.motion.placement import Footprint, footprint_gaps
        from scone_bt.motion.placement_search import obstacle_footprint

        shape = obstacle_footprint(spot)
        near: list[tuple[str, Footprint, ObjectState]] = []
        for n in self.objects:
            if n == spot.name:
                continue
            st = self.object_state(n)
            x, y, _z = st.position
            # Beyond both footprints' covering circles: cannot be near (most products).
            reach = shape.radius + float(np.hypot(*self.specs[n].size[:2])) / 2 + margin
            if (x - shape.x) ** 2 + (y - shape.y) ** 2 > reach * reach or not self.is_on_table(n):
                continue
            near.append((n, Footprint.of(self.specs[n], x, y, self._yaw(st.orientation)), st))
        if not near:
            return ()
        gaps = footprint_gaps(
            np.array([[shape.x, shape.y]]), np.array([shape.yaw]), shape, [f for _, f, _ in near]
        )[0]
        return tuple(
            self._obstacle(n, st) for (n, _, st), gap in zip(near, gaps, strict=True) if gap < margin
        )

    def table_products(self) -> tuple[Obstacle, ...]:
        """Every product standing on the table, as its shape where it stands (ground truth: the simulation's look
        at the table; upright or not, as long as it lies on the table top)."""
        (cx, cy, cz), (sx, sy, sz) = self.config.scene.table
        return tuple(
            self._obstacle(n, st)
            for n, st in self._near_table_top(cz + sz / 2)
            if abs(st.position[0] - cx) <= sx / 2 and abs(st.position[1] - cy) <= sy / 2
        )

    def _near_table_top(self, top: float) -> Iterator[tuple[str, ObjectState]]:
        """Each product whose centre lies within `TABLE_BAND_M` of the table top (``top``, metres)."""
        below, above = TABLE_BAND_M
        for n in self.objects:
            st = self.object_state(n)
            if top - below <= st.position[2] <= top + above:
                yield n, st

    def _obstacle(self, name: str, state: ObjectState) -> Obstacle:
        """The product's collision shape where ``state`` has it."""
        from scone_bt.motion.collision import Obstacle

        pose = np.eye(4)
        pose[:3, :3] = self._rotation(state.orientation)
        pose[:3, 3] = state.position
        spec = self.specs[name]
        return Obstacle(name, spec.shape, spec.size, pose)

    def free_place_spot(self, spec: ObjectSpec | None = None) -> tuple[float, float, float] | None:
        """A free table spot (x, y, table top z), ground truth: what the human sees when putting something down.

        The configured place spots come first, then a 2 cm grid over the table top (nearest the robot first), so
        a long recipe still finds room once the spots are taken. Without `spec` a spot is free when no object
        stands within 7 cm of it; with it, when the product's footprint (a box's rectangle, put down square to
        the table; a round product's circle) clears every footprint standing on the table by 1 cm and stays on
        the table. The test is the robot's own (`motion.placement.clear_spots`), fed with the simulator's truth.
        """
        from scone_bt.motion.placement import Footprint, TableRegion, clear_spots

        scene = self.config.scene
        table = TableRegion.from_scene(scene)
        (cx, cy), (sx, sy) = table.center, table.size
        top = table.top_z
        standing = [
            Footprint.of(self.specs[n], st.position[0], st.position[1], self._yaw(st.orientation))
            for n, st in self._near_table_top(top)
        ]
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
