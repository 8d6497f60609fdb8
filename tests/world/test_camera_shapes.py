"""A robot file's `camera_shapes` changes what the cameras render of the arm, never the physics."""

import dataclasses

import numpy as np
import pytest

from scone_bt.perception.camera import Camera
from scone_bt.world import Kitchen
from scone_bt.world import camera as cam


@pytest.fixture
def kitchens(kitchen_cfg, robot_cfg):
    made = []
    for shapes in ("visual", "collision"):
        k = Kitchen(kitchen_cfg, dataclasses.replace(robot_cfg, camera_shapes=shapes))
        names = kitchen_cfg.catalogue.names()[:12]
        k.spawn([kitchen_cfg.catalogue.get(n) for n in names], np.random.default_rng(3))
        made.append(k)
    yield made
    for k in made:
        k.close()


def _state(k):
    joints = [s[0] for s in k.bc.getJointStates(k.robot_id, list(range(k.bc.getNumJoints(k.robot_id))))]
    poses = [k.bc.getBasePositionAndOrientation(b) for b in k.objects.values()]
    return joints, poses


def test_the_physics_is_the_same_with_either_shapes(kitchens, robot_cfg):
    # The arm sweeps down through the front stand's products: contacts, pushes, topples.
    targets = np.array(robot_cfg.home) + np.array([0.0, 0.9, 0.0, 0.9, 0.0, -0.2, 0.0])
    for k in kitchens:
        k.advance(0.5)
        for s in np.linspace(0.0, 1.0, 60):
            k.hold_arm(list((1 - s) * np.array(robot_cfg.home) + s * targets))
            k.advance(1 / 30)
    assert _state(kitchens[0]) == _state(kitchens[1])


def test_the_images_differ_only_where_the_arm_is(kitchens, kitchen_cfg, robot_cfg):
    visual, collision = kitchens
    for k in kitchens:
        k.advance(0.5)
    cameras = [Camera(c) for c in kitchen_cfg.cameras]
    # At home the arm is in no camera's view: the images are the same.
    for c in cameras:
        a, b = cam._render(visual, c), cam._render(collision, c)
        assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])
    # Over the table, the table camera sees the arm: its outline differs by under a fifth of its pixels.
    over_table = [-0.8, 0.3, 0.0, -1.9, 0.0, 2.2, 0.785]
    table = Camera(kitchen_cfg.table_camera)
    empty = cam._render(visual, table)[1]
    for k in kitchens:
        for name, q in zip(robot_cfg.arm_joints, over_table, strict=True):
            k.bc.resetJointState(k.robot_id, k.joint_index[name], q)
    arm_v = np.abs(cam._render(visual, table)[1] - empty) > 0.005
    arm_c = np.abs(cam._render(collision, table)[1] - empty) > 0.005
    assert arm_v.sum() > 2000  # the arm is in view
    assert (arm_v ^ arm_c).sum() < 0.2 * (arm_v | arm_c).sum()
