"""The scenario test rig (`SimWorld`) on a real simulated kitchen: every change goes through `Kitchen`'s public
methods and the robot's components, and does what the scenario file says."""

from __future__ import annotations

import math

import numpy as np
import pytest

from scone_bt.robot.rig import SimWorld, SlotRef
from scone_bt.robot.sim import SimRobot

CANS = ("crushed tomatoes", "evaporated milk")


@pytest.fixture
def world(kitchen, kitchen_cfg, robot_cfg, rng):
    kitchen.spawn([kitchen_cfg.catalogue.get(n) for n in (*CANS, "salt", "garlic")], rng)
    robot = SimRobot(kitchen, kitchen_cfg, robot_cfg, np.random.default_rng(1))
    return SimWorld(kitchen, robot)


def _xy(world: SimWorld, name: str) -> np.ndarray:
    return np.asarray(world.kitchen.object_state(name).position[:2])


def test_swap_exchanges_two_products_places(world) -> None:
    a, b = (_xy(world, n) for n in CANS)
    world.swap(*CANS)
    world.kitchen.advance(0.5)
    assert np.allclose(_xy(world, CANS[0]), b, atol=0.01) and np.allclose(_xy(world, CANS[1]), a, atol=0.01)
    assert world.kitchen.is_on_shelf(CANS[0]) and world.kitchen.is_on_shelf(CANS[1])


def test_place_on_shelf_stands_the_product_on_the_slot(world) -> None:
    slot = SlotRef("left", 1, 0)
    (x, y, _), _ = world.slot_surface(slot)
    world.place_on_shelf("salt", slot, math.radians(30))
    world.kitchen.advance(0.5)
    assert np.allclose(_xy(world, "salt"), (x, y), atol=0.01) and world.kitchen.is_on_shelf("salt")


def test_calibration_offset_shifts_every_perceived_position(world) -> None:
    before = {d.name: np.asarray(d.position) for d in world.robot.perceive().detections}
    world.apply_fault(calibration_offset=(0.0, 0.025, 0.0))
    after = {d.name: np.asarray(d.position) for d in world.robot.perceive().detections}
    assert before and set(before) == set(after)
    for name in before:
        assert np.allclose(after[name] - before[name], (0.0, 0.025, 0.0), atol=0.004), name


def test_speed_scales_replace_the_arms_limits(world) -> None:
    v0 = world.robot.motion.limits.velocity.copy()
    datasheet = np.asarray(world.robot.robot_config.limits.velocity)
    world.apply_fault(velocity_scale=0.2, jerk_scale=0.5)
    assert np.allclose(world.robot.motion.limits.velocity, datasheet * 0.2)
    assert not np.allclose(world.robot.motion.limits.velocity, v0)
    assert world.robot.robot_config.limits.jerk_scale == 0.5


def test_gripper_and_planner_faults_reach_the_robot(world) -> None:
    world.apply_fault(gripper_force=3.0, finger_friction=0.05, planner_budget_s=0.01)
    g = world.kitchen.robot_config.gripper
    assert (g.max_force, g.finger_friction) == (3.0, 0.05)
    assert world.robot.motion.planner.time_limit_s == 0.01


def test_a_covered_camera_sees_nothing_and_uncovered_sees_again(world) -> None:
    name = world.camera_names()[0]
    seen = len(world.robot.perceive().detections)
    for cam in world.camera_names():
        world.cover_camera(cam)
    assert len(world.robot.perceive().detections) == 0 < seen
    for cam in world.camera_names():
        world.uncover_camera(cam)
    assert len(world.robot.perceive().detections) == seen
    with pytest.raises(Exception, match="valid"):
        world.cover_camera("nope" + name)


@pytest.mark.parametrize("gap", [0.02, 0.06])
def test_place_beside_leaves_the_stated_gap_along_the_tier(world, gap) -> None:
    world.place_on_shelf("salt", SlotRef("left", 1, 2))
    world.kitchen.advance(0.3)
    world.place_beside("garlic", "salt", gap, +1)
    world.place_beside("crushed tomatoes", "salt", gap, -1)
    world.kitchen.advance(0.5)
    specs = world.kitchen.specs
    for other in ("garlic", "crushed tomatoes"):
        between = float(np.linalg.norm(_xy(world, other) - _xy(world, "salt")))
        edge = (
            between - specs["salt"].size[0] / 2 - specs[other].size[0] / 2
        )  # cylinders: size[0] is the diameter
        assert edge == pytest.approx(gap, abs=0.004), other


def test_place_beside_past_the_tiers_end_is_one_line(world) -> None:
    world.place_on_shelf("salt", SlotRef("left", 1, 0))
    with pytest.raises(
        Exception, match=r"^no room for 'garlic' 6.0 cm beside 'salt' on left/1 \(the tier spans"
    ):
        world.place_beside("garlic", "salt", 0.06, -1)
