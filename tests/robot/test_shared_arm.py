"""Episodes run in turn in one thread share the arm model of their robot file (its URDF is parsed once)."""

from __future__ import annotations

import dataclasses
import threading

import pytest

from scone_bt.robot.sim import shared_arm


def test_one_arm_model_per_thread_and_robot_configuration(robot_cfg):
    arm = shared_arm(robot_cfg)
    assert shared_arm(robot_cfg) is arm
    other: list[object] = []
    thread = threading.Thread(target=lambda: other.append(shared_arm(robot_cfg)))
    thread.start()
    thread.join()
    assert other[0] is not arm  # another thread plans with its own model
    moved = dataclasses.replace(robot_cfg, home=tuple(q + 0.1 for q in robot_cfg.home))
    assert shared_arm(moved) is not arm and shared_arm(moved).config == moved


def test_a_motion_system_refuses_the_arm_model_of_another_robot_configuration(kitchen, robot_cfg):
    from scone_bt.motion import MotionSystem

    moved = dataclasses.replace(robot_cfg, home=tuple(q + 0.1 for q in robot_cfg.home))
    with pytest.raises(ValueError, match="another robot configuration"):
        MotionSystem.build(kitchen, robot_cfg, arm=shared_arm(moved))
    with MotionSystem.build(kitchen, robot_cfg, arm=shared_arm(robot_cfg)) as system:
        assert system.arm is shared_arm(robot_cfg)
