import pytest

from scone_bt.errors import UnknownNameError


def test_spawn_places_objects_on_distinct_shelf_slots(kitchen, kitchen_cfg, rng):
    specs = [kitchen_cfg.catalogue.get(n) for n in kitchen_cfg.catalogue.names()[:12]]
    slots = kitchen.spawn(specs, rng)
    assert len(set(slots.values())) == 12
    for name in slots:
        assert kitchen.is_on_shelf(name) and not kitchen.is_on_table(name)


def test_human_places_object_on_table(kitchen, kitchen_cfg, rng):
    kitchen.spawn([kitchen_cfg.catalogue.get("salt")], rng)
    assert kitchen.human_place_on_table("salt")
    kitchen.advance(0.5)
    assert kitchen.is_on_table("salt") and not kitchen.is_on_shelf("salt")


def test_unknown_object_in_kitchen(kitchen):
    with pytest.raises(UnknownNameError):
        kitchen.object_state("salt")
