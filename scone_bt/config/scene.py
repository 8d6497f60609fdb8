"""The kitchen's static scene and its cameras, as perception/kitchen.yaml describes them.

The shelving is one or more stepped shelf units. Each unit is written in its own frame (u: away from the robot,
v: along the unit) and turned about the robot's base by a multiple of 90 degrees, so every box of the scene stays
axis-aligned in the world. Slots are the places objects stand on: one per listed position along each tier.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import AfterValidator, Field, model_validator

from scone_bt.config.schema import FiniteFloat, StrictModel
from scone_bt.config.yaml_io import require

__all__ = [
    "CAMERA_ROLES",
    "CameraSpec",
    "ShelfTier",
    "ShelfUnit",
    "SceneSpec",
    "Slot",
    "SceneFile",
    "CameraFile",
    "NamedCameraFile",
    "scene_spec",
    "camera_specs",
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


def _within_scene(values: tuple[float, ...], where: str) -> None:
    """Positions along a shelf unit within MAX_SCENE_M of the robot, else one ConfigError naming the key."""
    require(
        all(abs(v) <= MAX_SCENE_M for v in values),
        f"{where}: every value must be in [-{MAX_SCENE_M:g}, {MAX_SCENE_M:g}] metres, got {list(values)}",
    )


def _unit(u: UnitFile, index: int, where: str) -> ShelfUnit:
    """One shelf unit, its slots checked against its span (the keys and ranges were checked by its model)."""
    where = f"{where}[{index}]"
    span = (u.span[0], u.span[1])
    require(span[0] < span[1], f"{where}.span: need v0 < v1, got {list(span)}")
    tiers = tuple(ShelfTier(t.center, t.top_z, tuple(t.slots)) for t in u.tiers)
    for i, tier in enumerate(tiers):  # a slot beyond the shelf's block would stand its product on thin air
        for k, v in enumerate(tier.slots):
            require(
                span[0] <= v <= span[1],
                f"{where}.tiers[{i}].slots[{k}]: {v:g} lies outside the unit's span {list(span)}",
            )
    return ShelfUnit(
        u.name if u.name is not None else f"unit{index}", u.rotation_deg, u.tier_depth, span, tiers
    )


def scene_spec(s: SceneFile, where: str) -> SceneSpec:
    """The scene a validated ``scene:`` section describes, with the checks across its keys."""
    units = tuple(_unit(u, i, f"{where}.shelves") for i, u in enumerate(s.shelves))
    names = [u.name for u in units]
    require(len(set(names)) == len(names), f"{where}.shelves: unit names must be unique, got {names}")
    seen: dict[tuple[float, float, float], str] = {}
    for i, unit in enumerate(units):
        for j, tier in enumerate(unit.tiers):
            at = f"{where}.shelves[{i}].tiers[{j}]"
            require(
                tier.top_z > s.floor_z,
                f"{at}.top_z: {tier.top_z:g} must be above scene.floor_z ({s.floor_z:g})",
            )
            for k, v in enumerate(tier.slots):
                x, y = unit.to_world(tier.center, v)
                key = (round(x, 6), round(y, 6), round(tier.top_z, 6))
                name = f"{at}.slots[{k}] ({unit.name})"
                require(key not in seen, f"{name} and {seen.get(key)} are the same slot position {list(key)}")
                seen[key] = name
    (tx, ty, _), (sx, sy, _) = s.table.center, s.table.size
    for k, (x, y) in enumerate(s.place_spots):  # a spot off the table puts a product down on thin air
        require(
            abs(x - tx) <= sx / 2 and abs(y - ty) <= sy / 2,
            f"{where}.place_spots[{k}]: [{x:g}, {y:g}] lies off the table (x in [{tx - sx / 2:g}, {tx + sx / 2:g}], "
            f"y in [{ty - sy / 2:g}, {ty + sy / 2:g}])",
        )
    return SceneSpec(
        floor_z=s.floor_z,
        pedestal=s.pedestal.box(),
        table=s.table.box(),
        shelves=units,
        place_spots=tuple((p[0], p[1]) for p in s.place_spots),
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


# ---------------------------------------------------------------------------------------------- the file's models
# pydantic checks every key, type and range (one line naming the key path: config.schema.format_validation_error);
# the checks across keys (slots inside the span, unique names, a camera that can render) follow in scene_spec and
# camera_specs, in the same words.


def _in(lo: float, hi: float, above: bool = False) -> AfterValidator:
    """A number in [lo, hi] (in (lo, hi] with ``above``), in the words the kitchen file's author reads."""

    def check(value: float) -> float:
        if not ((lo < value if above else lo <= value) and value <= hi):
            raise ValueError(f"must be in {'(' if above else '['}{lo:g}, {hi:g}], got {value!r}")
        return float(value)

    return AfterValidator(check)


def _pixels(value: int) -> int:
    if not MIN_PIXELS <= value <= MAX_PIXELS:
        raise ValueError(f"must be {MIN_PIXELS} to {MAX_PIXELS} pixels, got {value}")
    return value


def _all_within_scene(values: list[float]) -> list[float]:
    if not all(abs(v) <= MAX_SCENE_M for v in values):
        raise ValueError(f"every value must be in [-{MAX_SCENE_M:g}, {MAX_SCENE_M:g}] metres, got {values}")
    return values


def _at_least_one(what: str) -> AfterValidator:
    def check(values: list[Any]) -> list[Any]:
        if not values:
            raise ValueError(f"list at least one {what}")
        return values

    return AfterValidator(check)


def _rotation(value: int) -> int:
    if value not in _ROTATIONS:
        raise ValueError(f"{value} is not one of {', '.join(map(str, _ROTATIONS))}")
    return value


