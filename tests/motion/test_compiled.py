"""The compiled kernels (motion.compiled) against Pinocchio: kinematics, log6 and Jlog6, and the IK they make."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from scone_bt.config import load_robot
from scone_bt.motion import ArmModel
from scone_bt.motion.compiled import chain_poses, jlog6, log6
from scone_bt.motion.model import IKOptions


@pytest.fixture(scope="module", params=["panda", "iiwa7"])
def any_arm(request):
    return ArmModel(load_robot(request.param))


def test_chain_poses_are_pinocchios(any_arm):
    parents, placements, axes = any_arm.chain
    poses = np.empty((len(parents), 4, 4))
    data = any_arm.model.createData()
    rng = np.random.default_rng(0)
    for _ in range(50):
        q = rng.uniform(any_arm.lower, any_arm.upper)
        chain_poses(q, parents, placements, axes, poses)
        pin.forwardKinematics(any_arm.model, data, q)
        for j in range(len(parents)):
            np.testing.assert_allclose(poses[j], data.oMi[j].homogeneous, atol=1e-12)


@pytest.mark.parametrize("angle", [0.0, 1e-7, 5e-5, 0.3, 1.0, 2.5, 3.1, np.pi - 1e-6])
def test_log6_and_jlog6_are_pinocchios(angle):
    rng = np.random.default_rng(int(angle * 1e6))
    for _ in range(20):
        axis = rng.normal(size=3)
        m = pin.SE3(pin.exp3(axis / np.linalg.norm(axis) * angle), rng.normal(size=3))
        out, jac = np.empty(6), np.empty((6, 6))
        log6(m.rotation.copy(), m.translation.copy(), out)
        jlog6(m.rotation.copy(), m.translation.copy(), jac)
        np.testing.assert_allclose(out, pin.log6(m).vector, atol=1e-8)
        if angle < np.pi - 1e-3:  # Jlog6 is singular at a half turn
            np.testing.assert_allclose(jac, pin.Jlog6(m), atol=1e-8)


def test_the_compiled_ik_takes_pinocchios_steps(any_arm):
    """Reachable and unreachable targets, near and random seeds, restarts: the same answers to rounding."""
    rng = np.random.default_rng(3)
    compiled = any_arm.chain
    answered = 0
    for k in range(40):
        q = rng.uniform(any_arm.lower, any_arm.upper)
        target = any_arm.fk(q)
        if k % 5 == 0:
            target[:3, 3] += 2.0  # out of reach
        seed = np.clip(q + rng.normal(scale=0.4, size=any_arm.dof), any_arm.lower, any_arm.upper)
        options = IKOptions(restarts=2) if k % 2 else IKOptions(restarts=0, max_iterations=20)
        answers = []
        for chain in (compiled, None):
            any_arm.chain = chain
            answers.append(any_arm.ik(target, seed, np.random.default_rng(k), options))
        any_arm.chain = compiled
        fast, slow = answers
        assert (fast is None) == (slow is None)
        if fast is not None:
            answered += 1
            np.testing.assert_allclose(fast.q, slow.q, atol=1e-7)
            assert fast.position_error == pytest.approx(slow.position_error, abs=1e-9)
            assert fast.rotation_error == pytest.approx(slow.rotation_error, abs=1e-9)
            assert np.linalg.norm(any_arm.fk(fast.q)[:3, 3] - target[:3, 3]) < 2e-3
    assert 10 < answered < 40  # both kinds of answer were compared


def test_a_chain_the_kernel_does_not_model_uses_pinocchio(arm, robot_cfg):
    """A joint that is not a plain revolute one (here: a model rebuilt with a free-flyer) has no compiled chain."""
    from scone_bt.motion.model import _revolute_chain

    flyer = pin.buildModelFromUrdf(str(robot_cfg.urdf), pin.JointModelFreeFlyer())
    assert _revolute_chain(flyer) is None
    assert _revolute_chain(arm.model) is not None


def test_the_motion_systems_warm_up_runs_for_both_arms(any_arm):
    """The warm-up a MotionSystem queues on its planning thread (its future is not read: an error there would
    go unseen) runs to the end for each robot file."""
    from scone_bt.motion.collision import Obstacle
    from scone_bt.motion.model import pose_matrix
    from scone_bt.motion.system import _warm_up

    floor = Obstacle("floor", "box", (4.0, 4.0, 0.02), pose_matrix(np.eye(3), (0.0, 0.0, -0.01)))
    assert _warm_up(any_arm, np.asarray(any_arm.config.home, dtype=float), [floor]) is None
