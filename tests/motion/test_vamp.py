"""VAMP against OMPL on the same stocked scene: both plan, and both paths pass the project's mesh collision check.

VAMP is built by `make vamp` (tools/build_vamp.sh). Without it these tests skip, unless SCONE_REQUIRE_VAMP=1 (CI
sets it when `make vamp` succeeded): then a missing VAMP is a failure.
"""

from __future__ import annotations

import os

import numpy as np
import pytest

from scone_bt.motion import CollisionWorld, Obstacle, PlannerOptions, PlanStatus, plan_joint_path
from scone_bt.motion.grasp import top_down_rotation
from scone_bt.motion.model import pose_matrix
from scone_bt.motion.vamp_planner import (
    VampOptions,
    VampUnavailableError,
    mesh_check,
    plan_vamp,
    vamp_available,
)

if not vamp_available():
    if os.environ.get("SCONE_REQUIRE_VAMP") == "1":
        raise RuntimeError("SCONE_REQUIRE_VAMP=1 but vamp does not import: build it with `make vamp`")
    pytest.skip("VAMP is not installed: build it with `make vamp`", allow_module_level=True)


def _ik(arm, home, xyz, seed=0):
    sol = arm.ik(pose_matrix(top_down_rotation(-np.pi / 2), xyz), home, np.random.default_rng(seed))
    assert sol is not None
    return sol.q


@pytest.fixture(scope="module")
def stocked(arm, kitchen_cfg, robot_cfg, static_obstacles):
    """The kitchen's static boxes and eight products stocked on the shelving (seeded), as OMPL's obstacles."""
    from scipy.spatial.transform import Rotation

    from scone_bt.world import Kitchen

    products = list(kitchen_cfg.catalogue.objects)[:8]
    with Kitchen(kitchen_cfg, robot_cfg) as k:
        k.spawn(products, np.random.default_rng(3))
        placed = []
        for spec in products:
            st = k.object_state(spec.name)
            rot = Rotation.from_quat(st.orientation).as_matrix()
            placed.append(Obstacle(spec.name, spec.shape, spec.size, pose_matrix(rot, st.position)))
    world = CollisionWorld(arm, [*static_obstacles, *placed])
    return world, placed, np.asarray(robot_cfg.home)


def test_ompl_and_vamp_plan_mesh_valid_paths_on_the_same_scene(arm, stocked):
    world, placed, home = stocked
    assert any(ob.shape == "cylinder" for ob in placed) and any(ob.shape == "box" for ob in placed)
    start = _ik(arm, home, (0.45, -0.4, 0.3))
    top = max(placed, key=lambda ob: ob.pose[0, 3])  # the product farthest along x, over the shelf
    goal = _ik(arm, home, (*top.pose[:2, 3], top.pose[2, 3] + top.size[2] / 2 + 0.12))
    assert world.is_valid(start) and world.is_valid(goal)

    ompl = plan_joint_path(
        start, goal, arm.lower, arm.upper, world.is_valid, PlannerOptions(rng_seed=1, try_direct=False)
    )
    vamp = plan_vamp(start, goal, world, VampOptions(rng_seed=1))
    assert ompl.success, ompl.message
    assert vamp.success, vamp.result.message
    for path in (ompl.path, vamp.result.path):
        assert np.allclose(path[0], start) and np.allclose(path[-1], goal)
        check = mesh_check(world, path)
        assert check.valid, check.why
    assert vamp.mesh is not None and vamp.mesh.valid and vamp.mesh_valid
    # Seeded: the same query and seed give the same VAMP path.
    again = plan_vamp(start, goal, world, VampOptions(rng_seed=1))
    assert np.array_equal(again.result.path, vamp.result.path)


def test_a_goal_in_collision_is_not_solved_by_either(arm, stocked):
    world, placed, home = stocked
    product = placed[0]
    inside = _ik(arm, home, product.pose[:3, 3])  # the hand inside a product
    assert not world.is_valid(inside)
    ompl = plan_joint_path(home, inside, arm.lower, arm.upper, world.is_valid, PlannerOptions())
    vamp = plan_vamp(home, inside, world)
    assert ompl.status is PlanStatus.GOAL_INVALID
    assert vamp.result.status is PlanStatus.GOAL_INVALID and not vamp.success and vamp.result.path is None


def test_an_arm_vamp_has_no_model_of_is_a_typed_error(kitchen_cfg):
    from scone_bt.config import load_robot
    from scone_bt.motion import ArmModel

    iiwa = ArmModel(load_robot("iiwa7"))
    world = CollisionWorld(iiwa, [])
    with pytest.raises(VampUnavailableError, match="iiwa7"):
        plan_vamp(np.zeros(7), np.zeros(7), world)


def test_motion_benchmark_compares_the_planners_on_every_ompl_query_of_a_pick_and_place():
    from scone_bt.benchmarks.motion import _planner_report, _query

    plain = _query("kitchen", "panda", 0, 11, 2, 1)
    record = _query("kitchen", "panda", 0, 11, 2, 1, compare_vamp=True)
    timing = {"plan_ms", "plan_cpu_ms", "ruckig_ms", "ompl_ms", "sim_s", "planners"}
    # Recording the OMPL queries changes nothing of the pick-and-place itself.
    assert {k: v for k, v in record.items() if k not in timing} == {
        k: v for k, v in plain.items() if k not in timing
    }
    assert "planners" not in plain and record["planned"]
    rows = record["planners"]
    assert len(rows) >= 3  # approach, transit (carrying), return home
    assert any(r["carrying"] for r in rows) and any(not r["carrying"] for r in rows)
    for r in rows:
        assert r["ompl_status"] == "success" and r["vamp_status"] == "success"
        assert (
            r["ompl_ms"] > 0
            and r["vamp_ms"] > 0
            and r["ratio"] == pytest.approx(r["ompl_ms"] / r["vamp_ms"], rel=0.1)
        )
        assert isinstance(r["vamp_mesh_valid"], bool)
    report = _planner_report([record])
    assert report["queries"] == len(rows) and report["vamp_success_rate"] == 1.0
    assert report["both_solved"]["queries"] == len(rows) and report["both_solved"]["ratio_median"] > 0


def test_backend_vamp_plans_with_vamp_and_falls_back_to_ompl(arm, stocked, monkeypatch):
    import scone_bt.motion.vamp_planner as vamp_planner
    from scone_bt.motion.vamp_planner import MeshCheck

    world, placed, home = stocked
    start = _ik(arm, home, (0.45, -0.4, 0.3))
    top = max(placed, key=lambda ob: ob.pose[0, 3])
    goal = _ik(arm, home, (*top.pose[:2, 3], top.pose[2, 3] + top.size[2] / 2 + 0.12))
    options = PlannerOptions(rng_seed=1, try_direct=False, backend="vamp")
    result = plan_joint_path(start, goal, arm.lower, arm.upper, world.is_valid, options)
    assert result.success and result.message.startswith("VAMP"), result.message
    assert mesh_check(world, result.path).valid
    # A VAMP path that fails the mesh check (as a carry that tilts the object does): OMPL plans instead.
    monkeypatch.setattr(vamp_planner, "mesh_check", lambda *a, **k: MeshCheck(False, 1, None, "tilted"))
    result = plan_joint_path(start, goal, arm.lower, arm.upper, world.is_valid, options)
    assert result.success and result.message.startswith("RRTConnect"), result.message
    assert "fails the mesh check (tilted): planned with OMPL" in result.message
