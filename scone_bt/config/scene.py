"""The kitchen's static scene and its cameras, as perception/kitchen.yaml describes them.

The shelving is one or more stepped shelf units. Each unit is written in its own frame (u: away from the robot,
v: along the unit) and turned about the robot's base by a multiple of 90 degrees, so every box of the scene stays
axis-aligned in the world. Slots are the places objects stand on: one per listed position along each tier.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from scone_bt.config.yaml_io import Fields, require

__all__ = [
    "CAMERA_ROLES",
    "CameraSpec",
    "ShelfTier",
    "ShelfUnit",
    "SceneSpec",
    "Slot",
    "parse_scene",
    "parse_cameras",
]

CAMERA_ROLES = ("shelf", "table")
"""What a camera watches: the shelving (affordances) or the table (obstacles and free placing area)."""
_ROTATIONS = (0, 90, 180, 270)

Box = tuple[tuple[float, float, float], tuple[float, float, float]]
"""A box as (centre, full size), metres, world frame, axis-aligned."""


@dataclass(frozen=True)
class CameraSpec:
    """A pinhole RGB-D camera. Positions in metres (world frame); fov_deg is the vertical field of view.

    Attributes:
        name: Unique camera name ("shelf_front", "table", ...).
        role: One of CAMERA_ROLES.
    """

    position: tuple[float, float, float]
    target: tuple[float, float, float]
    up: tuple[float, float, float]
    width: int
    height: int
    fov_deg: float
    near: float
    far: float
    noise_std: float = 0.0
    depth_noise_std: float = 0.0
    name: str = "shelf"
    role: str = "shelf"


@dataclass(frozen=True)
class ShelfTier:
    """One step of a shelf unit.

    Attributes:
        center: Distance of the step's centre line from the robot along the unit's u axis, metres.
        top_z: Height of the step's top surface, metres.
        slots: Positions of the slots along the unit's v axis, metres.
    """

    center: float
    top_z: float
    slots: tuple[float, ...]


@dataclass(frozen=True)
class ShelfUnit:
    """A stepped shelf unit: solid blocks standing on the floor, lowest step nearest the robot.

    Attributes:
        name: Unique unit name.
        rotation_deg: Turn of the unit's (u, v) frame about the robot base's vertical axis: 0 puts u along world
            x and v along world y; 90 puts u along world y and v along world -x.
        tier_depth: Depth of every step along u, metres.
        span: (v0, v1) extent of the unit along v, metres.
        tiers: Its steps.
    """

    name: str
    rotation_deg: int
    tier_depth: float
    span: tuple[float, float]
    tiers: tuple[ShelfTier, ...]

    def to_world(self, u: float, v: float) -> tuple[float, float]:
        """World (x, y) of a point given in the unit's frame."""
        a = np.radians(self.rotation_deg)
        c, s = round(float(np.cos(a))), round(float(np.sin(a)))
        return (c * u - s * v, s * u + c * v)

    def to_unit(self, x: float, y: float) -> tuple[float, float]:
        """The unit-frame (u, v) of a world point."""
        a = np.radians(self.rotation_deg)
        c, s = round(float(np.cos(a))), round(float(np.sin(a)))
        return (c * x + s * y, -s * x + c * y)

    @property
    def facing_yaw(self) -> float:
        """World yaw of the unit's u axis, radians (products are stocked facing the robot along it)."""
        return float(np.radians(self.rotation_deg))

    def boxes(self, floor_z: float) -> list[Box]:
        """One solid block per tier, from the floor up to the tier's top."""
        v0, v1 = self.span
        out = []
        for tier in self.tiers:
            height = tier.top_z - floor_z
            x, y = self.to_world(tier.center, (v0 + v1) / 2)
            du, dv = (
                (self.tier_depth, v1 - v0) if self.rotation_deg % 180 == 0 else (v1 - v0, self.tier_depth)
            )
            out.append(((x, y, floor_z + height / 2), (du, dv, height)))
        return out

    def contains(
        self, position: tuple[float, float, float] | list[float], margin: float, floor_z: float
    ) -> bool:
        """True if a world point lies above this unit's footprint (within margin, metres) and above the floor."""
        u, v = self.to_unit(float(position[0]), float(position[1]))
        u0 = min(t.center for t in self.tiers) - self.tier_depth / 2
        u1 = max(t.center for t in self.tiers) + self.tier_depth / 2
        lowest = min(t.top_z for t in self.tiers)
        return (
            u0 - margin <= u <= u1 + margin
            and self.span[0] - margin <= v <= self.span[1] + margin
            and float(position[2]) >= lowest - margin
            and float(position[2]) > floor_z + 0.2
        )


@dataclass(frozen=True)
class Slot:
    """A place on the shelving: world position of its surface centre (metres) and the yaw facing the robot."""

    position: tuple[float, float, float]
    yaw: float
    unit: str
    tier: int


