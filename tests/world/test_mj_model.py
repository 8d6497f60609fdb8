"""The MuJoCo arm is the planner's arm: forward kinematics equal Pinocchio's on 1,000 random configurations."""

from __future__ import annotations

import os

import numpy as np
import pytest

from scone_bt.config import load_robot
from scone_bt.errors import ConfigError

os.environ.setdefault("MUJOCO_GL", "egl")  # before mujoco is first imported (it reads it then)
mujoco = pytest.importorskip("mujoco")

from scone_bt.motion.model import ArmModel  # noqa: E402
from scone_bt.world.mj_model import arm_spec  # noqa: E402


@pytest.mark.parametrize("robot_name", ["panda", "iiwa7"])
def test_forward_kinematics_equal_pinocchio(robot_name: str) -> None:
    robot = load_robot(robot_name)
    arm = ArmModel(robot)
    spec = arm_spec(robot)
    spec.worldbody.first_body().pos = list(robot.base_position)
    model = spec.compile()
    data = mujoco.MjData(model)
    arm_adr = [model.jnt_qposadr[model.joint(n).id] for n in robot.arm_joints]
    finger_adr = [model.jnt_qposadr[model.joint(n).id] for n in robot.gripper.joints]
    frames = {f.name for f in arm.model.frames}
    links = [model.body(i).name for i in range(1, model.nbody) if model.body(i).name in frames]
    assert robot.end_effector_frame in links and len(links) >= 9
    rng = np.random.default_rng(0)
    worst = 0.0
    for _ in range(1000):
        q = rng.uniform(arm.lower, arm.upper)
        data.qpos[arm_adr] = q
        data.qpos[finger_adr] = robot.gripper.open_position
        mujoco.mj_kinematics(model, data)
        for name in links:
            expected = arm.fk(q, name)
            body = model.body(name).id
            worst = max(worst, float(np.abs(expected[:3, 3] - data.xpos[body]).max()))
            worst = max(worst, float(np.abs(expected[:3, :3] - data.xmat[body].reshape(3, 3)).max()))
    assert worst <= 1e-6


def test_unreadable_urdf_is_one_line(tmp_path) -> None:
    import dataclasses

    robot = load_robot("panda")
    bad = tmp_path / "broken.urdf"
    bad.write_text(
        '<robot name="x"><link name="a"><visual><geometry><mesh filename="nowhere.obj"/>'
        "</geometry></visual></link></robot>"
    )
    with pytest.raises(ConfigError, match="nowhere.obj") as err:
        arm_spec(dataclasses.replace(robot, urdf=bad))
    assert "\n" not in str(err.value)
