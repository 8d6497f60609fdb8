"""The kitchen file: scene geometry, camera and object catalogue (perception/kitchen.yaml)."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from scone_bt.config.yaml_io import Fields, read_yaml, require
from scone_bt.errors import ConfigError, UnknownNameError
from scone_bt.resources import resolve_file

__all__ = ["ObjectSpec", "Catalogue", "CameraSpec", "SceneSpec", "KitchenConfig", "load_kitchen"]

SHAPES = ("box", "cylinder")


@dataclass(frozen=True)
class ObjectSpec:
    """One catalogue object.

    Attributes:
        name: Canonical name, used in action texts ("Put <name> on table").
        aliases: Other names recipes use for it.
        shape: "box" or "cylinder".
        size: Extent along x, y, z in metres (cylinder: diameter, diameter, height).
        mass: Kilograms.
        friction: Lateral friction coefficient of its surface.
        material: Free text (glass, metal, paper, ...).
        rgba: Body colour, components in [0, 1].
        marker_id: ArUco (DICT_4X4_50) id printed on the lid.
    """

    name: str
    aliases: tuple[str, ...]
    shape: str
    size: tuple[float, float, float]
    mass: float
    friction: float
    material: str
    rgba: tuple[float, float, float, float]
    marker_id: int

    @property
    def grasp_width(self) -> float:
        """Narrowest horizontal extent in metres (what the fingers must span)."""
        return min(self.size[0], self.size[1])

    @property
    def height(self) -> float:
        return self.size[2]


@dataclass(frozen=True)
class Catalogue:
    """All objects the kitchen can stock, by canonical name."""

    objects: tuple[ObjectSpec, ...]

    def names(self) -> list[str]:
        return [o.name for o in self.objects]

    def get(self, name: str) -> ObjectSpec:
        for obj in self.objects:
            if obj.name == name:
                return obj
        raise UnknownNameError("object", name, self.names())

    def by_marker(self, marker_id: int) -> ObjectSpec | None:
        for obj in self.objects:
            if obj.marker_id == marker_id:
                return obj
        return None

    def __len__(self) -> int:
        return len(self.objects)


@dataclass(frozen=True)
class CameraSpec:
    """A pinhole RGB-D camera. Positions in metres (world frame); fov_deg is the vertical field of view."""

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


@dataclass(frozen=True)
class SceneSpec:
    """Static geometry: boxes given by centre and full size in metres."""

    floor_z: float
    pedestal: tuple[tuple[float, float, float], tuple[float, float, float]]
    table: tuple[tuple[float, float, float], tuple[float, float, float]]
    shelf_tiers: tuple[tuple[float, float], ...]  # (centre x, top z)
    tier_depth: float
    shelf_y_range: tuple[float, float]
    slot_y: tuple[float, ...]
    place_spots: tuple[tuple[float, float], ...]
    tier_slot_y: tuple[
        tuple[float, ...] | None, ...
    ] = ()  # per tier: its own slot_y, or None for the default

    @property
    def table_top_z(self) -> float:
        (_, _, cz), (_, _, sz) = self.table
        return cz + sz / 2

    def shelf_slots(self) -> list[tuple[float, float, float]]:
        """All shelf locations as (x, y, surface z)."""
        own = self.tier_slot_y or (None,) * len(self.shelf_tiers)
        return [
            (x, y, z) for (x, z), ys in zip(self.shelf_tiers, own, strict=True) for y in (ys or self.slot_y)
        ]


@dataclass(frozen=True)
class KitchenConfig:
    scene: SceneSpec
    camera: CameraSpec
    catalogue: Catalogue
    source: Path = field(default=Path("."), compare=False)


def _box(f: Fields, key: str) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
    sub = f.sub(key)
    return sub.vector("center", 3), sub.vector("size", 3)  # type: ignore[return-value]


def _object(raw: object, index: int, where: str) -> ObjectSpec:
    f = Fields(raw, f"{where}.objects[{index}]")  # type: ignore[arg-type]
    shape = f.get("shape", str)
    require(shape in SHAPES, f"{f.where}.shape: {shape!r} is not one of {', '.join(SHAPES)}")
    size = f.vector("size", 3)
    require(all(s > 0 for s in size), f"{f.where}.size: all extents must be positive")
    mass = f.get("mass", float)
    require(mass > 0, f"{f.where}.mass must be positive")
    rgba = f.vector("rgba", 4)
    return ObjectSpec(
        name=f.get("name", str).strip(),
        aliases=tuple(str(a).strip() for a in f.get("aliases", list, [])),
        shape=shape,
        size=size,  # type: ignore[arg-type]
        mass=mass,
        friction=f.get("friction", float),
        material=f.get("material", str, "unknown"),
        rgba=rgba,  # type: ignore[arg-type]
        marker_id=f.get("marker_id", int),
    )


def load_kitchen(name_or_path: str | Path = "kitchen") -> KitchenConfig:
    """Load a kitchen file by name (perception/<name>.yaml) or path."""
    path = resolve_file("perception", name_or_path, (".yaml", ".yml"))
    f = Fields(read_yaml(path), str(path))
    s = f.sub("scene")
    shelf = s.sub("shelf")
    tiers = []
    tier_slots: list[tuple[float, ...] | None] = []
    for i, t in enumerate(shelf.get("tiers", list)):
        tf = Fields(t, f"{shelf.where}.tiers[{i}]")
        tiers.append((tf.get("center_x", float), tf.get("top_z", float)))
        tier_slots.append(tf.vector("slot_y", default=None) if "slot_y" in t else None)
    scene = SceneSpec(
        floor_z=s.get("floor_z", float),
        pedestal=_box(s, "pedestal"),
        table=_box(s, "table"),
        shelf_tiers=tuple(tiers),
        tier_slot_y=tuple(tier_slots),
        tier_depth=shelf.get("tier_depth", float),
        shelf_y_range=shelf.vector("y_range", 2),  # type: ignore[arg-type]
        slot_y=shelf.vector("slot_y"),
        place_spots=tuple(
            tuple(float(v) for v in p)  # type: ignore[misc]
            for p in s.get("place_spots", list)
        ),
    )
    c = f.sub("camera")
    camera = CameraSpec(
        position=c.vector("position", 3),  # type: ignore[arg-type]
        target=c.vector("target", 3),  # type: ignore[arg-type]
        up=c.vector("up", 3, (0.0, 0.0, 1.0)),  # type: ignore[arg-type]
        width=c.get("width", int),
        height=c.get("height", int),
        fov_deg=c.get("fov_deg", float),
        near=c.get("near", float, 0.05),
        far=c.get("far", float, 3.0),
        noise_std=c.get("noise_std", float, 0.0),
        depth_noise_std=c.get("depth_noise_std", float, 0.0),
    )
    objects = tuple(_object(o, i, str(path)) for i, o in enumerate(f.get("objects", list)))
    names = [o.name for o in objects]
    dupes = sorted({n for n in names if names.count(n) > 1})
    if dupes:
        raise ConfigError(f"{path}: duplicate object names: {', '.join(dupes)}")
    markers = [o.marker_id for o in objects]
    if len(set(markers)) != len(markers):
        raise ConfigError(f"{path}: marker_id values must be unique")
    return KitchenConfig(scene=scene, camera=camera, catalogue=Catalogue(objects), source=path)
