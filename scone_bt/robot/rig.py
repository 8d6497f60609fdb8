"""The test rig: what only a simulator or a lab rig can do to the world while the robot works, and nothing else.

A scenario (`scone_bt.scenario`) moves products, covers a camera or a lid, and degrades the robot only through
`World`, the seam a real robot's test rig would also provide (a person who moves things, a cloth, a weaker
gripper); the episode loop advances time and stocks the shelf through it, and the simulated human reads and
changes the world through its narrower part, `HumanWorld`. `SimWorld` implements it on the PyBullet simulation with
`world.Kitchen`'s public methods and the simulated robot's public components; scenario code never imports pybullet.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any, Protocol

from scone_bt.errors import ConfigError, UnknownNameError

if TYPE_CHECKING:
    import numpy as np

    from scone_bt.config import ObjectSpec, RobotConfig
    from scone_bt.motion.system import MotionSystem
    from scone_bt.perception.observe import Observer
    from scone_bt.world import Kitchen

__all__ = ["HumanWorld", "RigRobot", "World", "SimWorld", "SlotRef"]

COVER_DISTANCE_M = 0.02
"""A lens cover stands this far past the camera's near clipping plane."""
LID_COVER_M = 0.012
"""A lid cover is this much wider than the product on each side, and floats this far over its lid."""


@dataclasses.dataclass(frozen=True)
class SlotRef:
    """A shelf slot: unit name, tier (0: lowest) and position along the tier (0: the first in the kitchen file)."""

    unit: str
    tier: int
    index: int

    def __str__(self) -> str:
        return f"{self.unit}/{self.tier}/{self.index}"


class HumanWorld(Protocol):
    """What the simulated human reads and changes: the clock, where a product is, fetching one to the table.

    `world.Kitchen` and every `World` have it; a lab rig's version is a person with a stopwatch.
    """

    @property
    def sim_time(self) -> float:
        """Seconds since the episode started (simulated time in simulation)."""
        ...

    def is_on_table(self, name: str) -> bool:
        """Ground truth: the product rests upright on the table."""
        ...

    def is_on_shelf(self, name: str) -> bool:
        """Ground truth: the product stands on a shelf unit."""
        ...

    def touches_robot(self, name: str) -> bool:
        """The product is in or against the robot's gripper (a person does not grab it away)."""
        ...

    def place_on_table(self, name: str) -> bool:
        """Put the product on a free table spot by hand; False when the table is full."""
        ...

    def put_away(self, name: str) -> None:
        """Take a product the recipe has used off the table, out of the kitchen (room for the next one)."""
        ...


class World(HumanWorld, Protocol):
    """What the episode loop and a scenario can do to the world and read from it."""

    def advance(self, seconds: float) -> None:
        """Let ``seconds`` of time pass in the world (a simulator steps its physics; a lab rig waits)."""
        ...

    def stock(self, specs: Sequence[ObjectSpec], rng: np.random.Generator) -> None:
        """Stock the shelf with the products (``rng`` seeds their places) and let them settle."""
        ...

    def products(self) -> list[str]:
        """The products in the kitchen."""
        ...

    def slots_on_tier(self, unit: str, tier: int) -> int:
        """How many slots the shelf unit's tier has."""
        ...

    def place_on_shelf(self, name: str, slot: SlotRef, yaw: float = 0.0) -> None:
        """Stand the product on the slot (a product already there swaps places with it)."""
        ...

    def swap(self, name: str, other: str) -> None:
        """Exchange the places of two products (a look-alike put where the product stood, and back)."""
        ...

    def place_beside(self, name: str, anchor: str, gap_m: float, side: int) -> None:
        """Stand the product on the anchor's tier, ``gap_m`` from its side (``side`` +1: further along the tier,
        −1: back towards its start)."""
        ...

    def remove(self, name: str) -> None:
        """Take the product out of the kitchen."""
        ...

    def hide_marker(self, name: str) -> None:
        """Cover the product's lid (and its marker) where it stands now."""
        ...

    def show_marker(self, name: str) -> None:
        """Take the lid's cover away."""
        ...

    def cover_camera(self, camera: str) -> None:
        """Hold something opaque in front of the camera's lens."""
        ...

    def uncover_camera(self, camera: str) -> None:
        """Take it away."""
        ...

    def apply_fault(
        self,
        gripper_force: float | None = None,
        finger_friction: float | None = None,
        camera_noise: float | None = None,
        depth_noise: float | None = None,
        planner_budget_s: float | None = None,
        calibration_offset: tuple[float, float, float] | None = None,
        velocity_scale: float | None = None,
        acceleration_scale: float | None = None,
        jerk_scale: float | None = None,
    ) -> None:
        """Degrade (or restore) the robot from now on; None keeps a value (units: `scone_bt.scenario` Fault)."""
        ...


