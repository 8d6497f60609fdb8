"""Where each product stands on the shelving: heaviest lowest, side by side in lanes wide enough for the fingers.

Pure geometry (numpy only), so it is tested without a simulator and usable by capacity figures. A product takes a
lane along its tier: its footprint along the tier plus room for a finger on each side, at least one slot pitch
(`LANE_MIN_M`). Random slots are drawn as a person would pick free places, then filled heaviest-first from the
lowest tier up; a tier whose products are too wide for it passes its lightest ones to the next tier with room. On
a tier, products keep the order of their drawn slots and are pushed apart only as far as their lanes need, so
products of ordinary width stand exactly on their slots.

A product deeper than its tier (more than MAX_OVERHANG_M over the front edge) stands against the riser, square to
it, and on a lowest tier when one has room: on a higher tier its front would hang over the tier below, where the
products standing there are taller than the step and the two would be stocked inside each other (the solver then
throws both off the shelf).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from scone_bt.config.catalogue import ObjectSpec, Shape
from scone_bt.config.footprint import footprint
from scone_bt.config.scene import SceneSpec, ShelfUnit
from scone_bt.errors import ConfigError

__all__ = [
    "LANE_MIN_M",
    "FINGER_ROOM_M",
    "Placement",
    "fits_shelf",
    "fits_side_by_side",
    "lane_width",
    "pack_side_by_side",
    "plan_stocking",
    "wider_than_every_tier",
]

LANE_MIN_M = 0.10
"""The narrowest lane: the slot pitch of perception/kitchen.yaml."""
FINGER_ROOM_M = 0.03
"""Free space beside a product for a finger (both sides together), metres."""
MAX_OVERHANG_M = 0.03
"""How far a product may stick out over the front edge of its tier, metres."""
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


def _turn(spec: ObjectSpec, depth: float) -> float:
    """0, or a quarter turn for a box too deep for the tier whose other side fits."""
    sx, sy, _ = spec.size
    if spec.shape == Shape.BOX and sx > depth + MAX_OVERHANG_M and sy < sx:
        return np.pi / 2
    return 0.0


def fits_shelf(spec: ObjectSpec, scene: SceneSpec) -> bool:
    """True if the product can stand on some tier (depth with the allowed overhang, width within the tier)."""
    for unit in scene.shelves:
        u, v = footprint(spec, _turn(spec, unit.tier_depth))
        if u <= unit.tier_depth + 2 * MAX_OVERHANG_M and any(
            max(LANE_MIN_M, v + FINGER_ROOM_M) <= _length(unit, i) for i in range(len(unit.tiers))
        ):
            return True
    return False


def _too_deep(spec: ObjectSpec, scene: SceneSpec) -> bool:
    """True if the product, square to the riser, sticks out over the front edge of a tier by more than allowed."""
    return any(
        footprint(spec, _turn(spec, unit.tier_depth))[0] > unit.tier_depth + MAX_OVERHANG_M
        for unit in scene.shelves
    )


def _segment(unit: ShelfUnit, tier: int) -> tuple[float, float]:
    """The stretch of a tier products may occupy: from half a pitch before its first slot to after its last."""
    slots = unit.tiers[tier].slots
    return min(slots) - LANE_MIN_M / 2, max(slots) + LANE_MIN_M / 2


def _length(unit: ShelfUnit, tier: int) -> float:
    a, b = _segment(unit, tier)
    return b - a


def lane_width(spec: ObjectSpec, unit: ShelfUnit) -> float:
    """The lane a product facing the robot takes along a tier of ``unit`` (finger room included), metres."""
    _, v = footprint(spec, _turn(spec, unit.tier_depth))
    return max(LANE_MIN_M, v + FINGER_ROOM_M)


def _lowest_first(scene: SceneSpec) -> list[tuple[str, int]]:
    """Every (unit, tier), lowest tier first (units in file order at equal heights)."""
    keys = [(u.name, i, t.top_z) for u in scene.shelves for i, t in enumerate(u.tiers)]
    return [(name, i) for name, i, _ in sorted(keys, key=lambda k: k[2])]


def pack_side_by_side(scene: SceneSpec, specs: Sequence[ObjectSpec]) -> list[tuple[str, int]] | None:
    """A (unit, tier) for each product such that every tier's lanes fit it, or None when none is found.

    First fit, decreasing: products too deep for an upper tier first (onto a lowest tier when one has room), then
    the widest lanes first, each on the lowest tier with room; products face the robot (no yaw jitter). This is
    the packing `plan_stocking` falls back on last, so a set it accepts is always stocked.
    """
    if len(specs) > len(scene.slots()):
        return None
    units = {u.name: u for u in scene.shelves}
    tiers = _lowest_first(scene)
    used = dict.fromkeys(tiers, 0.0)
    deep = [_too_deep(spec, scene) for spec in specs]
    lanes = [{u.name: lane_width(spec, u) for u in scene.shelves} for spec in specs]
    order = sorted(range(len(specs)), key=lambda i: (not deep[i], -max(lanes[i].values())))
    out: dict[int, tuple[str, int]] = {}
    for i in order:
        ranked = sorted(tiers, key=lambda k: k[1] != 0) if deep[i] else tiers  # stable: lowest first
        for key in ranked:
            unit = units[key[0]]
            lane = lanes[i][key[0]]
            if used[key] + lane <= _length(unit, key[1]) + 1e-9:
                used[key] += lane
                out[i] = key
                break
        else:
            return None
    return [out[i] for i in range(len(specs))]


def wider_than_every_tier(scene: SceneSpec, specs: Sequence[ObjectSpec]) -> str | None:
    """One line naming the first product whose lane is longer than every tier of every unit (it stands nowhere,
    however few products share the shelving), or None."""
    for spec in specs:
        if all(
            lane_width(spec, u) > _length(u, i) + 1e-9 for u in scene.shelves for i in range(len(u.tiers))
        ):
            longest = max(_length(u, i) for u in scene.shelves for i in range(len(u.tiers)))
            family = f" of family {spec.family!r}" if spec.family else ""
            return (
                f"product {spec.name!r}{family} ({' x '.join(f'{v:g}' for v in spec.size)} m) needs a "
                f"{min(lane_width(spec, u) for u in scene.shelves):.2f} m lane, longer than every shelf tier (the longest is "
                f"{longest:.2f} m); give it a smaller size in its catalogue file or leave it out of the recipe"
            )
    return None


def fits_side_by_side(scene: SceneSpec, specs: Sequence[ObjectSpec]) -> bool:
    """True if `pack_side_by_side` stocks these products (then `plan_stocking` never refuses them)."""
    return pack_side_by_side(scene, specs) is not None


def plan_stocking(scene: SceneSpec, specs: Sequence[ObjectSpec], rng: np.random.Generator) -> list[Placement]:
    """Places for `specs` (same order), drawn from `rng`.

    Raises:
        ConfigError: If the products outnumber the slots or do not fit the shelving side by side.
    """
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
    tier_keys = list(
        dict.fromkeys(tier_keys)
    )  # drawn tiers first (lowest first), then every other, lowest first
    deep = {i for i, spec in enumerate(specs) if _too_deep(spec, scene)}
    for i in deep:  # drawn above, so the seeded draws of every other product stay as they were
        yaws[i] = 0.0
    wanted: dict[int, float] = {}  # product index -> v of its drawn slot
    tier_of: dict[int, tuple[str, int]] = {}
    for rank, i in enumerate(by_mass):
        slot = chosen[rank]
        unit = units[slot.unit]
        wanted[i] = unit.to_unit(slot.position[0], slot.position[1])[1]
        tier_of[i] = (slot.unit, slot.tier)

    def used(key: tuple[str, int], extra: int | None = None) -> float:
        members = [j for j in tier_of if tier_of[j] == key]
        return sum(lane_on(j, key) for j in members) + (lane_on(extra, key) if extra is not None else 0.0)

    def lane_on(i: int, key: tuple[str, int]) -> float:
        unit = units[key[0]]
        _, v = footprint(specs[i], yaws[i] + _turn(specs[i], unit.tier_depth))
        return max(LANE_MIN_M, v + FINGER_ROOM_M)

    # Too deep for a higher tier: down to a lowest tier with room, its own unit's first.
    for i in sorted(deep, key=lambda i: -specs[i].mass):
        unit_name, tier_index = tier_of[i]
        if tier_index == 0:
            continue
        lowest = sorted((k for k in tier_keys if k[1] == 0), key=lambda k: k[0] != unit_name)
        room = [k for k in lowest if used(k, i) <= _length(units[k[0]], k[1]) + 1e-9]
        if room:
            tier_of[i] = room[0]

    # Too wide for their tier: the lightest products move up to the next tier with room (a deep one last).
    feasible = True
    for key in tier_keys:
        members = sorted((i for i in tier_of if tier_of[i] == key), key=lambda i: (i in deep, specs[i].mass))
        while members and used(key) > _length(units[key[0]], key[1]) + 1e-9:
            moved = members.pop(0)
            here = tier_keys.index(key)
            # The next tiers up first, then any other (a wide product may still fit a lower tier's spare room).
            order = tier_keys[here + 1 :] + tier_keys[:here]
            room = [k for k in order if used(k, moved) <= _length(units[k[0]], k[1]) + 1e-9]
            if not room:
                feasible = False
                break
            tier_of[moved] = room[0]
            tier = units[room[0][0]].tiers[room[0][1]]
            wanted[moved] = float(np.mean(tier.slots))
        if not feasible:
            break
    if not feasible:
        # The drawn slots crowd wide products together: pack first-fit instead, heaviest first, lowest tier first.
        tier_of.clear()
        for i in by_mass:
            key = next(
                (k for k in tier_keys if used(k, i) <= _length(units[k[0]], k[1]) + 1e-9),
                None,
            )
            if key is None:
                feasible = False
                break
            tier = units[key[0]].tiers[key[1]]
            wanted[i] = tier.slots[sum(1 for j in tier_of if tier_of[j] == key) % len(tier.slots)]
            tier_of[i] = key
        else:
            feasible = True
    if not feasible:
        # Still crowded: the tightest packing, widest first, every product facing the robot (its lane as narrow
        # as it gets). What `fits_side_by_side` accepts is stocked here.
        packed = pack_side_by_side(scene, specs)
        if packed is None:
            if (too_wide := wider_than_every_tier(scene, specs)) is not None:
                raise ConfigError(too_wide)
            total = sum(lane_width(spec, scene.shelves[0]) for spec in specs)
            raise ConfigError(
                f"{len(specs)} products do not fit the shelving side by side (they need about {total:.2f} m "
                f"of shelf); stock fewer or narrower products"
            )
        tier_of = dict(enumerate(packed))
        yaws = [0.0] * len(specs)
        for i, key in tier_of.items():
            tier = units[key[0]].tiers[key[1]]
            wanted[i] = tier.slots[sum(1 for j in range(i) if tier_of[j] == key) % len(tier.slots)]

    out: dict[int, Placement] = {}
    for key in tier_keys:
        unit, tier_index = units[key[0]], key[1]
        tier = unit.tiers[tier_index]
        members = sorted((i for i in tier_of if tier_of[i] == key), key=lambda i: wanted[i])
        if not members:
            continue
        a, b = _segment(unit, tier_index)
        v = [wanted[i] for i in members]
        widths = [lane_on(i, key) for i in members]
        # Push apart left to right, then back from the far end: the least movement that gives every lane room.
        v[0] = max(v[0], a + widths[0] / 2)
        for k in range(1, len(v)):
            v[k] = max(v[k], v[k - 1] + (widths[k - 1] + widths[k]) / 2)
        v[-1] = min(v[-1], b - widths[-1] / 2)
        for k in range(len(v) - 2, -1, -1):
            v[k] = min(v[k], v[k + 1] - (widths[k] + widths[k + 1]) / 2)
        for i, vi in zip(members, v, strict=True):
            turn = _turn(specs[i], unit.tier_depth)
            depth, _ = footprint(specs[i], yaws[i] + turn)
            # Centred on the tier; a product deeper than the tier stands against the riser behind it.
            u = min(tier.center, tier.center + unit.tier_depth / 2 - depth / 2 - 0.003)
            x, y = unit.to_world(u, vi)
            out[i] = Placement(
                specs[i].name, (x, y, tier.top_z), unit.facing_yaw + turn + yaws[i], unit.name, tier_index
            )
    return [out[i] for i in range(len(specs))]
