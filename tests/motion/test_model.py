"""Arm model: kinematics, IK and the collision model built from robots/*.yaml."""

from __future__ import annotations

import numpy as np
import pytest

from scone_bt.config import load_robot
from scone_bt.errors import ConfigError, UnknownNameError
from scone_bt.motion import ArmModel, CollisionWorld
from scone_bt.motion.grasp import top_down_rotation
from scone_bt.motion.model import pose_matrix


def test_model_has_the_arm_dofs_and_urdf_limits(arm, robot_cfg):
    assert arm.dof == robot_cfg.dof == 7
    assert np.all(arm.lower < arm.upper)
    assert arm.upper[3] == pytest.approx(0.0)  # panda_joint4 is always bent


def test_home_pose_points_down(arm, robot_cfg):
    pose = arm.fk(np.asarray(robot_cfg.home))
    assert pose[:3, 2] @ np.array([0, 0, -1.0]) > 0.99
    assert 0.2 < pose[0, 3] < 0.4 and pose[2, 3] > 0.3


@pytest.mark.parametrize("target", [(0.37, 0.3, 0.08), (0.5, -0.4, 0.15), (0.45, 0.2, 0.3)])
def test_ik_reaches_grasp_poses_within_limits(arm, robot_cfg, target):
    goal = pose_matrix(top_down_rotation(-np.pi / 2), target)
    sol = arm.ik(goal, np.asarray(robot_cfg.home), np.random.default_rng(0))
    assert sol is not None
    assert arm.within_limits(sol.q)
    reached = arm.fk(sol.q)
    assert np.linalg.norm(reached[:3, 3] - goal[:3, 3]) < 2e-3
    assert np.allclose(reached[:3, :3], goal[:3, :3], atol=2e-2)


def test_ik_fails_out_of_reach(arm, robot_cfg):
    goal = pose_matrix(top_down_rotation(0.0), (1.5, 0.0, 0.2))
    assert arm.ik(goal, np.asarray(robot_cfg.home), np.random.default_rng(0)) is None


def test_self_collision_pairs_skip_adjacent_and_yaml_disabled_links(arm):
    names = [g.name for g in arm.geom_model.geometryObjects]
    pairs = {
        frozenset((arm.link_of_geometry[names[i]], arm.link_of_geometry[names[j]]))
        for i, j in arm.self_collision_pairs()
    }
    assert frozenset(("panda_link1", "panda_link2")) not in pairs  # adjacent
    assert frozenset(("panda_link0", "panda_link2")) not in pairs  # listed in the YAML
    assert frozenset(("panda_link1", "panda_hand")) in pairs


def test_collision_world_sees_obstacles(arm, robot_cfg, static_obstacles):
    world = CollisionWorld(arm, static_obstacles)
    home = np.asarray(robot_cfg.home)
    assert world.is_valid(home)
    down = arm.ik(
        pose_matrix(top_down_rotation(-np.pi / 2), (0.47, -0.43, -0.05)), home, np.random.default_rng(1)
    )
    assert down is not None  # kinematically fine, but the hand is inside the table
    assert not world.is_valid(down.q)
    assert any("table" in b for _, b in world.colliding_pairs(down.q))


def test_unknown_end_effector_frame_names_the_frames(robot_cfg, tmp_path):
    text = robot_cfg.source.read_text().replace(
        "end_effector_frame: panda_grasptarget", "end_effector_frame: nope"
    )
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    with pytest.raises(UnknownNameError, match="panda_grasptarget"):
        ArmModel(load_robot(path))


def test_second_robot_loads(robot_cfg):
    iiwa = ArmModel(load_robot("iiwa7"))
    assert iiwa.dof == 7
    home = np.asarray(iiwa.config.home)
    assert iiwa.fk(home)[:3, 2] @ np.array([0, 0, -1.0]) > 0.99


def test_disabled_pair_with_unknown_link_names_the_links(robot_cfg, tmp_path):
    text = robot_cfg.source.read_text().replace(
        "- [panda_link0, panda_link2]", "- [panda_link0, panda_link99]"
    )
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    with pytest.raises(UnknownNameError, match="panda_link99.*panda_hand"):
        ArmModel(load_robot(path))


