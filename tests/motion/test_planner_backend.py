"""The robot file's planner backend and the OMPL fallback, without VAMP installed (no skip: `make test` runs these
everywhere; tests/motion/test_vamp.py holds the tests that need VAMP itself)."""

from __future__ import annotations

import numpy as np
import pytest

from scone_bt.motion import CollisionWorld, PlannerOptions, plan_joint_path, vamp_planner


def test_backend_vamp_on_an_arm_vamp_has_no_model_of_plans_with_ompl(static_obstacles):
    from scone_bt.config import load_robot
    from scone_bt.motion import ArmModel

    cfg = load_robot("iiwa7")
    iiwa = ArmModel(cfg)
    world = CollisionWorld(iiwa, static_obstacles)
    home = np.asarray(cfg.home)
    goal = home.copy()
    goal[0] += 0.6
    options = PlannerOptions(rng_seed=1, try_direct=False, backend="vamp")
    result = plan_joint_path(home, goal, iiwa.lower, iiwa.upper, world.is_valid, options)
    assert result.success and "VAMP has no model of iiwa7: planned with OMPL" in result.message


def test_robot_file_planner_backend(tmp_path, robot_cfg):
    from scone_bt.config import load_robot
    from scone_bt.errors import ConfigError

    assert robot_cfg.planner.backend == "ompl" and PlannerOptions.of(robot_cfg.planner).backend == "ompl"
    text = robot_cfg.source.read_text()
    assert "backend: ompl" in text
    (tmp_path / "vamp_panda.yaml").write_text(text.replace("backend: ompl", "backend: vamp"))
    cfg = load_robot(tmp_path / "vamp_panda.yaml")
    assert cfg.planner.backend == "vamp" and PlannerOptions.of(cfg.planner).backend == "vamp"
    (tmp_path / "bad.yaml").write_text(text.replace("backend: ompl", "backend: moveit"))
    with pytest.raises(ConfigError, match="backend"):
        load_robot(tmp_path / "bad.yaml")


def test_backend_vamp_without_vamp_installed_plans_with_ompl(arm, static_obstacles, monkeypatch):
    monkeypatch.setattr(vamp_planner, "vamp_available", lambda: False)
    world = CollisionWorld(arm, static_obstacles)
    home = np.asarray(arm.config.home)
    goal = home.copy()
    goal[0] += 0.6
    options = PlannerOptions(rng_seed=1, try_direct=False, backend="vamp")
    result = plan_joint_path(home, goal, arm.lower, arm.upper, world.is_valid, options)
    assert result.success and "VAMP is not installed (make vamp): planned with OMPL" in result.message


def test_a_robot_file_asking_for_vamp_without_vamp_is_refused_before_the_robot_acts(monkeypatch, tmp_path):
    """It planned every motion with OMPL without a word (`scone-bench motion` refused the same)."""
    import dataclasses

    from scone_bt.config import load_robot
    from scone_bt.motion import MotionSystem, vamp_planner
    from scone_bt.motion.vamp_planner import VampUnavailableError

    monkeypatch.setattr(vamp_planner, "vamp_available", lambda: False)
    robot = load_robot("panda")
    robot = dataclasses.replace(robot, planner=dataclasses.replace(robot.planner, backend="vamp"))

    class Cell:  # build() refuses before it touches the cell
        robot_config = robot

    with pytest.raises(
        VampUnavailableError, match=r"planner.backend: vamp, but VAMP is not installed; build it"
    ):
        MotionSystem.build(Cell(), robot)  # type: ignore[arg-type]
