"""The kitchen file: scene geometry, camera and object catalogue (perception/kitchen.yaml)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

from scone_bt.config.catalogue import Catalogue, ObjectSpec, catalogue_files, load_catalogue
from scone_bt.config.yaml_io import Fields, read_yaml
from scone_bt.resources import data_dir, resolve_file

__all__ = ["ObjectSpec", "Catalogue", "CameraSpec", "SceneSpec", "KitchenConfig", "load_kitchen"]


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


def load_kitchen(
    name_or_path: str | Path = "kitchen", catalogues: Sequence[str | Path] = ()
) -> KitchenConfig:
    """Load a kitchen file by name (perception/<name>.yaml) or path.

    Args:
        name_or_path: The kitchen file.
        catalogues: Extra product files (a user's own products), merged after the kitchen's ``catalogue:`` list.
    """
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
    entries = f.get("catalogue", list)
    files = catalogue_files(entries, path.parent, data_dir("perception")) + [Path(c) for c in catalogues]
    catalogue = load_catalogue(files)
    return KitchenConfig(scene=scene, camera=camera, catalogue=catalogue, source=path)
