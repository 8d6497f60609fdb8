"""What the PyBullet and MuJoCo kitchens share: one static scene, one set of ground-truth rules (`GroundTruth`),
each engine reading quaternions its own way only to the last bit."""

from __future__ import annotations

import numpy as np
import pytest

from scone_bt.errors import ConfigError, UnknownNameError
from scone_bt.world.ground_truth import GroundTruth, rotation_of, yaw_of
from scone_bt.world.scene_boxes import static_boxes

NAMES = ("salt", "sugar", "honey", "pasta", "rice", "flour")


def test_the_pybullet_kitchen_is_built_from_the_shared_scene_and_rules(kitchen, kitchen_cfg):
    assert isinstance(kitchen, GroundTruth)
    assert kitchen.static_boxes == static_boxes(kitchen_cfg)
    assert set(kitchen.static_body_ids) == {b.name for b in static_boxes(kitchen_cfg)}


def test_the_mujoco_model_has_the_same_static_boxes(kitchen_cfg, robot_cfg):
    pytest.importorskip("mujoco")
    from scone_bt.world.mj_model import build_model

    _model, parts = build_model(kitchen_cfg, robot_cfg, (), 1.0 / robot_cfg.control.physics_hz)
    assert list(parts.boxes) == static_boxes(kitchen_cfg)


def test_pybullet_quaternion_arithmetic_agrees_with_the_engine_neutral_one(kitchen, kitchen_cfg, rng):
    """`Kitchen` keeps PyBullet's conversions (seeded runs repeat to the bit); they differ from `yaw_of` and
    `rotation_of` by rounding only, so the shared rules give the same answers with either."""
    kitchen.spawn([kitchen_cfg.catalogue.get(n) for n in NAMES], rng)
    for name in NAMES[:3]:
        assert kitchen.place_on_table(name)
    kitchen.place_object(NAMES[3], kitchen.free_place_spot(kitchen.specs[NAMES[3]]), yaw=0.7)
    kitchen.advance(1.0)
    for name in NAMES:
        q = kitchen.object_state(name).orientation
        assert kitchen.object_yaw(name) == pytest.approx(yaw_of(q), abs=1e-12)
        np.testing.assert_allclose(kitchen._rotation(q), rotation_of(q), atol=1e-12)
    assert kitchen.object_yaw(NAMES[3]) == pytest.approx(0.7, abs=1e-3)
    engine = (
        kitchen.free_place_spot(),
        kitchen.free_place_spot(kitchen.specs[NAMES[4]]),
        kitchen.objects_on_table(),
    )
    kitchen._yaw = yaw_of  # the engine-neutral arithmetic, on this kitchen alone
    kitchen._rotation = rotation_of
    neutral = (
        kitchen.free_place_spot(),
        kitchen.free_place_spot(kitchen.specs[NAMES[4]]),
        kitchen.objects_on_table(),
    )
    assert engine == neutral and engine[2] == frozenset(NAMES[:4])


def test_the_shared_checks_name_the_product(kitchen, kitchen_cfg, rng):
    kitchen.spawn([kitchen_cfg.catalogue.get("salt")], rng)
    with pytest.raises(ConfigError, match="'salt' is already in the kitchen"):
        kitchen.spawn([kitchen_cfg.catalogue.get("salt")], rng)
    with pytest.raises(UnknownNameError):
        kitchen.park_object("sugar")
    kitchen.park_object("salt")
    assert not kitchen.is_on_table("salt") and not kitchen.is_on_shelf("salt")