@dataclass(frozen=True)
class SceneSpec:
    """Static geometry: boxes given by centre and full size in metres, and the shelf units."""

    floor_z: float
    pedestal: Box
    table: Box
    shelves: tuple[ShelfUnit, ...]
    place_spots: tuple[tuple[float, float], ...]

    @property
    def table_top_z(self) -> float:
        (_, _, cz), (_, _, sz) = self.table
        return cz + sz / 2

    def slots(self) -> list[Slot]:
        """Every slot of every unit, unit by unit, lowest tier first."""
        out = []
        for unit in self.shelves:
            for i, tier in enumerate(unit.tiers):
                for v in tier.slots:
                    x, y = unit.to_world(tier.center, v)
                    out.append(Slot((x, y, tier.top_z), unit.facing_yaw, unit.name, i))
        return out

    def shelf_slots(self) -> list[tuple[float, float, float]]:
        """All shelf locations as (x, y, surface z)."""
        return [s.position for s in self.slots()]

    def on_shelf(self, position: tuple[float, float, float] | list[float], margin: float = 0.03) -> bool:
        """True if a world position lies above the footprint of any shelf unit (metres)."""
        return any(unit.contains(position, margin, self.floor_z) for unit in self.shelves)

    def on_table(self, position: tuple[float, float, float] | list[float], margin: float = 0.0) -> bool:
        """True if a world point lies above the table top's footprint (metres)."""
        (cx, cy, _), (sx, sy, _) = self.table
        return abs(position[0] - cx) <= sx / 2 + margin and abs(position[1] - cy) <= sy / 2 + margin


def _box(f: Fields, key: str) -> Box:
    sub = f.sub(key).allow("center", "size")
    size = sub.vector("size", 3)
    require(all(v > 0 for v in size), f"{sub.where}.size: every size must be > 0 metres, got {list(size)}")
    return sub.vector("center", 3), size


def _within_scene(values: tuple[float, ...], where: str) -> None:
    """Positions along a shelf unit within MAX_SCENE_M of the robot, else one ConfigError naming the key."""
    require(
        all(abs(v) <= MAX_SCENE_M for v in values),
        f"{where}: every value must be in [-{MAX_SCENE_M:g}, {MAX_SCENE_M:g}] metres, got {list(values)}",
    )


def _unit(raw: Any, index: int, where: str) -> ShelfUnit:
    f = Fields(raw, f"{where}[{index}]").allow(*_UNIT_KEYS)
    rotation = f.get("rotation_deg", int, 0)
    require(
        rotation in _ROTATIONS,
        f"{f.where}.rotation_deg: {rotation} is not one of {', '.join(map(str, _ROTATIONS))}",
    )
    tiers = []
    for i, raw_tier in enumerate(f.get("tiers", list)):
        t = Fields(raw_tier, f"{f.where}.tiers[{i}]").allow("center", "top_z", "slots")
        slots = t.vector("slots")
        require(len(slots) > 0, f"{t.where}.slots: list at least one slot position")
        _within_scene(slots, f"{t.where}.slots")
        center = t.number("center", -MAX_SCENE_M, MAX_SCENE_M)
        tiers.append(ShelfTier(center, t.number("top_z", -MAX_SCENE_M, MAX_SCENE_M), tuple(slots)))
    require(len(tiers) > 0, f"{f.where}.tiers: list at least one tier")
    span = f.vector("span", 2)
    _within_scene(span, f"{f.where}.span")
    require(span[0] < span[1], f"{f.where}.span: need v0 < v1, got {list(span)}")
    for i, tier in enumerate(tiers):  # a slot beyond the shelf's block would stand its product on thin air
        for k, v in enumerate(tier.slots):
            require(
                span[0] <= v <= span[1],
                f"{f.where}.tiers[{i}].slots[{k}]: {v:g} lies outside the unit's span {list(span)}",
            )
    depth = f.number("tier_depth", 0.0, MAX_SCENE_M, above=True)
    return ShelfUnit(f.get("name", str, f"unit{index}"), rotation, depth, span, tuple(tiers))


def parse_scene(s: Fields) -> SceneSpec:
    """The ``scene:`` section of a kitchen file."""
    s.allow(*_SCENE_KEYS)
    floor_z = s.get("floor_z", float)
    units = tuple(_unit(u, i, f"{s.where}.shelves") for i, u in enumerate(s.get("shelves", list)))
    require(len(units) > 0, f"{s.where}.shelves: list at least one shelf unit")
    names = [u.name for u in units]
    require(len(set(names)) == len(names), f"{s.where}.shelves: unit names must be unique, got {names}")
    seen: dict[tuple[float, float, float], str] = {}
    for i, unit in enumerate(units):
        for j, tier in enumerate(unit.tiers):
            where = f"{s.where}.shelves[{i}].tiers[{j}]"
            require(
                tier.top_z > floor_z,
                f"{where}.top_z: {tier.top_z:g} must be above scene.floor_z ({floor_z:g})",
            )
            for k, v in enumerate(tier.slots):
                x, y = unit.to_world(tier.center, v)
                key = (round(x, 6), round(y, 6), round(tier.top_z, 6))
                name = f"{where}.slots[{k}] ({unit.name})"
                require(key not in seen, f"{name} and {seen.get(key)} are the same slot position {list(key)}")
                seen[key] = name
    spots = tuple(_spot(p, i, s.where) for i, p in enumerate(s.get("place_spots", list)))
    require(len(spots) > 0, f"{s.where}.place_spots: list at least one [x, y] table spot")
    return SceneSpec(
        floor_z=floor_z,
        pedestal=_box(s, "pedestal"),
        table=_box(s, "table"),
        shelves=units,
        place_spots=spots,
    )


