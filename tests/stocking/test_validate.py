"""Names checked against the stocked kitchen: products, slots, cameras and pinned products, one line each."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest

from scone_bt.errors import ConfigError
from scone_bt.recipes import load_recipe
from scone_bt.stocking import (
    KitchenNames,
    kitchen_names,
    parse_slot,
    slots_beside,
    stock_shelf,
    stocked_names,
)


@dataclass(frozen=True)
class _Pin:
    product: str
    slot: str
    neighbours: tuple[str, ...] = ()
    gap_m: float | None = None


@dataclass(frozen=True)
class _Stocked:
    names: KitchenNames


@pytest.fixture(scope="module")
def stocked(kitchen_cfg) -> _Stocked:
    stock = stock_shelf(
        load_recipe("example:tomato-pasta"),
        kitchen_cfg.catalogue,
        kitchen_cfg.scene,
        3,
        np.random.default_rng(0),
    )
    return _Stocked(kitchen_names(kitchen_cfg, stock, "f.yaml"))


def _error(call, *args) -> str:
    with pytest.raises(ConfigError) as caught:
        call(*args)
    message = str(caught.value)
    assert "\n" not in message
    return message


def test_the_stocked_names_are_the_recipes_and_the_distractors_on_the_shelf(kitchen_cfg, stocked) -> None:
    stock = stock_shelf(
        load_recipe("example:tomato-pasta"),
        kitchen_cfg.catalogue,
        kitchen_cfg.scene,
        3,
        np.random.default_rng(0),
    )
    off = {*stock.recipe.unstocked, *stock.recipe.off_shelf}
    assert stocked_names(stock) == tuple(
        n for n in (*stock.recipe.needed, *stock.distractors) if n not in off
    )
    assert len(stock.distractors) == 3 and set(stock.distractors) <= stocked.names.present
    assert stocked.names.present == set(stocked_names(stock))
    assert stocked.names.cameras == (
        "shelf_front",
        "shelf_left",
        "shelf_back",
        "table",
    )  # shelf cameras first


def test_a_product_is_stocked_or_the_line_says_why(kitchen_cfg, stocked) -> None:
    names = stocked.names
    some = sorted(names.present)[0]
    names.product(some, "k")
    unknown = _error(names.product, "unobtainium", "events[0].remove")
    assert unknown.startswith(
        "f.yaml: events[0].remove: 'unobtainium' is not a product of the catalogue; valid: "
    )
    assert some in unknown
    absent = next(n for n in kitchen_cfg.catalogue.names() if n not in names.present)
    assert "is not stocked in this episode" in _error(names.product, absent, "k")
    assert _error(names.products, [some, "x"], "world.on_table").startswith("f.yaml: world.on_table[1]: 'x' ")


def test_a_slot_names_a_unit_tier_and_index_of_the_shelves(stocked) -> None:
    names = stocked.names
    names.slot("left/2/2", "k")
    assert (
        _error(names.slot, "side/0/0", "k")
        == "f.yaml: k: unknown shelf unit 'side'; valid: front, left, back"
    )
    assert _error(names.slot, "left/3/0", "k") == "f.yaml: k: unit 'left' has tiers 0-2 (got 3)"
    assert _error(names.slot, "left/2/3", "k") == "f.yaml: k: tier left/2 has slots 0-2 (got 3)"
    assert "is not a shelf slot like left/1/0" in _error(names.slot, "left-2-3", "k")
    assert parse_slot("back/0/11") == ("back", 0, 11)


def test_a_camera_is_one_of_the_kitchens(stocked) -> None:
    stocked.names.camera("table", "k")
    assert _error(stocked.names.camera, "roof", "events[2].cover_camera") == (
        "f.yaml: events[2].cover_camera: unknown camera 'roof'; valid: shelf_front, shelf_left, shelf_back, table"
    )


def test_the_slots_beside_a_slot_nearest_first_within_the_tier() -> None:
    assert slots_beside("left/1/1", 4) == ["left/1/2", "left/1/0", "left/1/3"]
    assert slots_beside("left/1/0", 3) == ["left/1/1", "left/1/2"]
    assert slots_beside("left/1/0", 1) == []


def test_pinned_products_each_own_a_slot_with_room_for_their_neighbours(stocked) -> None:
    names = stocked.names
    a, b, c, d = sorted(names.present)[:4]
    names.placements([_Pin(a, "left/2/0", (b, c)), _Pin(d, "front/0/4", (b, c), gap_m=0.02)])
    taken = _error(names.placements, [_Pin(a, "left/0/1"), _Pin(b, "left/0/1")])
    assert taken == (
        f"f.yaml: world.place[1].slot: left/0/1 is already world.place[0]'s ({a}); give each product its own slot"
    )
    no_room = _error(names.placements, [_Pin(a, "left/2/0", (b, c, d))])
    assert no_room.endswith(
        "world.place[0].neighbours: tier left/2 has 3 slots, no room for 3 neighbours beside slot left/2/0"
    )
    gap = _error(names.placements, [_Pin(a, "left/0/0", (b, c, d), gap_m=0.01)])
    assert gap.endswith("world.place[0].gap_m: a gap places at most 2 neighbours, one on each side (got 3)")
    # The checks run in the order the file reads: the product before its slot, the slot before its neighbours.
    first = _error(names.placements, [_Pin("x", "side/0/0", ("y",))])
    assert first.startswith("f.yaml: world.place[0].product: 'x' ")
    assert _error(names.placements, [_Pin(a, "left/0/0", ("y",))]).startswith(
        "f.yaml: world.place[0].neighbours[0]: 'y' "
    )
