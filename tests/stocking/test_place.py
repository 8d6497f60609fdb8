"""Stocking the shelving: heaviest lowest, side by side with room for the fingers, seeded."""

from __future__ import annotations

import numpy as np
import pytest

from scone_bt.config import ObjectSpec
from scone_bt.config.footprint import footprint
from scone_bt.errors import ConfigError
from scone_bt.stocking import FINGER_ROOM_M, LANE_MIN_M, plan_stocking


def _product(name: str, mass: float, size=(0.06, 0.06, 0.10), shape: str = "cylinder") -> ObjectSpec:
    return ObjectSpec(name, (), shape, size, mass, 0.5, "test", (1.0, 1.0, 1.0, 1.0), 0)


def _unit_v(scene, place):
    unit = next(u for u in scene.shelves if u.name == place.unit)
    return unit.to_unit(place.position[0], place.position[1])


def test_heavier_products_stand_lower(kitchen_cfg):
    scene = kitchen_cfg.scene
    specs = [_product(f"p{i}", mass) for i, mass in enumerate(np.linspace(0.1, 2.0, 20))]
    for seed in range(5):
        places = plan_stocking(scene, specs, np.random.default_rng(seed))
        by_mass = sorted(zip(specs, places, strict=True), key=lambda sp: -sp[0].mass)
        heights = [p.position[2] for _, p in by_mass]
        assert heights == sorted(heights), seed


def test_narrow_products_stand_on_distinct_slots(kitchen_cfg):
    scene = kitchen_cfg.scene
    slots = {tuple(np.round(s.position, 6)) for s in scene.slots()}
    specs = [_product(f"p{i}", 0.3) for i in range(len(slots))]
    places = plan_stocking(scene, specs, np.random.default_rng(1))
    spots = [tuple(np.round(p.position, 6)) for p in places]
    assert len(set(spots)) == len(specs) and set(spots) <= slots


def test_wide_products_get_wide_lanes_without_overlap(kitchen_cfg):
    scene = kitchen_cfg.scene
    specs = [_product(f"box{i}", 0.5, (0.08, 0.16, 0.2), "box") for i in range(8)]
    specs += [_product(f"can{i}", 0.4, (0.074, 0.074, 0.11)) for i in range(8)]
    places = plan_stocking(scene, specs, np.random.default_rng(2))
    rows: dict[tuple[str, int], list[tuple[float, float]]] = {}
    for spec, place in zip(specs, places, strict=True):
        unit = next(u for u in scene.shelves if u.name == place.unit)
        _, v = _unit_v(scene, place)
        _, width = footprint(spec, place.yaw - unit.facing_yaw)
        rows.setdefault((place.unit, place.tier), []).append((v, width))
    for row in rows.values():
        row.sort()
        for (va, wa), (vb, wb) in zip(row, row[1:], strict=False):
            assert vb - va >= (wa + wb) / 2 + FINGER_ROOM_M - 1e-9
            assert vb - va >= LANE_MIN_M - 1e-9


def test_stocking_is_seeded(kitchen_cfg):
    specs = [_product(f"p{i}", 0.1 * i + 0.1) for i in range(12)]
    a = plan_stocking(kitchen_cfg.scene, specs, np.random.default_rng(7))
    b = plan_stocking(kitchen_cfg.scene, specs, np.random.default_rng(7))
    c = plan_stocking(kitchen_cfg.scene, specs, np.random.default_rng(8))
    assert a == b and a != c


def test_too_many_or_too_wide_is_a_config_error(kitchen_cfg):
    scene = kitchen_cfg.scene
    many = [_product(f"p{i}", 0.3) for i in range(len(scene.slots()) + 1)]
    with pytest.raises(ConfigError, match="do not fit"):
        plan_stocking(scene, many, np.random.default_rng(0))
    wide = [_product(f"w{i}", 0.3, (0.08, 0.30, 0.1), "box") for i in range(len(scene.slots()))]
    with pytest.raises(ConfigError, match="side by side"):
        plan_stocking(scene, wide, np.random.default_rng(0))


def test_a_product_deeper_than_its_tier_stands_square_on_a_lowest_tier(kitchen_cfg):
    # The light flat pack is drawn onto upper tiers (heaviest lowest); its front would hang over the tier below.
    scene = kitchen_cfg.scene
    flat = _product("tortillas", 0.05, size=(0.22, 0.22, 0.02), shape="box")
    tall = [_product(f"jar{i}", 1.0, size=(0.075, 0.075, 0.13)) for i in range(9)]
    for seed in range(6):
        places = plan_stocking(scene, [flat, *tall], np.random.default_rng(seed))
        unit = next(u for u in scene.shelves if u.name == places[0].unit)
        assert places[0].tier == 0, seed
        assert places[0].yaw == pytest.approx(unit.facing_yaw), seed
        # Its centre of mass stays over the tier (stands against the riser, overhanging the front).
        assert _unit_v(scene, places[0])[0] > unit.tiers[0].center - unit.tier_depth / 2, seed


def test_products_that_fit_their_tier_keep_their_seeded_places(kitchen_cfg):
    # Adding a deep product elsewhere in the list changes no other product's draws.
    scene = kitchen_cfg.scene
    specs = [_product(f"p{i}", 0.2 + 0.1 * i) for i in range(8)]
    deep = _product("tray", 0.05, size=(0.22, 0.22, 0.02), shape="box")
    shallow = _product("tray", 0.05, size=(0.08, 0.08, 0.02), shape="box")
    a = plan_stocking(scene, [*specs, deep], np.random.default_rng(3))
    b = plan_stocking(scene, [*specs, shallow], np.random.default_rng(3))
    assert [p.yaw for p in a[:-1]] == [p.yaw for p in b[:-1]]


def test_a_tight_set_that_fits_side_by_side_is_always_stocked(kitchen_cfg):
    # The narrowest catalogue products up to the most that fit: drawn slots and heaviest-first packing crowd them.
    from scone_bt.stocking import fits_side_by_side, lane_width

    scene, catalogue = kitchen_cfg.scene, kitchen_cfg.catalogue
    specs = sorted(
        (catalogue.get(n) for n in catalogue.names()),
        key=lambda s: max(lane_width(s, u) for u in scene.shelves),
    )
    tight: list = []
    for spec in specs:
        if not fits_side_by_side(scene, [*tight, spec]):
            break
        tight.append(spec)
    assert len(tight) >= len(scene.slots()) - 8
    for seed in range(8):
        places = plan_stocking(scene, tight, np.random.default_rng(seed))
        rows: dict[tuple[str, int], list[tuple[float, float]]] = {}
        for spec, place in zip(tight, places, strict=True):
            unit = next(u for u in scene.shelves if u.name == place.unit)
            _, width = footprint(spec, place.yaw - unit.facing_yaw)
            rows.setdefault((place.unit, place.tier), []).append((_unit_v(scene, place)[1], width))
        for row in rows.values():
            row.sort()
            for (va, wa), (vb, wb) in zip(row, row[1:], strict=False):
                assert vb - va >= max((wa + wb) / 2 + FINGER_ROOM_M, LANE_MIN_M) - 1e-9, seed
