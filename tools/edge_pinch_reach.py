"""Can the arm pinch a flat pack by its front edge once the pack sticks out over its tier? Kinematics only.

A product wider than the gripper on both sides (a meat tray, a pack of bacon) cannot be gripped from above or from
the side: 187 of the 1,100 development executions (tools/data/sc_probe) are such products, and none succeeds. A
skill for the flat ones would slide the pack towards the robot until its front edge sticks out over the tier's
edge by ``d``, then pinch that edge with the fingers closing vertically (one above the pack, one under it), the hand
approaching horizontally. This checks the second half only, with the robot's own IK and collision model
(`motion.model`, `motion.collision`): for every slot of every tier of every shelf unit in perception/kitchen.yaml,
and each pack size and overhang, whether some pinch pose (approach yawed up to 60° from the tier's outward
direction, either wrist sense) has an IK solution that collides with nothing fixed, and a pregrasp 6 cm back along
the approach that collides with neither the scene nor the pack. Neighbours on the shelf are not modelled, nor is
the slide, nor any physics: a pose found here is necessary, not sufficient.

One JSON line per (shelf unit, tier, pack, overhang): ``reachable`` slots of ``slots``.

    PYTHONPATH=$PWD python tools/edge_pinch_reach.py
"""

from __future__ import annotations

import itertools
import json

import numpy as np

PACKS = {
    "meat tray": (0.14, 0.20, 0.045),
    "bacon": (0.12, 0.25, 0.01),
    "croissants": (0.12, 0.20, 0.07),
}
"""Catalogue sizes (along the tier's depth, along the tier, height; metres) of the commonest flat wide packs."""
OVERHANGS_M = (0.035, 0.045, 0.055)
PAD_INSET_M = 0.012
"""The finger pads' centre inside the pack's front edge, metres."""
PREGRASP_M = 0.06
YAWS_DEG = (0, 20, -20, 40, -40, 60, -60)


class PinchCheck:
    """The scene's fixed boxes and the arm, loaded once; `reachable` checks one pinch (module docstring)."""

    def __init__(self, kitchen_file: str = "perception/kitchen.yaml", robot_name: str = "panda") -> None:
        from scone_bt.config import load_kitchen
        from scone_bt.config.robot import load_robot
        from scone_bt.motion.collision import CollisionWorld, fixed_obstacles
        from scone_bt.motion.model import ArmModel
        from scone_bt.world.scene_boxes import static_boxes

        self.kitchen = load_kitchen(kitchen_file)
        self.robot = load_robot(robot_name)
        self.arm = ArmModel(self.robot)
        self.static = list(fixed_obstacles(static_boxes(self.kitchen), self.kitchen.scene.floor_z))
        self.open_m = self.robot.gripper.open_position
        self.world = CollisionWorld(self.arm, self.static, finger_position=self.open_m)
        self.home = np.asarray(self.robot.home, dtype=float)
        self.rng = np.random.default_rng(0)

    def reachable(
        self, unit_name: str, tier_index: int, v: float, size: tuple[float, float, float], d: float
    ) -> bool:
        """Whether a pack of ``size`` (metres: along the tier's depth, along the tier, height) at ``v`` along
        tier ``tier_index`` of ``unit_name``, its front edge ``d`` metres past the tier's, can be pinched."""
        from scone_bt.motion.collision import CollisionWorld, Obstacle
        from scone_bt.motion.model import IKOptions, pose_matrix

        unit = next(u for u in self.kitchen.scene.shelves if u.name == unit_name)
        tier = unit.tiers[tier_index]
        du, dv, h = size
        front_u = tier.center - unit.tier_depth / 2
        x, y = unit.to_world(front_u - d + PAD_INSET_M, v)
        point = np.array([x, y, tier.top_z + h / 2])
        outward = np.subtract(unit.to_world(front_u + 1.0, v), unit.to_world(front_u, v))
        turn = np.deg2rad(unit.rotation_deg)
        along = np.array(
            [[np.cos(turn), -np.sin(turn), 0.0], [np.sin(turn), np.cos(turn), 0.0], [0.0, 0.0, 1.0]]
        )
        px, py = unit.to_world(front_u - d + du / 2, v)
        pack = Obstacle("pack", "box", (du, dv, h), pose_matrix(along, (px, py, tier.top_z + h / 2)))
        with_pack = CollisionWorld(self.arm, [*self.static, pack], finger_position=self.open_m)
        for yaw, sense in itertools.product(np.deg2rad(YAWS_DEG), (1.0, -1.0)):
            c, s = np.cos(yaw), np.sin(yaw)
            z = np.array([c * outward[0] - s * outward[1], s * outward[0] + c * outward[1], 0.0])
            closing = np.array([0.0, 0.0, sense])
            rotation = np.column_stack([np.cross(closing, z), closing, z])
            grasp = self.arm.ik(pose_matrix(rotation, point), self.home, self.rng, IKOptions(restarts=8))
            if grasp is None or not self.world.is_valid(grasp.q):
                continue
            back = pose_matrix(rotation, point - PREGRASP_M * z)
            pre = self.arm.ik(back, grasp.q, self.rng, IKOptions(restarts=0))
            if pre is not None and with_pack.is_valid(pre.q):
                return True
        return False


def main() -> None:
    check = PinchCheck()
    for unit in check.kitchen.scene.shelves:
        for t, tier in enumerate(unit.tiers):
            for name, size in PACKS.items():
                for d in OVERHANGS_M:
                    found = [check.reachable(unit.name, t, v, size, d) for v in tier.slots]
                    line = {"unit": unit.name, "tier": t, "pack": name, "overhang_m": d}
                    print(json.dumps({**line, "reachable": sum(found), "slots": len(found)}), flush=True)


if __name__ == "__main__":
    main()
