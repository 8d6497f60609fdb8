"""Side by side: whether a set of products fits the shelving's lanes at all, and one packing that shows it does.

`plan_stocking` (`scone_bt.stocking.place`) falls back on `pack_side_by_side` last, so a set it accepts is always
stocked; `wider_than_every_tier` names a product that stands nowhere, however few share the shelving.
"""

from __future__ import annotations

from collections.abc import Sequence

from scone_bt.config.catalogue import ObjectSpec
from scone_bt.config.scene import SceneSpec
from scone_bt.stocking.lanes import TierKey, lane_width, lowest_first, tier_length, too_deep

__all__ = ["fits_side_by_side", "pack_side_by_side", "wider_than_every_tier"]


def pack_side_by_side(scene: SceneSpec, specs: Sequence[ObjectSpec]) -> list[TierKey] | None:
    """A (unit, tier) for each product such that every tier's lanes fit it, or None when none is found.

    First fit, decreasing: products too deep for an upper tier first (onto a lowest tier when one has room), then
    the widest lanes first, each on the lowest tier with room; products face the robot (no yaw jitter). This is
    the packing `plan_stocking` falls back on last, so a set it accepts is always stocked.
    """
    if len(specs) > len(scene.slots()):
        return None
    units = {u.name: u for u in scene.shelves}
    tiers = lowest_first(scene)
    used = dict.fromkeys(tiers, 0.0)
    deep = [too_deep(spec, scene) for spec in specs]
    lanes = [{u.name: lane_width(spec, u) for u in scene.shelves} for spec in specs]
    order = sorted(range(len(specs)), key=lambda i: (not deep[i], -max(lanes[i].values())))
    out: dict[int, TierKey] = {}
    for i in order:
        ranked = sorted(tiers, key=lambda k: k[1] != 0) if deep[i] else tiers  # stable: lowest first
        for key in ranked:
            unit = units[key[0]]
            lane = lanes[i][key[0]]
            if used[key] + lane <= tier_length(unit, key[1]) + 1e-9:
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
            lane_width(spec, u) > tier_length(u, i) + 1e-9 for u in scene.shelves for i in range(len(u.tiers))
        ):
            longest = max(tier_length(u, i) for u in scene.shelves for i in range(len(u.tiers)))
            family = f" of family {spec.family!r}" if spec.family else ""
            return (
                f"product {spec.name!r}{family} ({' x '.join(f'{v:g}' for v in spec.size)} m) needs a "
                f"{min(lane_width(spec, u) for u in scene.shelves):.2f} m lane, longer than every shelf tier "
                f"(the longest is {longest:.2f} m); give it a smaller size in its catalogue file or leave it out "
                "of the recipe"
            )
    return None


def fits_side_by_side(scene: SceneSpec, specs: Sequence[ObjectSpec]) -> bool:
    """True if `pack_side_by_side` stocks these products (then `plan_stocking` never refuses them)."""
    return pack_side_by_side(scene, specs) is not None