_SCENE_KEYS = ("floor_z", "pedestal", "table", "shelves", "place_spots")
_UNIT_KEYS = ("name", "rotation_deg", "tier_depth", "span", "tiers")
_CAMERA_KEYS = (
    "position",
    "target",
    "up",
    "width",
    "height",
    "fov_deg",
    "near",
    "far",
    "noise_std",
    "depth_noise_std",
)
MIN_PIXELS, MAX_PIXELS = 16, 4096
"""Smallest and largest camera image side, pixels (a 100000 x 100000 image does not fit in memory)."""
MAX_DEPTH_NOISE_M = 1.0
"""Largest depth noise, metres (pixel noise is on the 0-255 scale)."""
MAX_FAR_M = 100.0
"""Farthest a camera's far plane may be, metres (the kitchen is a few metres across)."""
MAX_FOV_DEG = 170.0
"""Widest vertical field of view, degrees (what scone_bt.perception.camera renders)."""
MAX_SCENE_M = 10.0
"""Farthest a shelf unit's span, slots and tiers (centre, top) may be from the robot base, metres (the arms reach
under 1 m; a 1e9 m shelf is a typo, not a kitchen)."""


def _spot(raw: Any, index: int, where: str) -> tuple[float, float]:
    """One table spot [x, y] in metres (a number or a string is a one-line error, not a TypeError)."""
    ok = (
        isinstance(raw, list)
        and len(raw) == 2
        and all(isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v) for v in raw)
    )
    require(ok, f"{where}.place_spots[{index}]: expected [x, y] in metres, got {raw!r}")
    return float(raw[0]), float(raw[1])


def _pixels(c: Fields, key: str) -> int:
    value = c.get(key, int)
    require(
        MIN_PIXELS <= value <= MAX_PIXELS,
        f"{c.where}.{key}: must be {MIN_PIXELS} to {MAX_PIXELS} pixels, got {value}",
    )
    return value


def _camera(c: Fields, name: str, role: str) -> CameraSpec:
    near = c.number("near", 0.0, MAX_FAR_M, 0.05, above=True)
    far = c.number("far", 0.0, MAX_FAR_M, 3.0, above=True)
    require(near < far, f"{c.where}.far: must be larger than near ({near:g}), got {far:g}")
    position, target = c.vector("position", 3), c.vector("target", 3)
    up = c.vector("up", 3, (0.0, 0.0, 1.0))
    view = np.subtract(target, position)  # the same tests as scone_bt.perception.camera's, at load time
    require(
        bool(np.linalg.norm(view) >= 1e-6),
        f"{c.where}.target: camera {name!r} looks at its own position {list(position)}; give another target",
    )
    require(
        bool(np.linalg.norm(np.cross(view, up)) >= 1e-6 * np.linalg.norm(view)),
        f"{c.where}.up: camera {name!r}: {list(up)} is parallel to its viewing direction (target - position = "
        f"{[round(float(v), 6) for v in view]}); give an up vector that is not parallel to it",
    )
    return CameraSpec(
        position=position,
        target=target,
        up=up,
        width=_pixels(c, "width"),
        height=_pixels(c, "height"),
        fov_deg=c.number("fov_deg", 1.0, MAX_FOV_DEG),
        near=near,
        far=far,
        noise_std=c.number("noise_std", 0.0, 255.0, 0.0),
        depth_noise_std=c.number("depth_noise_std", 0.0, MAX_DEPTH_NOISE_M, 0.0),
        name=name,
        role=role,
    )


def parse_cameras(f: Fields) -> tuple[CameraSpec, ...]:
    """The ``cameras:`` list of a kitchen file (or a single ``camera:``, which watches the shelf).

    Returns:
        The cameras in file order; at least one watches the shelf.
    """
    if "cameras" not in f.data and "camera" in f.data:
        return (_camera(f.sub("camera").allow(*_CAMERA_KEYS), "shelf", "shelf"),)
    out = []
    for i, raw in enumerate(f.get("cameras", list)):
        c = Fields(raw, f"{f.where}.cameras[{i}]").allow(*_CAMERA_KEYS, "name", "role")
        role = c.get("role", str, "shelf")
        require(role in CAMERA_ROLES, f"{c.where}.role: {role!r} is not one of {', '.join(CAMERA_ROLES)}")
        out.append(_camera(c, c.get("name", str, f"camera{i}"), role))
    names = [c.name for c in out]
    require(len(set(names)) == len(names), f"{f.where}.cameras: camera names must be unique, got {names}")
    require(
        any(c.role == "shelf" for c in out),
        f"{f.where}.cameras: at least one camera needs role: shelf (valid roles: {', '.join(CAMERA_ROLES)})",
    )
    return tuple(out)
