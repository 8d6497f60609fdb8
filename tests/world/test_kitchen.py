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


def test_a_resting_scene_is_not_stepped(kitchen, kitchen_cfg, rng):
    kitchen.spawn([kitchen_cfg.catalogue.get(n) for n in ("salt", "sugar")], rng)
    kitchen.advance(1.0)
    before = {n: kitchen.object_state(n).position for n in kitchen.objects}
    skipped, stepped = kitchen.steps_skipped, kitchen.steps - kitchen.steps_skipped
    kitchen.advance(2.0)
    per_s = round(1 / kitchen.time_step)
    assert kitchen.steps_skipped == skipped + 2 * per_s and kitchen.steps - kitchen.steps_skipped == stepped
    assert kitchen.sim_time == pytest.approx(3.5)
    assert {n: kitchen.object_state(n).position for n in kitchen.objects} == before
    kitchen.hold_arm([q + 0.3 for q in kitchen.robot_config.home])  # a new motor target wakes the scene
    kitchen.advance(0.5)
    assert kitchen.steps - kitchen.steps_skipped == stepped + per_s // 2


def test_resting_objects_far_from_the_moving_arm_freeze_without_changing_the_outcome(kitchen_cfg, robot_cfg):
    import numpy as np

    from scone_bt.world import Kitchen

    names = kitchen_cfg.catalogue.names()[:8]
    end = {}
    for freeze in (False, True):
        with Kitchen(kitchen_cfg, robot_cfg, freeze_resting=freeze) as k:
            k.spawn([kitchen_cfg.catalogue.get(n) for n in names], np.random.default_rng(3))
            k.hold_arm([q + (0.6 if i == 0 else 0.0) for i, q in enumerate(robot_cfg.home)])
            k.advance(3.0)
            assert bool(k.frozen) == freeze
            assert all(k.is_on_shelf(n) for n in names)
            end[freeze] = {n: np.array(k.object_state(n).position) for n in names}
    assert max(np.abs(end[True][n] - end[False][n]).max() for n in names) < 0.003


def test_the_human_finds_room_on_the_table_for_a_long_recipe(kitchen, kitchen_cfg, rng):
    cat = kitchen_cfg.catalogue
    # Fifteen products with small footprints: more than the nine configured place spots.
    small = sorted(cat.objects, key=lambda o: max(o.size[0], o.size[1]))[:15]
    kitchen.spawn(small, rng)
    for spec in small:
        assert kitchen.human_place_on_table(spec.name), spec.name
    kitchen.advance(1.0)
    assert all(kitchen.is_on_table(spec.name) for spec in small)


def test_products_touched_follows_a_push_from_product_to_product(kitchen, kitchen_cfg, rng):
    """What the held product touches, and what that touches in turn (a row on the table); not a product apart."""
    names = ("salt", "sugar", "honey", "ketchup")
    kitchen.spawn([kitchen_cfg.catalogue.get(n) for n in names], rng)
    (cx, cy, cz), (_, _, sz) = kitchen_cfg.scene.table
    top = cz + sz / 2
    x = 0.0
    for name in names[:3]:  # salt, sugar and honey side by side, each touching the next
        half = kitchen.specs[name].grasp_width / 2
        x += half
        kitchen.place_object(name, (cx - 0.1 + x, cy, top))
        x += half
    kitchen.place_object("ketchup", (cx + 0.2, cy + 0.2, top))
    kitchen.advance(0.3)
    assert kitchen.products_touched("salt") == frozenset({"sugar", "honey"})
    assert kitchen.products_touched("ketchup") == frozenset()
    assert kitchen.products_touched(None) == frozenset()  # the arm at home touches nothing
    assert kitchen.objects_on_table() == frozenset(names)


def test_products_at_a_spot_are_those_standing_on_the_table_within_the_margin(kitchen, kitchen_cfg, rng):
    """The look at a place spot: what stands on the table over or beside its footprint, with its shape."""
    import numpy as np

    from scone_bt.motion.collision import Obstacle

    names = ("salt", "sugar", "honey")
    kitchen.spawn([kitchen_cfg.catalogue.get(n) for n in names], rng)
    (cx, cy, cz), (_, _, sz) = kitchen_cfg.scene.table
    top = cz + sz / 2
    salt = kitchen.specs["salt"]
    pose = np.eye(4)
    pose[:3, 3] = (cx, cy, top + salt.height / 2)
    spot = Obstacle("salt", salt.shape, salt.size, pose)  # where the salt would stand
    kitchen.place_object("sugar", (cx + 0.01, cy, top))  # on the spot
    half = (salt.grasp_width + kitchen.specs["honey"].grasp_width) / 2
    kitchen.place_object("honey", (cx, cy + half + 0.003, top))  # 3 mm beside it
    kitchen.advance(0.3)
    found = kitchen.products_at(spot, 0.005)
    assert sorted(o.name for o in found) == ["honey", "sugar"]
    sugar = next(o for o in found if o.name == "sugar")
    assert np.allclose(sugar.pose[:3, 3], kitchen.object_state("sugar").position)
    assert sugar.size == kitchen.specs["sugar"].size
    assert [o.name for o in kitchen.products_at(spot, 0.001)] == ["sugar"]  # honey keeps 3 mm
    kitchen.park_object("sugar")  # taken away: the spot is free of it
    assert [o.name for o in kitchen.products_at(spot, 0.001)] == []


def test_products_touched_names_a_restocked_kitchens_products_not_the_last_ones(kitchen, kitchen_cfg, rng):
    """The generator restocks one kitchen per worker and the new products get the old body ids: the same ids
    named the previous execution's products, and asking the kitchen about one raised UnknownNameError."""
    state = kitchen.bc.saveState()
    (cx, cy, cz), (_, _, sz) = kitchen_cfg.scene.table
    top = cz + sz / 2
    for pair in (("salt", "sugar"), ("honey", "ketchup")):
        kitchen.clear_products(state)
        kitchen.spawn([kitchen_cfg.catalogue.get(n) for n in pair], rng)
        first, second = pair
        kitchen.place_object(first, (cx, cy, top))
        kitchen.place_object(
            second,
            (cx + kitchen.specs[first].grasp_width / 2 + kitchen.specs[second].grasp_width / 2, cy, top),
        )
        kitchen.advance(0.3)
        assert kitchen.products_touched(first) == frozenset({second})
