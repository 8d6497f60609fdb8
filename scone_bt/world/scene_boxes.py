"""The kitchen's fixed boxes (pedestal, table, shelf tiers), engine-neutral: both the PyBullet `world.Kitchen` and
the MuJoCo model (`world.mj_model`) build their static scene from `static_boxes`, with the same names and colours.
"""

from __future__ import annotations

from dataclasses import dataclass

from scone_bt.config import KitchenConfig

__all__ = ["FLOOR_FRICTION", "SCENE_FRICTION", "StaticBox", "box_colour", "static_boxes"]

SCENE_FRICTION = 0.8
"""Sliding friction coefficient of the fixed boxes (pedestal, table, shelf tiers), on both engines."""
FLOOR_FRICTION = 0.5
"""Sliding friction coefficient of the floor (Bullet's default, which the PyBullet kitchen's plane keeps)."""

_COLOURS = {"pedestal": (0.3, 0.3, 0.3, 1.0), "table": (0.55, 0.40, 0.25, 1.0)}
_SHELF_COLOUR = (0.75, 0.72, 0.65, 1.0)


@dataclass(frozen=True)
class StaticBox:
    """An immovable box of the scene. Centre and full size in metres, world frame."""

    name: str
    center: tuple[float, float, float]
    size: tuple[float, float, float]


def static_boxes(kitchen: KitchenConfig) -> list[StaticBox]:
    """The pedestal, the table, then every shelf unit's tiers, lowest first."""
    scene = kitchen.scene
    boxes = [StaticBox("pedestal", *scene.pedestal), StaticBox("table", *scene.table)]
    for unit in scene.shelves:
        # The first unit keeps the historical names (shelf_tier0...), which logs and tests refer to.
        prefix = "shelf" if unit is scene.shelves[0] else f"shelf_{unit.name}"
        for i, (center, size) in enumerate(unit.boxes(scene.floor_z)):
            boxes.append(StaticBox(f"{prefix}_tier{i}", center, size))
    return boxes


def box_colour(name: str) -> tuple[float, float, float, float]:
    """The RGBA colour a static box is drawn in: the pedestal and table their own, shelf tiers a light wood."""
    return _COLOURS.get(name, _SHELF_COLOUR)