def _quaternion_z_to(direction: Sequence[float]) -> tuple[float, float, float, float]:
    """The rotation (x, y, z, w) that turns +z onto ``direction``."""
    n = math.sqrt(sum(c * c for c in direction))
    dx, dy, dz = (c / n for c in direction)
    # axis = z × d, angle = acos(z · d)
    ax, ay = -dy, dx
    s = math.sqrt(ax * ax + ay * ay)
    if s < 1e-9:
        return (0.0, 0.0, 0.0, 1.0) if dz > 0 else (1.0, 0.0, 0.0, 0.0)
    angle = math.acos(max(-1.0, min(1.0, dz)))
    h = math.sin(angle / 2) / s
    return (ax * h, ay * h, 0.0, math.cos(angle / 2))


class RigRobot(Protocol):
    """What the test rig reaches into on a simulated robot (`robot.sim.SimRobot`): its cameras, its planner, its
    calibration and its limits."""

    robot_config: RobotConfig
    calibration_offset: tuple[float, float, float]
    """Metres added to every detection's position."""

    @property
    def observer(self) -> Observer: ...

    @property
    def motion(self) -> MotionSystem: ...


class SimWorld:
    """`World` on the PyBullet simulation: `Kitchen`'s public methods, the robot's cameras and motion system.

    Args:
        kitchen: The episode's kitchen (products already stocked).
        robot: The simulated robot (set up: cameras and motion system built).
    """

    def __init__(self, kitchen: Kitchen, robot: RigRobot) -> None:
        self.kitchen = kitchen
        self.robot = robot
        self._lid_covers: dict[str, int] = {}
        self._lens_covers: dict[str, int] = {}

    # ------------------------------------------------------------------------------------------- reading
    @property
    def sim_time(self) -> float:
        return self.kitchen.sim_time

    def products(self) -> list[str]:
        return list(self.kitchen.objects)

    def is_on_table(self, name: str) -> bool:
        return self.kitchen.is_on_table(name)

    def is_on_shelf(self, name: str) -> bool:
        return self.kitchen.is_on_shelf(name)

    def touches_robot(self, name: str) -> bool:
        return self.kitchen.touches_robot(name)

    def advance(self, seconds: float) -> None:
        self.kitchen.advance(seconds)

    def stock(self, specs: Sequence[ObjectSpec], rng: np.random.Generator) -> None:
        self.kitchen.spawn(specs, rng)

    def camera_names(self) -> list[str]:
        return [c.spec.name for c in self.robot.observer.cameras]

    # ------------------------------------------------------------------------------------------- products
    def slot_surface(self, slot: SlotRef) -> tuple[tuple[float, float, float], float]:
        """The slot's surface point (world, metres) and the yaw facing the robot."""
        scene = self.kitchen.config.scene
        units = {u.name: u for u in scene.shelves}
        if slot.unit not in units:
            raise UnknownNameError("shelf unit", slot.unit, units)
        unit = units[slot.unit]
        if not 0 <= slot.tier < len(unit.tiers):
            raise ConfigError(f"slot {slot}: unit {slot.unit!r} has tiers 0-{len(unit.tiers) - 1}")
        tier = unit.tiers[slot.tier]
        if not 0 <= slot.index < len(tier.slots):
            raise ConfigError(f"slot {slot}: tier {slot.tier} has slots 0-{len(tier.slots) - 1}")
        x, y = unit.to_world(tier.center, tier.slots[slot.index])
        return (x, y, tier.top_z), unit.facing_yaw

    def slots_on_tier(self, unit: str, tier: int) -> int:
        (x, y, z), _ = self.slot_surface(SlotRef(unit, tier, 0))  # checks the unit and the tier
        units = {u.name: u for u in self.kitchen.config.scene.shelves}
        return len(units[unit].tiers[tier].slots)

    def _standing_near(self, point: Sequence[float], radius: float, besides: str) -> str | None:
        best, best_d = None, radius
        for other in self.kitchen.objects:
            if other == besides:
                continue
            x, y, z = self.kitchen.object_state(other).position
            d = math.hypot(x - point[0], y - point[1])
            if d < best_d and abs(z - point[2]) < 0.3:
                best, best_d = other, d
        return best

    def place_on_shelf(self, name: str, slot: SlotRef, yaw: float = 0.0) -> None:
        surface, facing = self.slot_surface(slot)
        was, was_yaw = self._stand(name)
        occupant = self._standing_near(surface, 0.05, name)
        self.kitchen.park_object(name)  # out of the way while the occupant moves
        if occupant is not None:
            self.kitchen.place_object(occupant, was, was_yaw)
        self.kitchen.place_object(name, surface, facing + yaw)

    def _stand(self, name: str) -> tuple[tuple[float, float, float], float]:
        """Where the product stands now: the point under its base (m) and its yaw (rad)."""
        here = self.kitchen.object_state(name)
        height = self.kitchen.specs[name].height
        yaw = self.kitchen.object_yaw(name)
        return (here.position[0], here.position[1], here.position[2] - height / 2 - 1e-3), yaw

    def swap(self, name: str, other: str) -> None:
        if name == other:
            return
        (a, a_yaw), (b, b_yaw) = self._stand(name), self._stand(other)
        self.kitchen.park_object(name)  # out of the way while the other one moves
        self.kitchen.place_object(other, a, a_yaw)
        self.kitchen.place_object(name, b, b_yaw)

    def place_beside(self, name: str, anchor: str, gap_m: float, side: int) -> None:
        from scone_bt.config.footprint import footprint
        from scone_bt.perception.context import shelf_place

        scene = self.kitchen.config.scene
        (x, y, z), anchor_yaw = self._stand(anchor)
        place = shelf_place(scene, (x, y, z + 0.01))
        if place is None:
            raise ConfigError(f"{anchor!r} does not stand on a shelf tier: nothing to stand {name!r} beside")
        unit = next(u for u in scene.shelves if u.name == place[0])
        tier = unit.tiers[place[1]]
        _, v0 = unit.to_unit(x, y)
        half = footprint(self.kitchen.specs[anchor], anchor_yaw - unit.facing_yaw)[1] / 2
        half_other = footprint(self.kitchen.specs[name], 0.0)[1] / 2
        v = v0 + (1 if side >= 0 else -1) * (half + gap_m + half_other)
        if not unit.span[0] + half_other <= v <= unit.span[1] - half_other:
            raise ConfigError(
                f"no room for {name!r} {gap_m * 100:.1f} cm beside {anchor!r} on {unit.name}/{place[1]} "
                f"(the tier spans {unit.span[0]:.2f}-{unit.span[1]:.2f} m along it)"
            )
        was, was_yaw = self._stand(name)
        wx, wy = unit.to_world(tier.center, v)
        # a product standing there takes the moved one's old place (as a person would swap them)
        occupant = self._standing_near((wx, wy, tier.top_z), half_other + 0.03, name)
        self.kitchen.park_object(name)
        if occupant is not None and occupant != anchor:
            self.kitchen.place_object(occupant, was, was_yaw)
        self.kitchen.place_object(name, (wx, wy, tier.top_z), unit.facing_yaw)

    def place_on_table(self, name: str) -> bool:
        return self.kitchen.place_on_table(name)

    def put_away(self, name: str) -> None:
        self.kitchen.park_object(name)

    def remove(self, name: str) -> None:
        self.kitchen.park_object(name)

    def hide_marker(self, name: str) -> None:
        if name in self._lid_covers:
            return
        st = self.kitchen.object_state(name)
        spec = self.kitchen.specs[name]
        sx, sy, sz = spec.size
        side = max(sx, sy) + 2 * LID_COVER_M
        x, y, z = st.position
        self._lid_covers[name] = self.kitchen.add_cover((x, y, z + sz / 2 + LID_COVER_M), (side, side, 0.004))

    def show_marker(self, name: str) -> None:
        handle = self._lid_covers.pop(name, None)
        if handle is not None:
            self.kitchen.remove_cover(handle)

    def _camera(self, camera: str) -> Any:
        for c in self.robot.observer.cameras:
            if c.spec.name == camera:
                return c
        raise UnknownNameError("camera", camera, self.camera_names())

    def cover_camera(self, camera: str) -> None:
        if camera in self._lens_covers:
            return
        spec = self._camera(camera).spec
        direction = [t - p for t, p in zip(spec.target, spec.position, strict=True)]
        n = math.sqrt(sum(c * c for c in direction))
        d = spec.near + COVER_DISTANCE_M
        center = [p + c / n * d for p, c in zip(spec.position, direction, strict=True)]
        # Wide enough to fill the whole field of view at that distance, whatever the aspect ratio.
        side = 4.0 * d * math.tan(math.radians(spec.fov_deg) / 2) * max(1.0, spec.width / spec.height)
        self._lens_covers[camera] = self.kitchen.add_cover(
            center, (side, side, 0.002), orientation=_quaternion_z_to(direction)
        )

    def uncover_camera(self, camera: str) -> None:
        self._camera(camera)
        handle = self._lens_covers.pop(camera, None)
        if handle is not None:
            self.kitchen.remove_cover(handle)

    # ------------------------------------------------------------------------------------------- the robot
    def apply_fault(
        self,
        gripper_force: float | None = None,
        finger_friction: float | None = None,
        camera_noise: float | None = None,
        depth_noise: float | None = None,
        planner_budget_s: float | None = None,
        calibration_offset: tuple[float, float, float] | None = None,
        velocity_scale: float | None = None,
        acceleration_scale: float | None = None,
        jerk_scale: float | None = None,
    ) -> None:
        if gripper_force is not None or finger_friction is not None:
            self.kitchen.set_gripper_properties(max_force=gripper_force, finger_friction=finger_friction)
        if camera_noise is not None or depth_noise is not None:
            for cam in self.robot.observer.cameras:
                spec = cam.spec
                cam.spec = dataclasses.replace(
                    spec,
                    noise_std=spec.noise_std if camera_noise is None else float(camera_noise),
                    depth_noise_std=spec.depth_noise_std if depth_noise is None else float(depth_noise),
                )
        if planner_budget_s is not None:
            motion = self.robot.motion
            motion.planner = dataclasses.replace(motion.planner, time_limit_s=float(planner_budget_s))
        if calibration_offset is not None:
            x, y, z = calibration_offset
            self.robot.calibration_offset = (float(x), float(y), float(z))
        if velocity_scale is not None or acceleration_scale is not None or jerk_scale is not None:
            from scone_bt.motion.timing import limits_of

            cfg = self.robot.robot_config
            lim = cfg.limits
            lim = dataclasses.replace(
                lim,
                velocity_scale=lim.velocity_scale if velocity_scale is None else float(velocity_scale),
                acceleration_scale=(
                    lim.acceleration_scale if acceleration_scale is None else float(acceleration_scale)
                ),
                jerk_scale=lim.jerk_scale if jerk_scale is None else float(jerk_scale),
            )
            cfg = dataclasses.replace(cfg, limits=lim)
            self.robot.robot_config = cfg
            self.robot.motion.limits = limits_of(cfg)