def test_malformed_disabled_pair_is_a_config_error(robot_cfg, tmp_path):
    text = robot_cfg.source.read_text().replace("- [panda_link0, panda_link2]", "- [panda_link0]")
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    with pytest.raises(ConfigError, match="disabled_pairs\\[0\\]"):
        load_robot(path)


@pytest.mark.parametrize("robot", ["panda", "iiwa7"])
def test_geometry_reach_bounds_every_geometry_over_random_joints(robot):
    """The bound that prunes collision pairs must hold for every q, or a real collision would go unchecked."""
    import pinocchio as pin

    arm = ArmModel(load_robot(robot))
    data, gdata = arm.model.createData(), arm.geom_model.createData()
    rng = np.random.default_rng(0)
    worst = 0.0
    for _ in range(300):
        q = rng.uniform(arm.lower, arm.upper)
        pin.updateGeometryPlacements(arm.model, data, arm.geom_model, gdata, q)
        for k, g in enumerate(arm.geom_model.geometryObjects):
            g.geometry.computeLocalAABB()
            centre = gdata.oMg[k].act(np.asarray(g.geometry.aabb_center, dtype=float))
            far = float(np.linalg.norm(centre)) + float(g.geometry.aabb_radius)
            assert far <= arm.geometry_reach[k] + 1e-9
            worst = max(worst, far / arm.geometry_reach[k])
    assert worst > 0.5  # a bound that is not absurdly loose


def test_collision_world_keeps_every_pair_an_obstacle_in_reach_needs(arm, robot_cfg):
    """Pairs are pruned only for obstacles beyond a link's reach: a box at the shoulder is still checked."""
    from scone_bt.motion import Obstacle

    base = np.asarray(robot_cfg.base_position)
    near = Obstacle("near", "box", (0.05, 0.05, 0.05), pose_matrix(np.eye(3), base + [0.0, 0.0, 0.333]))
    far = Obstacle("far", "box", (0.05, 0.05, 0.05), pose_matrix(np.eye(3), base + [5.0, 0.0, 0.0]))
    world = CollisionWorld(arm, [near, far])
    names = [g.name for g in world.geom_model.geometryObjects]
    checked = {names[p.first] for p in world.geom_model.collisionPairs} | {
        names[p.second] for p in world.geom_model.collisionPairs
    }
    assert "obstacle:near" in checked and "obstacle:far" not in checked
    assert not world.is_valid(np.asarray(robot_cfg.home))  # the shoulder box is inside link 1


def test_a_joint_measured_just_past_its_limit_is_planned_from_the_limit(arm, robot_cfg):
    """A slip left the Panda's wrist 6e-5 rad past its limit (the hummus at seed 2): every later plan and the way
    home failed at the start. A plan takes such a reading at the limit; a joint farther past stays refused."""
    from scone_bt.motion.model import LIMIT_OVERSHOOT_RAD
    from scone_bt.motion.pick_place import plan_home
    from scone_bt.motion.planner import PlannerOptions
    from scone_bt.motion.timing import limits_of

    read = np.array([1.7682, -0.8067, 1.7087, -1.9793, 0.8764, 1.9452, arm.upper[6] + 6e-5])
    assert not arm.within_limits(read)
    taken = arm.as_measured(read)
    assert arm.within_limits(taken) and taken[6] == arm.upper[6] and np.array_equal(taken[:6], read[:6])
    far = read.copy()
    far[6] = arm.upper[6] + 2 * LIMIT_OVERSHOOT_RAD
    assert np.array_equal(arm.as_measured(far), far)
    home = np.asarray(robot_cfg.home, dtype=float)
    options, limits, rate = PlannerOptions(), limits_of(robot_cfg), robot_cfg.control.rate_hz
    way = plan_home(arm, read, home, (), options, limits, rate, seed=0)
    assert way is not None and np.allclose(way.trajectory.positions[-1], home, atol=1e-6)
    assert plan_home(arm, far, home, (), options, limits, rate, seed=0) is None
