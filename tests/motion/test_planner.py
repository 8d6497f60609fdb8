"""OMPL planning: success in the kitchen, typed failures, seeding, planner selection."""

from __future__ import annotations

import numpy as np
import pytest

from scone_bt.config import load_robot
from scone_bt.errors import UnknownNameError
from scone_bt.motion import ArmModel, CollisionWorld, Obstacle, PlannerOptions, PlanStatus, plan_joint_path
from scone_bt.motion.grasp import top_down_rotation
from scone_bt.motion.model import pose_matrix


def _goal(arm, home, xyz, seed=0):
    sol = arm.ik(pose_matrix(top_down_rotation(-np.pi / 2), xyz), home, np.random.default_rng(seed))
    assert sol is not None
    return sol.q


@pytest.fixture(scope="module")
def scene(arm, robot_cfg, static_obstacles):
    # A tall box standing on the lowest shelf step, between home and the goal.
    box = Obstacle("box", "box", (0.08, 0.08, 0.25), pose_matrix(np.eye(3), (0.37, 0.3, 0.125)))
    return CollisionWorld(arm, [*static_obstacles, box]), np.asarray(robot_cfg.home)


def test_plans_a_collision_free_path_shelf_to_table(arm, scene):
    world, home = scene
    start = _goal(arm, home, (0.37, 0.5, 0.2))
    goal = _goal(arm, home, (0.45, -0.4, 0.15))
    result = plan_joint_path(start, goal, arm.lower, arm.upper, world.is_valid, PlannerOptions(rng_seed=1))
    assert result.success and result.status is PlanStatus.SUCCESS
    path = result.path
    assert np.allclose(path[0], start) and np.allclose(path[-1], goal)
    for a, b in zip(path[:-1], path[1:], strict=True):
        assert world.segment_valid(a, b, resolution=0.01)


def test_goal_inside_an_obstacle_is_goal_invalid(arm, scene):
    world, home = scene
    inside = _goal(arm, home, (0.37, 0.3, 0.2))  # the hand inside the tall box
    result = plan_joint_path(home, inside, arm.lower, arm.upper, world.is_valid, PlannerOptions())
    assert not result.success
    assert result.status is PlanStatus.GOAL_INVALID and result.path is None
    assert "goal" in result.message


def test_start_in_collision_is_start_invalid(arm, scene):
    world, home = scene
    inside = _goal(arm, home, (0.37, 0.3, 0.2))
    result = plan_joint_path(inside, home, arm.lower, arm.upper, world.is_valid, PlannerOptions())
    assert result.status is PlanStatus.START_INVALID


def test_disconnected_goal_times_out(arm, scene):
    world, home = scene
    goal = _goal(arm, home, (0.45, -0.4, 0.15))
    # A forbidden band of the base joint between start and goal: no path exists (joint 1 does not wrap around).
    assert abs(home[0] - goal[0]) > 0.1
    mid = (home[0] + goal[0]) / 2
    band = (mid - 0.04, mid + 0.04)

    def is_valid(q):
        return world.is_valid(q) and not band[0] < q[0] < band[1]

    result = plan_joint_path(home, goal, arm.lower, arm.upper, is_valid, PlannerOptions(time_limit_s=0.3))
    assert result.status is PlanStatus.TIMED_OUT and result.path is None


def test_same_seed_same_path(arm, scene):
    world, home = scene
    goal = _goal(arm, home, (0.45, -0.4, 0.15))
    start = _goal(arm, home, (0.37, 0.5, 0.2))
    a = plan_joint_path(
        start, goal, arm.lower, arm.upper, world.is_valid, PlannerOptions(rng_seed=5, simplify=False)
    )
    b = plan_joint_path(
        start, goal, arm.lower, arm.upper, world.is_valid, PlannerOptions(rng_seed=5, simplify=False)
    )
    assert a.success and b.success
    assert np.array_equal(a.path, b.path)


@pytest.mark.parametrize("name", ["RRT", "KPIECE1"])
def test_other_planners_by_name(arm, scene, name):
    world, home = scene
    goal = _goal(arm, home, (0.45, -0.4, 0.15))
    result = plan_joint_path(
        home, goal, arm.lower, arm.upper, world.is_valid, PlannerOptions(name=name, time_limit_s=2.0)
    )
    assert result.success, result.message


def test_unknown_planner_names_the_valid_ones(arm, scene):
    world, home = scene
    with pytest.raises(UnknownNameError, match="RRTConnect"):
        plan_joint_path(home, home, arm.lower, arm.upper, world.is_valid, PlannerOptions(name="AStar"))


def test_second_robot_plans(static_obstacles):
    iiwa = ArmModel(load_robot("iiwa7"))
    home = np.asarray(iiwa.config.home)
    world = CollisionWorld(iiwa, static_obstacles)
    goal = iiwa.ik(
        pose_matrix(top_down_rotation(np.pi / 2), (0.45, -0.4, 0.15)), home, np.random.default_rng(0)
    )
    assert goal is not None
    result = plan_joint_path(home, goal.q, iiwa.lower, iiwa.upper, world.is_valid, PlannerOptions(rng_seed=2))
    assert result.success, result.message


def test_plans_to_a_goal_set_and_says_which_goal_it_reached(arm, scene):
    world, home = scene
    start = _goal(arm, home, (0.37, 0.5, 0.2))
    inside = _goal(arm, home, (0.37, 0.3, 0.2))  # in the tall box: dropped from the set
    far = _goal(arm, home, (0.45, -0.4, 0.15))
    near = _goal(arm, home, (0.5, -0.3, 0.2))
    for direct in (True, False):
        opts = PlannerOptions(rng_seed=2, try_direct=direct)
        result = plan_joint_path(
            start, np.array([inside, far, near]), arm.lower, arm.upper, world.is_valid, opts
        )
        assert result.success and result.goal_index in (1, 2), result.message
        assert np.allclose(result.path[-1], [inside, far, near][result.goal_index])
        if not direct:
            assert "direct" not in result.message  # OMPL's GoalStates did it
        for a, b in zip(result.path[:-1], result.path[1:], strict=True):
            assert world.segment_valid(a, b, resolution=0.01)
    all_bad = plan_joint_path(start, np.array([inside, inside]), arm.lower, arm.upper, world.is_valid)
    assert all_bad.status is PlanStatus.GOAL_INVALID and "all 2 goal configurations" in all_bad.message
