"""The carry's watch (`motion.path_watch`): products the plan did not know, and which of them the rest of the motion
would hit; in PyBullet, a product put down in the carry's way is gone around, and without the watch it is hit."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from scone_bt.motion import ArmModel, FailureStage, MotionPhase
from scone_bt.motion.collision import Obstacle
from scone_bt.motion.model import pose_matrix
from scone_bt.motion.path_watch import MOVED_M, PathWatch
from scone_bt.motion.placement import Footprint, TableRegion, clear_spots


def _box(name: str, x: float, y: float, z: float = 0.1, size=(0.05, 0.05, 0.1)) -> Obstacle:
    return Obstacle(name, "box", size, pose_matrix(np.eye(3), (x, y, z)))


@pytest.mark.parametrize("base", [(0.0, 0.0, 0.0), (0.5, 0.2, 0.1)])
def test_products_are_placed_in_the_world_frame_wherever_the_arm_stands(robot_cfg, base):
    """An arm whose base stands off the origin (both robot files put it there, so this is the only check of the
    frames): a box at the hand, in world coordinates, is in the way; the same box 1 m away is not."""
    arm = ArmModel(replace(robot_cfg, base_position=base))
    q = np.asarray(robot_cfg.home, dtype=float)
    hand = arm.fk(q)[:3, 3]
    watch = PathWatch.of(arm, _box("tea", 0.0, 0.0, 0.1, (0.04, 0.04, 0.04)), None, ())
    assert [o.name for o in watch.in_the_way(np.array([q, q]), None, [_box("sugar", *hand)])] == ["sugar"]
    assert watch.in_the_way(np.array([q, q]), None, [_box("salt", hand[0], hand[1] + 1.0, hand[2])]) == ()


def test_the_carried_product_itself_can_be_what_hits(arm, robot_cfg):
    """A small box 10 cm beyond the hand, where the carried product hangs, is in the way; the same box is clear
    of a watch whose carried product sits at the hand (so it is the product, not the hand, that would hit it)."""
    q = np.asarray(robot_cfg.home, dtype=float)
    beyond = (arm.fk(q) @ np.array([0.0, 0.0, 0.1, 1.0]))[:3]
    box = _box("sugar", *beyond, size=(0.02, 0.02, 0.02))
    hanging = PathWatch.of(arm, _box("tea", 0.0, 0.0, 0.1, (0.04, 0.04, 0.04)), None, ())
    at_hand = PathWatch.of(arm, _box("tea", 0.0, 0.0, 0.0, (0.04, 0.04, 0.04)), None, ())
    assert [o.name for o in hanging.in_the_way(np.array([q, q]), None, [box])] == ["sugar"]
    assert at_hand.in_the_way(np.array([q, q]), None, [box]) == ()


@pytest.fixture
def watch(arm):
    """A watch of a plan that knew the salt at (0.3, -0.4), carrying a 4 cm cube 10 cm below the hand."""
    carried = _box("tea", 0.0, 0.0, 0.1, (0.04, 0.04, 0.04))
    return PathWatch.of(arm, carried, None, [_box("salt", 0.3, -0.4)])


def test_a_product_is_unknown_when_new_on_the_table_or_moved_beyond_the_camera_error(watch):
    now = [
        _box("salt", 0.3 + MOVED_M / 2, -0.4),
        _box("sugar", 0.5, 0.0),
        _box("tea", 0.2, 0.2),
    ]
    assert [o.name for o in watch.unknown(now, {"tea"})] == ["sugar"]
    moved = [_box("salt", 0.3 + 1.5 * MOVED_M, -0.4)]
    assert [o.name for o in watch.unknown(moved, ())] == ["salt"]
    assert [o.name for o in watch.learn(moved)] == ["salt"]  # planned anew knowing it there
    assert watch.unknown(moved, ()) == ()
    # A later re-plan is told everything learnt since the first plan, not only what it learns then.
    assert [o.name for o in watch.learn([_box("sugar", 0.5, 0.0)])] == ["salt", "sugar"]


def test_only_a_product_the_rest_of_the_motion_reaches_is_in_the_way(arm, watch):
    q = np.asarray(arm.config.home, dtype=float)
    hand = arm.fk(q)[:3, 3]  # the world frame
    transit = np.array([q, q])
    at_hand = _box("sugar", *hand)
    far = _box("honey", hand[0] + 1.5, hand[1] + 1.5, hand[2])
    assert [o.name for o in watch.in_the_way(transit, None, [at_hand, far])] == ["sugar"]
    # The far one is cleared where it stands; the one in the way is still in the way when asked again.
    assert [o.name for o in watch.in_the_way(transit, None, [at_hand, far])] == ["sugar"]
    # A cleared product is checked again once it moves: slid 1 cm onto the hand (under MOVED_M), it is in the way.
    slid = _box("honey", *hand)
    slid.pose[0, 3] += 0.01
    cleared = _box("honey", hand[0] + 0.3, hand[1], hand[2])
    assert watch.in_the_way(transit, None, [cleared]) == ()
    assert [o.name for o in watch.in_the_way(transit, None, [slid])] == ["honey"]
    # Only the lowering reaches it: in the way all the same.
    away = np.array([q, q])
    away[:, 0] += np.pi / 2
    assert [o.name for o in watch.in_the_way(away, transit, [at_hand])] == ["sugar"]


def _in_the_way(system, task, kitchen, name, transit=None, lower=None, place_spot=None, avoid=None):
    """A table spot for ``name`` beside the place spot (not on it, nor within 9 cm of ``avoid``) that the transit
    or the lowering reaches (default: the first plan's)."""
    plan = task.plan
    spec = kitchen.specs[name]
    carried = Obstacle(task.target.name, task.spec.shape, task.spec.size, plan.feasible.cand.object_in_ee)
    probe = PathWatch.of(system.arm, carried, plan.finger_position, ())
    segments = {s.phase: s.trajectory.positions for s in plan.segments}
    transit = segments[MotionPhase.TRANSIT] if transit is None else transit
    lower = segments[MotionPhase.LOWER] if lower is None else lower
    x0, y0, top = plan.place_spot if place_spot is None else place_spot
    table = TableRegion.from_scene(kitchen.config.scene)
    for r in (0.10, 0.12, 0.14, 0.08, 0.16, 0.20):
        for a in np.linspace(0.0, 2 * np.pi, 24, endpoint=False):
            x, y = x0 + r * np.cos(a), y0 + r * np.sin(a)
            if avoid is not None and np.hypot(x - avoid[0], y - avoid[1]) < 0.09:
                continue
            if not clear_spots(
                table, [], Footprint.of(spec), np.array([[x, y]]), np.zeros(1), 0.0, 0.01
            ).free[0]:
                continue  # a person stands it on the table, not beyond its edge
            ob = Obstacle(name, spec.shape, spec.size, pose_matrix(np.eye(3), (x, y, top + spec.height / 2)))
            if probe.in_the_way(transit, lower, [ob]):
                return x, y, top
    raise AssertionError("no spot beside the place spot lies in the carry's way")


def _put_in_the_way_during_the_transit(kitchen, system, task, name):
    """Run the task; once the carry has begun, a person stands ``name`` in its way. Returns the outcome and
    where ``name`` was put."""
    spot = None
    while not task.done():
        kitchen.advance(0.1)
        if spot is None and task.progress().phase is MotionPhase.TRANSIT:
            spot = _in_the_way(system, task, kitchen, name)
            kitchen.place_object(name, spot)
            assert kitchen.is_on_table(name)
    assert spot is not None
    return task.outcome(), np.array(spot[:2])


@pytest.mark.slow
def test_a_product_put_down_in_the_carry_s_way_is_gone_around(stocked, task_for):
    kitchen, system = stocked
    task = task_for(kitchen, system, "salt")
    task.start()
    outcome, put = _put_in_the_way_during_the_transit(kitchen, system, task, "sugar")
    assert outcome.success, outcome.message
    assert outcome.message == "placed upright on the table (another way: sugar was put down in its way)"
    assert kitchen.is_on_table("sugar")
    assert np.linalg.norm(np.array(kitchen.object_state("sugar").position[:2]) - put) < 0.005  # untouched


@pytest.mark.slow
def test_a_second_re_plan_still_knows_what_the_first_learnt(stocked, task_for):
    """The sugar is put in the carry's way, then the honey in the way the robot takes around it: the second
    re-plan goes around both, and neither is touched."""
    kitchen, system = stocked
    task = task_for(kitchen, system, "salt")
    task.start()
    put: dict[str, np.ndarray] = {}
    while not task.done():
        kitchen.advance(0.1)
        c = task._controller
        if not put and task.progress().phase is MotionPhase.TRANSIT:
            put["sugar"] = np.array(_in_the_way(system, task, kitchen, "sugar")[:2])
            kitchen.place_object("sugar", (*put["sugar"], task.plan.place_spot[2]))
        elif len(put) == 1 and c.spot_changes == 1 and c.phase is MotionPhase.TRANSIT:
            rest = c.current.trajectory.positions
            spot = _in_the_way(
                system,
                task,
                kitchen,
                "honey",
                rest[len(rest) // 2 :],
                c._lowering(),
                c.place_spot,
                put["sugar"],
            )
            put["honey"] = np.array(spot[:2])
            kitchen.place_object("honey", spot)
    assert len(put) == 2, "the second product was never put down"
    outcome = task.outcome()
    assert outcome.success, outcome.message
    assert outcome.message.count("another way") == 2, outcome.message
    for name, where in put.items():
        assert np.linalg.norm(np.array(kitchen.object_state(name).position[:2]) - where) < 0.005, name


@pytest.mark.slow
def test_without_the_watch_the_product_in_the_way_is_hit(stocked, task_for):
    """The control: the same attempt whose controller looks only at its spot runs into the sugar (so the spot the
    first test chose is really in the way, and the watch is what saves it)."""
    kitchen, system = stocked
    task = task_for(kitchen, system, "salt")
    task._path_watch = None  # type: ignore[method-assign]
    task.start()
    outcome, put = _put_in_the_way_during_the_transit(kitchen, system, task, "sugar")
    moved = np.linalg.norm(np.array(kitchen.object_state("sugar").position[:2]) - put)
    assert not outcome.success and outcome.stage is FailureStage.COLLISION, outcome.message
    assert "sugar" in outcome.message or moved > 0.005


def _named_spot(kitchen_cfg) -> tuple[float, float, float]:
    """The kitchen's first named table spot (x, y, table top z)."""
    x, y = kitchen_cfg.scene.place_spots[0]
    return x, y, kitchen_cfg.scene.table_top_z


@pytest.mark.slow
def test_a_spot_the_request_named_is_kept_and_the_product_in_its_way_gone_around(
    stocked, task_for, kitchen_cfg
):
    """A request that names its spot keeps it: the rest of the carry goes there another way, around the sugar."""
    kitchen, system = stocked
    named = _named_spot(kitchen_cfg)
    task = task_for(kitchen, system, "salt", place_spot=named)
    task.start()
    outcome, put = _put_in_the_way_during_the_transit(kitchen, system, task, "sugar")
    assert outcome.success, outcome.message
    assert outcome.message == "placed upright on the table (another way: sugar was put down in its way)"
    salt = np.array(kitchen.object_state("salt").position[:2])
    assert np.linalg.norm(salt - np.array(named[:2])) < 0.01  # on the spot it was asked for
    assert np.linalg.norm(np.array(kitchen.object_state("sugar").position[:2]) - put) < 0.005  # untouched


@pytest.mark.slow
def test_a_spot_the_request_named_is_not_traded_for_another_when_something_stands_on_it(
    stocked, task_for, kitchen_cfg
):
    kitchen, system = stocked
    named = _named_spot(kitchen_cfg)
    task = task_for(kitchen, system, "salt", place_spot=named)
    task.start()
    while not task.done():
        kitchen.advance(0.1)
        if task.progress().phase is MotionPhase.TRANSIT and not kitchen.is_on_table("sugar"):
            kitchen.place_object("sugar", named)
    message = task.outcome().message
    assert "sugar stood on the planned spot, and the request named its spot" in message, message
