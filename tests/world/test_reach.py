"""Every shelf slot can be grasped by geometry with both arms: IK and collision-free pre-grasp, descent and grasp."""

from __future__ import annotations

import numpy as np
import pytest

from scone_bt.config import ObjectSpec, load_kitchen, load_robot
from scone_bt.perception.types import Detection

# A typical product: a 400 g can (about ∅74 × 110 mm, 0.45 kg).
CAN = ObjectSpec(
    name="can",
    aliases=(),
    shape="cylinder",
    size=(0.074, 0.074, 0.11),
    mass=0.45,
    friction=0.35,
    material="metal",
    rgba=(0.8, 0.2, 0.1, 1.0),
    marker_id=0,
)


def _static_obstacles(kitchen_cfg, robot_cfg):
    from scone_bt.motion.collision import fixed_obstacles
    from scone_bt.world import Kitchen

    with Kitchen(kitchen_cfg, robot_cfg) as kitchen:
        return list(fixed_obstacles(kitchen.static_boxes, kitchen_cfg.scene.floor_z))


def _graspable(arm, static, slot, rng) -> str:
    """'' if some grasp of the can standing on the slot is reachable and collision-free, else why not."""
    from scone_bt.config.grasp import GraspParams
    from scone_bt.motion import CollisionWorld, Obstacle, grasp_candidates
    from scone_bt.motion.grasp import object_pose

    x, y, z = slot.position
    det = Detection("can", -1, (x, y, z + CAN.height), slot.yaw, 1.0, (0, 0, 0, 0))
    target = Obstacle("can", CAN.shape, CAN.size, object_pose(det, CAN))
    free = CollisionWorld(arm, [*static, target])
    near = CollisionWorld(arm, [*static, target], ignore_for_hand=["can"], padding=0.004)
    home = np.asarray(arm.config.home, dtype=float)
    y_axis = arm.fk(home)[:3, 1]
    why = "no grasp candidate"
    for cand in grasp_candidates(det, CAN, GraspParams(), float(np.arctan2(y_axis[1], y_axis[0]))):
        pre = arm.ik(cand.pregrasp, home, rng)
        if pre is None or not free.is_valid(pre.q):
            why = "pre-grasp out of reach or colliding"
            continue
        grasp = arm.ik(cand.grasp, pre.q, rng)
        if grasp is None or not near.segment_valid(pre.q, grasp.q):
            why = "descent out of reach or colliding"
            continue
        return ""
    return why


@pytest.mark.slow
@pytest.mark.parametrize("robot", ["panda", "iiwa7"])
def test_every_slot_is_graspable_by_both_arms(robot):
    from scone_bt.motion import ArmModel

    kitchen_cfg, robot_cfg = load_kitchen(), load_robot(robot)
    arm = ArmModel(robot_cfg)
    static = _static_obstacles(kitchen_cfg, robot_cfg)
    rng = np.random.default_rng(0)
    slots = kitchen_cfg.scene.slots()
    failures = {s.position: why for s in slots if (why := _graspable(arm, static, s, rng))}
    assert not failures, f"{robot}: {len(failures)} of {len(slots)} slots not graspable: {failures}"


def test_slot_outside_reach_is_reported():
    """The check can fail: a slot 1.2 m away is beyond either arm."""
    from scone_bt.config.scene import Slot
    from scone_bt.motion import ArmModel

    kitchen_cfg, robot_cfg = load_kitchen(), load_robot("panda")
    arm = ArmModel(robot_cfg)
    far = Slot((1.2, 0.0, 0.0), 0.0, "nowhere", 0)
    assert _graspable(arm, _static_obstacles(kitchen_cfg, robot_cfg), far, np.random.default_rng(0))
