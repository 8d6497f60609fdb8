"""A recording of the MuJoCo kitchen draws its arm (the URDF's meshes) where MuJoCo has it, every tick, as PyBullet's."""

from __future__ import annotations

import os

import numpy as np
import pytest

from scone_bt.config import load_robot
from scone_bt.viz import Recorder, TickSnapshot
from scone_bt.viz.readback import body_poses, component_values, summarize_recording

os.environ.setdefault("MUJOCO_GL", "egl")  # before mujoco is first imported (it reads it then)
pytest.importorskip("mujoco")

pytestmark = pytest.mark.slow

TICKS = 6
OBJECTS = ("salt", "olive oil")


def _poses_equal(a, b) -> None:
    assert a[0] == pytest.approx(b[0], abs=1e-6)
    qa, qb = np.asarray(a[1]), np.asarray(b[1])
    assert min(np.abs(qa - qb).max(), np.abs(qa + qb).max()) <= 1e-6, (qa, qb)


@pytest.mark.parametrize("arm", ["panda", "iiwa7"])
def test_both_engines_report_every_link_and_the_base_alike(arm, kitchen_cfg):
    """The recorder shifts the base from its centre of mass to its link frame: MuJoCo must report it as PyBullet."""
    from scone_bt.world import Kitchen
    from scone_bt.world.mj_kitchen import MjKitchen

    robot = load_robot(arm)
    with Kitchen(kitchen_cfg, robot) as pb, MjKitchen(kitchen_cfg, robot) as mj:
        bullet, mujoco = pb.link_poses(), mj.link_poses()
    assert "base" in mujoco and robot.end_effector_frame in mujoco
    assert set(mujoco) <= set(bullet), sorted(set(mujoco) - set(bullet))
    for name, pose in mujoco.items():
        _poses_equal(pose, bullet[name])


@pytest.fixture(scope="module")
def recording(tmp_path_factory, kitchen_cfg, robot_cfg):
    from scone_bt.world.mj_kitchen import MjKitchen

    path = tmp_path_factory.mktemp("viz_mj") / "mujoco.rrd"
    with MjKitchen(kitchen_cfg, robot_cfg) as kitchen, Recorder(save=path, robot_geometry="visual") as rec:
        kitchen.spawn([kitchen_cfg.catalogue.get(n) for n in OBJECTS], np.random.default_rng(0))
        rec.log_static_scene(kitchen)
        home = np.array(robot_cfg.home)
        for tick in range(TICKS):
            kitchen.hold_arm(home + 0.3 * np.sin(0.5 * (tick + 1)) * np.eye(7)[0])
            kitchen.advance(0.05)
            rec.log_tick(
                TickSnapshot(
                    tick=tick,
                    sim_time=kitchen.sim_time,
                    link_poses=kitchen.link_poses(),
                    object_poses={
                        n: (s.position, s.orientation)
                        for n in kitchen.objects
                        for s in [kitchen.object_state(n)]
                    },
                    executed_q=kitchen.arm_joint_positions(),
                )
            )
        hand = kitchen.link_poses()["panda_hand"]
    return path, hand


def test_the_recording_holds_the_kitchen_the_arm_meshes_and_the_products(recording):
    path, _ = recording
    summary = summarize_recording(path)
    assert summary.ticks == tuple(range(TICKS))
    expected = {
        "/world/scene/table",
        "/world/scene/shelf_tier0",
        "/world/robot/panda_link0/geometry_0",
        "/world/robot/panda_link4/geometry_0",
        "/world/robot/panda_hand/geometry_0",
        "/world/objects/salt",
        "/world/objects/olive_oil",
    }
    assert expected <= summary.entity_paths, sorted(expected - summary.entity_paths)
    # The links are drawn with the URDF's meshes, not boxes.
    meshes = component_values(path, "/world/robot/panda_link4/geometry_0", "Asset3D:blob")
    assert meshes and len(meshes[0][1][0]) > 1000


def test_the_arm_is_posed_where_mujoco_has_it_every_tick(recording):
    path, hand = recording
    poses = body_poses(path)
    # MuJoCo's base link frame is at the origin: the recording draws it there, not at its centre of mass.
    assert poses["robot/panda_link0"][0][1] == pytest.approx((0.0, 0.0, 0.0), abs=1e-6)
    shoulder = poses["robot/panda_link2"]
    assert set(range(TICKS)) <= {t for t, _ in shoulder}  # the arm moved every tick, and was re-posed
    assert poses["robot/panda_hand"][-1][1] == pytest.approx(hand[0], abs=1e-6)
    assert {"object/salt", "object/olive oil"} <= set(poses)
