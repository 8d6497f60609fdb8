"""Physical pick-and-place in PyBullet (DIRECT): success, failures that come from physics, cancel, determinism."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from scone_bt.config import load_robot
from scone_bt.motion import FailureStage, MotionPhase, MotionSystem, limits_of
from scone_bt.world import Kitchen

pytestmark = pytest.mark.slow


def test_pick_and_place_puts_the_object_on_the_table(stocked, arm, robot_cfg, assert_within_limits, task_for):
    kitchen, system = stocked
    assert kitchen.is_on_shelf("salt")
    task = task_for(kitchen, system, "salt")
    assert task.progress().phase is MotionPhase.IDLE and task.progress().phase == "idle"
    task.start()
    first = task.progress()
    assert first.phase in (MotionPhase.PLANNING, MotionPhase.READY) and not task.done()
    assert first.is_planning == (first.phase is MotionPhase.PLANNING)
    phases = []
    while not task.done():
        kitchen.advance(0.1)
        progress = task.progress()
        assert isinstance(progress.phase, MotionPhase)
        assert progress.is_planning == (progress.phase is MotionPhase.PLANNING)
        if not phases or phases[-1] != progress.phase:
            phases.append(progress.phase)
    outcome = task.outcome()
    assert outcome.success and outcome.stage is None, outcome.message
    assert outcome.still_held is None
    assert kitchen.is_on_table("salt")
    # The grasp held by friction alone: the only constraint is the fingers' coupling, robot to robot.
    bc = kitchen.bc
    constraints = [bc.getConstraintInfo(bc.getConstraintUniqueId(k)) for k in range(bc.getNumConstraints())]
    assert [(c[0], c[2]) for c in constraints] == [(kitchen.robot_id, kitchen.robot_id)]
    for phase in ("approach", "descend", "close", "lift", "transit", "lower", "release", "retreat", "home"):
        assert phase in phases
    assert 0 < outcome.duration < 20.0
    assert len(outcome.trajectories) == 7 and outcome.ee_path.shape[1] == 3
    limits = limits_of(robot_cfg)
    for traj in outcome.trajectories:
        assert_within_limits(traj, arm.lower, arm.upper, limits)
    # Back home, and the neighbours were not disturbed.
    assert np.allclose(kitchen.arm_joint_positions(), robot_cfg.home, atol=0.05)
    assert kitchen.is_on_shelf("sugar") and kitchen.is_on_shelf("honey")
    # The robot remembers what it put on the table (the shelf camera cannot see it) as an obstacle for later plans.
    placed = system.placed["salt"]
    assert np.allclose(placed.pose[:2, 3], kitchen.object_state("salt").position[:2], atol=0.02)


def test_object_wider_than_the_gripper_cannot_be_grasped(kitchen_cfg, robot_cfg, task_for, run_to_end):
    opening = 2 * robot_cfg.gripper.open_position
    # A can a little wider than the opening every way: the robot tries, the fingers land on its lid.
    wide = min(
        (o for o in kitchen_cfg.catalogue.objects if o.shape == "cylinder" and opening < o.grasp_width < 0.1),
        key=lambda o: (o.height > 0.15, o.name),
    )
    with Kitchen(kitchen_cfg, robot_cfg) as k:
        k.spawn([wide, kitchen_cfg.catalogue.get("salt")], np.random.default_rng(5))
        with MotionSystem.build(k) as system:
            outcome = run_to_end(k, task_for(k, system, wide.name))
        # It fails in the physics (the fingers slip off or tip it over), not in planning.
        physical = (FailureStage.GRASP, FailureStage.TRANSIT, FailureStage.PLACE)
        assert not outcome.success and outcome.stage in physical, outcome.message
        assert not k.is_on_table(wide.name)


def test_a_product_as_wide_as_the_opening_sticks_between_the_open_fingers(
    kitchen_cfg, robot_cfg, task_for, run_to_end
):
    # A bell pepper is 8.0 cm across, the Panda opens 8.0 cm: it is grasped, but opening cannot free it.
    with Kitchen(kitchen_cfg, robot_cfg) as k:
        k.spawn([kitchen_cfg.catalogue.get(n) for n in ("bell pepper", "salt")], np.random.default_rng(0))
        with MotionSystem.build(k) as system:
            outcome = run_to_end(k, task_for(k, system, "bell pepper"))
        # The finger sensors report it, so the robot can ask for it to be taken out (behaviours.ClearGripper).
        assert outcome.stage is FailureStage.PLACE and outcome.still_held == "bell pepper", outcome.message
        assert outcome.message == "released, but the bell pepper stuck between the open fingers"
        assert k.touches_robot("bell pepper") and not k.is_on_table("bell pepper")


def test_weak_gripper_lets_a_heavy_slippery_bottle_slip(kitchen_cfg, robot_cfg, task_for, run_to_end):
    weak = replace(robot_cfg, gripper=replace(robot_cfg.gripper, max_force=5.0))
    with Kitchen(kitchen_cfg, weak) as k:
        k.spawn([kitchen_cfg.catalogue.get(n) for n in ("olive oil", "salt")], np.random.default_rng(5))
        with MotionSystem.build(k) as system:
            outcome = run_to_end(k, task_for(k, system, "olive oil"))
        assert outcome.stage in (FailureStage.GRASP, FailureStage.TRANSIT), outcome.message
        assert not k.is_on_table("olive oil")


def test_unreachable_object_fails_at_ik_without_moving(kitchen_cfg, robot_cfg, detect, run_to_end):
    with Kitchen(kitchen_cfg, robot_cfg) as k:
        k.spawn([kitchen_cfg.catalogue.get("salt")], np.random.default_rng(17))
        # Seen (say, held up by the human) a metre away: no grasp pose of the arm reaches it.
        far = replace(detect(k, "salt"), position=(0.95, 0.7, 0.25))
        before = k.arm_joint_positions()
        with MotionSystem.build(k) as system:
            outcome = run_to_end(k, system.pick_and_place(far, k.specs["salt"], [], rng_seed=3))
        assert outcome.stage is FailureStage.IK and "salt" in outcome.message
        assert outcome.trajectories == ()
        assert np.allclose(k.arm_joint_positions(), before, atol=0.01)


def test_cancel_opens_the_hand_and_returns_home(stocked, robot_cfg, task_for):
    kitchen, system = stocked
    task = task_for(kitchen, system, "honey")
    task.start()
    while task.progress().phase not in ("transit", "done"):
        kitchen.advance(0.1)
    task.cancel()
    while not task.done():
        kitchen.advance(0.1)
    outcome = task.outcome()
    assert not outcome.success and outcome.stage is FailureStage.CANCELLED
    assert np.allclose(kitchen.arm_joint_positions(), robot_cfg.home, atol=0.05)
    assert np.sum(kitchen.gripper_positions()) > 0.07  # open


def test_same_seed_repeats_exactly(kitchen_cfg, robot_cfg, task_for, run_to_end):
    results = []
    for _ in range(2):
        with Kitchen(kitchen_cfg, robot_cfg) as k:
            k.spawn(
                [kitchen_cfg.catalogue.get(n) for n in ("salt", "sugar", "honey")], np.random.default_rng(1)
            )
            with MotionSystem.build(k) as system:
                outcome = run_to_end(k, task_for(k, system, "honey", seed=11))
            results.append((outcome.success, outcome.stage, k.sim_time, k.object_state("honey").position))
    assert results[0] == results[1]


def test_second_robot_picks_and_places(kitchen_cfg, task_for, run_to_end):
    iiwa = load_robot("iiwa7")
    with Kitchen(kitchen_cfg, iiwa) as k:
        k.spawn([kitchen_cfg.catalogue.get(n) for n in ("salt", "sugar", "honey")], np.random.default_rng(1))
        with MotionSystem.build(k) as system:
            outcome = run_to_end(k, task_for(k, system, "salt"))
        assert outcome.success, outcome.message
        assert k.is_on_table("salt")


def _put_on_the_spot_during_the_transit(kitchen, task, name):
    """Run the task; once the carry has begun, a person stands ``name`` on the planned place spot."""
    while not task.done():
        kitchen.advance(0.1)
        if task.progress().phase is MotionPhase.TRANSIT and kitchen.is_on_shelf(name):
            x, y, top = task.plan.place_spot
            kitchen.place_object(name, (x, y, top))
            assert kitchen.is_on_table(name)
    return task.outcome()


def test_a_product_put_on_the_place_spot_during_the_carry_sends_the_robot_to_another_spot(stocked, task_for):
    """A person puts the sugar where the robot is carrying the salt: the robot holds, plans another spot among
    what stands on the table now, and puts the salt there; the sugar is untouched, and the outcome says why."""
    kitchen, system = stocked
    task = task_for(kitchen, system, "salt")
    task.start()
    outcome = _put_on_the_spot_during_the_transit(kitchen, task, "sugar")
    assert outcome.success, outcome.message
    assert outcome.message == "placed upright on the table (at another spot: sugar stood on the one planned)"
    assert kitchen.is_on_table("salt") and kitchen.is_on_table("sugar")
    salt, sugar = (np.array(kitchen.object_state(n).position[:2]) for n in ("salt", "sugar"))
    assert np.linalg.norm(salt - sugar) > 0.05
    # The robot remembers where the salt stands now, not the spot it first planned.
    assert np.allclose(system.placed["salt"].pose[:2, 3], salt, atol=0.02)


def test_a_product_put_on_the_place_spot_is_knocked_over_and_said_where_the_robot_does_not_look(
    kitchen_cfg, robot_cfg, task_for
):
    """Without the look at the spot (a backend that cannot look again): lowering the salt knocks the sugar over,
    and the attempt is a failure that names it, not a success (the salt itself stands on the table)."""
    with Kitchen(kitchen_cfg, robot_cfg) as kitchen:
        kitchen.spawn(
            [kitchen_cfg.catalogue.get(n) for n in ("salt", "sugar", "honey")], np.random.default_rng(1)
        )
        with MotionSystem.build(kitchen) as system:
            task = task_for(kitchen, system, "salt")
            task._request_new_spot = None  # type: ignore[method-assign]
            task.start()
            outcome = _put_on_the_spot_during_the_transit(kitchen, task, "sugar")
            assert not kitchen.is_on_table("sugar")
            assert not outcome.success and outcome.stage is FailureStage.COLLISION, outcome.message
            assert "knocked sugar over or off the table" in outcome.message
