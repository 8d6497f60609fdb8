"""Where each product stands on the shelving: heaviest lowest, side by side in lanes wide enough for the fingers.

Pure geometry (numpy only), so it is tested without a simulator. Random slots are drawn as a person would pick
free places, then filled heaviest-first from the lowest tier up; a tier whose products are too wide for it passes
its lightest ones to the next tier with room. On a tier, products keep the order of their drawn slots and are
pushed apart only as far as their lanes need (`scone_bt.stocking.lanes`), so products of ordinary width stand
exactly on their slots.

A product deeper than its tier (more than MAX_OVERHANG_M over the front edge) stands against the riser, square to
it, and on a lowest tier when one has room: on a higher tier its front would hang over the tier below, where the
products standing there are taller than the step and the two would be stocked inside each other (the solver then
throws both off the shelf).

`plan_stocking` runs its steps in order, each on one `_Draft`: draw the slots, lower the deep products, pass the
lightest up from crowded tiers; if that fails, pack first-fit; if that fails too, the tightest packing
(`pack_side_by_side`); then push the products on each tier apart.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from scone_bt.config.catalogue import ObjectSpec
from scone_bt.config.footprint import footprint
from scone_bt.config.scene import SceneSpec, ShelfUnit
from scone_bt.errors import ConfigError
from scone_bt.stocking.lanes import (
    FINGER_ROOM_M,
    LANE_MIN_M,
    TierKey,
    lane_width,
    segment,
    tier_length,
    too_deep,
    turn,
)
from scone_bt.stocking.pack import pack_side_by_side, wider_than_every_tier

__all__ = ["YAW_JITTER_RAD", "Placement", "plan_stocking"]

YAW_JITTER_RAD = 0.3
"""Products stand facing the robot within ± this."""


@dataclass(frozen=True)
class Placement:
    """Where one product stands: surface point under its centre (world, metres) and its yaw (radians)."""

    name: str
    position: tuple[float, float, float]
    yaw: float
    unit: str
    tier: int


@dataclass
class _Draft:
    """The plan as its steps change it: each product's tier, the place along it it wants, its yaw jitter.

    Attributes:
        specs: The products, in the caller's order (indices below are into it).
        units: Shelf unit name → unit.
        tier_keys: The drawn tiers first (lowest first), then every other, lowest first.
        by_mass: Product indices, heaviest first (equal masses in the order given).
        deep: Products deeper than their tier.
        yaws: Each product's yaw jitter, radians.
        wanted: Product → the place along its tier it wants (metres, the unit's v axis).
        tier_of: Product → its tier.
    """

    specs: Sequence[ObjectSpec]
    units: dict[str, ShelfUnit]
    tier_keys: list[TierKey]
    by_mass: list[int]
    deep: set[int]
    yaws: list[float]
    wanted: dict[int, float]
    tier_of: dict[int, TierKey]

    def lane_on(self, i: int, key: TierKey) -> float:
        """The lane product ``i`` takes on tier ``key`` with its yaw, metres."""
        unit = self.units[key[0]]
        _, v = footprint(self.specs[i], self.yaws[i] + turn(self.specs[i], unit.tier_depth))
        return max(LANE_MIN_M, v + FINGER_ROOM_M)

    def used(self, key: TierKey, extra: int | None = None) -> float:
        """The lanes on tier ``key`` (with product ``extra`` added), metres."""
        members = [j for j in self.tier_of if self.tier_of[j] == key]
        return sum(self.lane_on(j, key) for j in members) + (
            self.lane_on(extra, key) if extra is not None else 0.0
        )

    def has_room(self, key: TierKey, extra: int | None = None) -> bool:
        """Whether tier ``key`` holds its lanes (and ``extra``'s)."""
        return self.used(key, extra) <= tier_length(self.units[key[0]], key[1]) + 1e-9


def plan_stocking(scene: SceneSpec, specs: Sequence[ObjectSpec], rng: np.random.Generator) -> list[Placement]:
    """Places for `specs` (same order), drawn from `rng`.

    Raises:
        ConfigError: If the products outnumber the slots or do not fit the shelving side by side.
    """
    draft = _draw(scene, specs, rng)
    _lower_deep_products(draft)
    if not _pass_up_lightest(draft) and not _pack_first_fit(draft):
        _pack_tightest(scene, draft)
    return _push_apart(draft)


def _draw(scene: SceneSpec, specs: Sequence[ObjectSpec], rng: np.random.Generator) -> _Draft:
    """Draw a slot and a yaw for each product; the heaviest take the lowest drawn slots."""
    slots = scene.slots()
    if len(specs) > len(slots):
        raise ConfigError(f"{len(specs)} objects do not fit on the shelf's {len(slots)} slots")
    units = {u.name: u for u in scene.shelves}
    chosen = [slots[int(i)] for i in rng.permutation(len(slots))[: len(specs)]]
    yaws = [float(rng.uniform(-YAW_JITTER_RAD, YAW_JITTER_RAD)) for _ in specs]
    # Stable sorts: equal heights keep the random draw order, equal masses the order given.
    chosen.sort(key=lambda slot: slot.position[2])
    by_mass = sorted(range(len(specs)), key=lambda i: -specs[i].mass)
    tier_keys = list(dict.fromkeys((s.unit, s.tier) for s in chosen))
    tier_keys += [(s.unit, s.tier) for s in sorted(slots, key=lambda s: s.position[2])]
    tier_keys = list(dict.fromkeys(tier_keys))  # drawn tiers first (lowest first), then every other
    deep = {i for i, spec in enumerate(specs) if too_deep(spec, scene)}
    for i in deep:  # drawn above, so the seeded draws of every other product stay as they were
        yaws[i] = 0.0
    wanted: dict[int, float] = {}
    tier_of: dict[int, TierKey] = {}
    for rank, i in enumerate(by_mass):
        slot = chosen[rank]
        wanted[i] = units[slot.unit].to_unit(slot.position[0], slot.position[1])[1]
        tier_of[i] = (slot.unit, slot.tier)
    return _Draft(specs, units, tier_keys, by_mass, deep, yaws, wanted, tier_of)


def _lower_deep_products(d: _Draft) -> None:
    """Too deep for a higher tier: down to a lowest tier with room, its own unit's first."""
    for i in sorted(d.deep, key=lambda i: -d.specs[i].mass):
        unit_name, tier_index = d.tier_of[i]
        if tier_index == 0:
            continue
        lowest = sorted((k for k in d.tier_keys if k[1] == 0), key=lambda k: k[0] != unit_name)
        room = [k for k in lowest if d.has_room(k, i)]
        if room:
            d.tier_of[i] = room[0]


def _pass_up_lightest(d: _Draft) -> bool:
    """Too wide for their tier: the lightest products move up to the next tier with room (a deep one last).

    Returns False when a product finds no tier with room.
    """
    for key in d.tier_keys:
        members = sorted(
            (i for i in d.tier_of if d.tier_of[i] == key), key=lambda i: (i in d.deep, d.specs[i].mass)
        )
        while members and not d.has_room(key):
            moved = members.pop(0)
            here = d.tier_keys.index(key)
            # The next tiers up first, then any other (a wide product may still fit a lower tier's spare room).
            order = d.tier_keys[here + 1 :] + d.tier_keys[:here]
            room = [k for k in order if d.has_room(k, moved)]
            if not room:
                return False
            d.tier_of[moved] = room[0]
            tier = d.units[room[0][0]].tiers[room[0][1]]
            d.wanted[moved] = float(np.mean(tier.slots))
    return True


def _pack_first_fit(d: _Draft) -> bool:
    """The drawn slots crowd wide products together: pack first-fit instead, heaviest first, lowest tier first.

    Returns False when a product finds no tier with room.
    """
    d.tier_of.clear()
    for i in d.by_mass:
        key = next((k for k in d.tier_keys if d.has_room(k, i)), None)
        if key is None:
            return False
        tier = d.units[key[0]].tiers[key[1]]
        d.wanted[i] = tier.slots[sum(1 for j in d.tier_of if d.tier_of[j] == key) % len(tier.slots)]
        d.tier_of[i] = key
    return True


def _pack_tightest(scene: SceneSpec, d: _Draft) -> None:
    """Still crowded: the tightest packing, widest first, every product facing the robot (its lane as narrow as it
    gets). What `fits_side_by_side` accepts is stocked here.

    Raises:
        ConfigError: The products do not fit side by side (naming one wider than every tier, if one is).
    """
    packed = pack_side_by_side(scene, d.specs)
    if packed is None:
        if (too_wide := wider_than_every_tier(scene, d.specs)) is not None:
            raise ConfigError(too_wide)
        total = sum(lane_width(spec, scene.shelves[0]) for spec in d.specs)
        raise ConfigError(
            f"{len(d.specs)} products do not fit the shelving side by side (they need about {total:.2f} m "
            f"of shelf); stock fewer or narrower products"
        )
    d.tier_of = dict(enumerate(packed))
    d.yaws = [0.0] * len(d.specs)
    for i, key in d.tier_of.items():
        tier = d.units[key[0]].tiers[key[1]]
        d.wanted[i] = tier.slots[sum(1 for j in range(i) if d.tier_of[j] == key) % len(tier.slots)]


def _push_apart(d: _Draft) -> list[Placement]:
    """Each tier's products at their wanted places, pushed apart as little as their lanes need."""
    out: dict[int, Placement] = {}
    for key in d.tier_keys:
        unit, tier_index = d.units[key[0]], key[1]
        tier = unit.tiers[tier_index]
        members = sorted((i for i in d.tier_of if d.tier_of[i] == key), key=lambda i: d.wanted[i])
        if not members:
            continue
        a, b = segment(unit, tier_index)
        v = [d.wanted[i] for i in members]
        widths = [d.lane_on(i, key) for i in members]
        # Push apart left to right, then back from the far end: the least movement that gives every lane room.
        v[0] = max(v[0], a + widths[0] / 2)
        for k in range(1, len(v)):
            v[k] = max(v[k], v[k - 1] + (widths[k - 1] + widths[k]) / 2)
        v[-1] = min(v[-1], b - widths[-1] / 2)
        for k in range(len(v) - 2, -1, -1):
            v[k] = min(v[k], v[k + 1] - (widths[k] + widths[k + 1]) / 2)
        for i, vi in zip(members, v, strict=True):
            quarter = turn(d.specs[i], unit.tier_depth)
            depth, _ = footprint(d.specs[i], d.yaws[i] + quarter)
            # Centred on the tier; a product deeper than the tier stands against the riser behind it.
            u = min(tier.center, tier.center + unit.tier_depth / 2 - depth / 2 - 0.003)
            x, y = unit.to_world(u, vi)
            out[i] = Placement(
                d.specs[i].name,
                (x, y, tier.top_z),
                unit.facing_yaw + quarter + d.yaws[i],
                unit.name,
                tier_index,
            )
    return [out[i] for i in range(len(d.specs))]