def _positive_sizes(values: list[float]) -> list[float]:
    if not all(v > 0 for v in values):
        raise ValueError(f"every size must be > 0 metres, got {values}")
    return values


_Vec2 = Annotated[list[FiniteFloat], Field(min_length=2, max_length=2)]
_Vec3 = Annotated[list[FiniteFloat], Field(min_length=3, max_length=3)]


_SceneM = Annotated[float, Field(allow_inf_nan=False), _in(-MAX_SCENE_M, MAX_SCENE_M)]
_Pixels = Annotated[int, AfterValidator(_pixels)]


class BoxFile(StrictModel):
    """A box of the scene: centre and full size, metres."""

    center: _Vec3
    size: Annotated[_Vec3, AfterValidator(_positive_sizes)]

    def box(self) -> Box:
        return tuple(self.center), tuple(self.size)  # type: ignore[return-value]


class TierFile(StrictModel):
    """One tier of a shelf unit (unit frame, metres)."""

    center: _SceneM
    top_z: _SceneM
    slots: Annotated[list[FiniteFloat], _at_least_one("slot position"), AfterValidator(_all_within_scene)]


class UnitFile(StrictModel):
    """One shelf unit: its name, turn about the robot base (degrees), tier depth and span (metres), tiers."""

    name: str | None = None
    rotation_deg: Annotated[int, AfterValidator(_rotation)] = 0
    tier_depth: Annotated[float, Field(allow_inf_nan=False), _in(0.0, MAX_SCENE_M, above=True)]
    span: Annotated[_Vec2, AfterValidator(_all_within_scene)]
    tiers: Annotated[list[TierFile], _at_least_one("tier")]


class SceneFile(StrictModel):
    """The ``scene:`` section of a kitchen file."""

    floor_z: FiniteFloat
    pedestal: BoxFile
    table: BoxFile
    shelves: Annotated[list[UnitFile], _at_least_one("shelf unit")]
    place_spots: Annotated[list[_Vec2], _at_least_one("[x, y] table spot")]


class CameraFile(StrictModel):
    """A camera entry (world frame, metres; fov_deg the vertical field of view)."""

    position: _Vec3
    target: _Vec3
    up: _Vec3 = [0.0, 0.0, 1.0]
    width: _Pixels
    height: _Pixels
    fov_deg: Annotated[float, Field(allow_inf_nan=False), _in(1.0, MAX_FOV_DEG)]
    near: Annotated[float, Field(allow_inf_nan=False), _in(0.0, MAX_FAR_M, above=True)] = 0.05
    far: Annotated[float, Field(allow_inf_nan=False), _in(0.0, MAX_FAR_M, above=True)] = 3.0
    noise_std: Annotated[float, Field(allow_inf_nan=False), _in(0.0, 255.0)] = 0.0
    depth_noise_std: Annotated[float, Field(allow_inf_nan=False), _in(0.0, MAX_DEPTH_NOISE_M)] = 0.0

    @model_validator(mode="after")
    def _near_before_far(self) -> CameraFile:
        if self.near >= self.far:
            raise ValueError(f"far: must be larger than near ({self.near:g}), got {self.far:g}")
        return self


class NamedCameraFile(CameraFile):
    """A camera of the ``cameras:`` list: also its name and what it watches."""

    name: str | None = None
    role: Literal["shelf", "table"] = "shelf"


def _camera(c: CameraFile, name: str, role: str, where: str) -> CameraSpec:
    """A camera from its validated entry, checked as scone_bt.perception.camera will use it."""
    position, target, up = tuple(c.position), tuple(c.target), tuple(c.up)
    view = np.subtract(target, position)  # the same tests as scone_bt.perception.camera's, at load time
    require(
        bool(np.linalg.norm(view) >= 1e-6),
        f"{where}.target: camera {name!r} looks at its own position {list(position)}; give another target",
    )
    require(
        bool(np.linalg.norm(np.cross(view, up)) >= 1e-6 * np.linalg.norm(view)),
        f"{where}.up: camera {name!r}: {list(up)} is parallel to its viewing direction (target - position = "
        f"{[round(float(v), 6) for v in view]}); give an up vector that is not parallel to it",
    )
    return CameraSpec(
        position=position,  # type: ignore[arg-type]
        target=target,  # type: ignore[arg-type]
        up=up,  # type: ignore[arg-type]
        width=c.width,
        height=c.height,
        fov_deg=c.fov_deg,
        near=c.near,
        far=c.far,
        noise_std=c.noise_std,
        depth_noise_std=c.depth_noise_std,
        name=name,
        role=role,
    )


def camera_specs(
    cameras: list[NamedCameraFile] | None, camera: CameraFile | None, where: str
) -> tuple[CameraSpec, ...]:
    """The ``cameras:`` list of a validated kitchen file (or its single ``camera:``, which watches the shelf).

    Returns:
        The cameras in file order; at least one watches the shelf.
    """
    if cameras is None and camera is not None:
        return (_camera(camera, "shelf", "shelf", f"{where}: camera"),)
    require(cameras is not None, f"{where}: missing key 'cameras' (or a single 'camera')")
    assert cameras is not None
    out = [
        _camera(c, c.name if c.name is not None else f"camera{i}", c.role, f"{where}: cameras[{i}]")
        for i, c in enumerate(cameras)
    ]
    names = [c.name for c in out]
    require(len(set(names)) == len(names), f"{where}: cameras: camera names must be unique, got {names}")
    require(
        any(c.role == "shelf" for c in out),
        f"{where}: cameras: at least one camera needs role: shelf (valid roles: {', '.join(CAMERA_ROLES)})",
    )
    return tuple(out)
