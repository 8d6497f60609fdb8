"""Checking names against the stocked kitchen: the products on its shelf, its slots, its cameras, its pins.

A scenario file (`scone_bt.scenario`) names products, shelf slots ``unit/tier/index`` and cameras. Each name is
checked here against the stocking the episode will draw (`stocked_names`, `KitchenNames`), so a misspelt or
absent name is one line (`scone_bt.errors.ConfigError`, naming the key and the valid choices) before the
simulator starts. Pure and cheap: no simulator, only the kitchen file and the seeded stocking.
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Protocol

from scone_bt.config.kitchen import KitchenConfig
from scone_bt.config.scene import ShelfUnit
from scone_bt.errors import ConfigError
from scone_bt.stocking.shelf import ShelfStock

__all__ = [
    "SLOT_PATTERN",
    "KitchenNames",
    "Pin",
    "kitchen_names",
    "parse_slot",
    "slots_beside",
    "stocked_names",
]

SLOT_PATTERN = r"^([A-Za-z0-9_-]+)/(\d+)/(\d+)$"
"""A shelf slot as a scenario writes it: ``unit/tier/index`` (tier 0 the lowest)."""
_SLOT = re.compile(SLOT_PATTERN)


def parse_slot(text: str) -> tuple[str, int, int]:
    """(unit, tier, index) of a slot ``unit/tier/index``.

    Raises:
        ConfigError: ``text`` is not of that form.
    """
    m = _SLOT.fullmatch(text)
    if m is None:
        raise ConfigError(f"{text!r} is not a shelf slot like left/1/0 (unit/tier/index)")
    return m.group(1), int(m.group(2)), int(m.group(3))


def slots_beside(slot: str, slots_on_tier: int) -> list[str]:
    """The slots of the same tier beside ``slot``, nearest first, the next along the tier before the one back
    (index + 1, index − 1, index + 2, ...), only those the tier has."""
    unit, tier, index = parse_slot(slot)
    around = [index + d * s for d in range(1, slots_on_tier) for s in (1, -1)]
    return [f"{unit}/{tier}/{i}" for i in around if 0 <= i < slots_on_tier]


def stocked_names(stock: ShelfStock) -> tuple[str, ...]:
    """The products standing on the shelf: the recipe's and the distractors, less those the human brings."""
    off = (*stock.recipe.unstocked, *stock.recipe.off_shelf)
    return tuple(n for n in (*stock.recipe.needed, *stock.distractors) if n not in off)


class Pin(Protocol):
    """A product pinned to a slot, with neighbours beside it (a scenario's ``world.place`` entry)."""

    @property
    def product(self) -> str: ...

    @property
    def slot(self) -> str: ...

    @property
    def neighbours(self) -> Sequence[str]: ...

    @property
    def gap_m(self) -> float | None: ...


@dataclass(frozen=True)
class KitchenNames:
    """What names are checked against: the products stocked in this episode, the catalogue's, the shelf units and
    the cameras; `where` starts each error (the file, and the case of a sweep)."""

    where: str
    present: frozenset[str]
    catalogue: frozenset[str]
    units: Mapping[str, ShelfUnit]
    cameras: tuple[str, ...]

    def product(self, name: str, key: str) -> None:
        """`name` is stocked in this episode, or one line saying why not."""
        if name in self.present:
            return
        why = (
            "is not a product of the catalogue"
            if name not in self.catalogue
            else "is not stocked in this episode"
        )
        raise ConfigError(f"{self.where}: {key}: {name!r} {why}; valid: {', '.join(sorted(self.present))}")

    def products(self, names: Sequence[str], key: str) -> None:
        """Each of `names` is stocked in this episode (`key`: the list's key; errors name ``key[i]``)."""
        for i, name in enumerate(names):
            self.product(name, f"{key}[{i}]")

    def slot(self, text: str, key: str) -> None:
        """`text` ("unit/tier/index") names a slot of the kitchen's shelves."""
        try:
            unit, tier, index = parse_slot(text)
        except ConfigError as exc:
            raise ConfigError(f"{self.where}: {key}: {exc}") from None
        if unit not in self.units:
            raise ConfigError(
                f"{self.where}: {key}: unknown shelf unit {unit!r}; valid: {', '.join(self.units)}"
            )
        tiers = self.units[unit].tiers
        if tier >= len(tiers):
            raise ConfigError(f"{self.where}: {key}: unit {unit!r} has tiers 0-{len(tiers) - 1} (got {tier})")
        if index >= len(tiers[tier].slots):
            raise ConfigError(
                f"{self.where}: {key}: tier {unit}/{tier} has slots 0-{len(tiers[tier].slots) - 1} (got {index})"
            )

    def camera(self, name: str, key: str) -> None:
        """`name` is one of the kitchen's cameras."""
        if name not in self.cameras:
            raise ConfigError(
                f"{self.where}: {key}: unknown camera {name!r}; valid: {', '.join(self.cameras)}"
            )

    def placements(self, place: Sequence[Pin], key: str = "world.place") -> None:
        """Pinned products: each stocked, on a slot of the shelves, one product a slot, room for its neighbours
        (at most 2 with a gap: one on each side)."""
        pinned: dict[str, int] = {}
        for i, pl in enumerate(place):
            self.product(pl.product, f"{key}[{i}].product")
            self.slot(pl.slot, f"{key}[{i}].slot")
            if (
                pl.slot in pinned
            ):  # the later pin would move the earlier product away, and its pin would not hold
                raise ConfigError(
                    f"{self.where}: {key}[{i}].slot: {pl.slot} is already {key}[{pinned[pl.slot]}]'s "
                    f"({place[pinned[pl.slot]].product}); give each product its own slot"
                )
            pinned[pl.slot] = i
            self.products(pl.neighbours, f"{key}[{i}].neighbours")
            unit, tier, _ = parse_slot(pl.slot)
            room = len(self.units[unit].tiers[tier].slots)
            written = "/".join(pl.slot.split("/")[:2])  # the tier as the file wrote it
            if pl.gap_m is not None and len(pl.neighbours) > 2:
                raise ConfigError(
                    f"{self.where}: {key}[{i}].gap_m: a gap places at most 2 neighbours, one on each side "
                    f"(got {len(pl.neighbours)})"
                )
            if pl.gap_m is None and len(slots_beside(pl.slot, room)) < len(pl.neighbours):
                raise ConfigError(
                    f"{self.where}: {key}[{i}].neighbours: tier {written} has {room} slots, no room "
                    f"for {len(pl.neighbours)} neighbours beside slot {pl.slot}"
                )


def kitchen_names(kitchen: KitchenConfig, stock: ShelfStock, where: str) -> KitchenNames:
    """The names of ``kitchen`` stocked with ``stock``: its shelf cameras first, then its other cameras."""
    cameras = (*kitchen.shelf_cameras, *[c for c in kitchen.cameras if c.role != "shelf"])
    return KitchenNames(
        where,
        frozenset(stocked_names(stock)),
        frozenset(kitchen.catalogue.names()),
        {u.name: u for u in kitchen.scene.shelves},
        tuple(c.name for c in cameras),
    )
