"""Slide a flat pack wider than the gripper to the edge of its tier, pinch the edge that sticks out, lift it: does the
physics allow it? One product at a time, on either engine.

A product wider than the gripper on both sides cannot be gripped from above or from the side (187 of the 1,100
development executions, none succeeds). For a flat one on a lowest tier a person slides it towards themselves with
a fingertip and picks it up by the edge that then sticks out. `tools/edge_pinch_reach.py` shows the arm reaches such
a pinch on every lowest-tier slot and none on a higher tier (the hand would cut into the tier in front). This checks
the physics of the whole sequence on the lowest tier of the front unit, the pack alone on it, with the nominal
robot's gripper:

1. **slide**: fingers closed, the hand pointing down, its fingertips pressed ``--press`` metres into the pack's top
   ``FAR_INSET_M`` inside its far edge, then moved ``--slide`` metres towards the robot, then lifted away;
2. **pinch**: the hand horizontal, the fingers closing vertically, open around the strip that sticks out
   (``PAD_INSET_M`` inside the pack's front edge), closed;
3. **lift**: up 10 cm and back 10 cm, then held for a second.

The arm follows straight lines in joint space between IK poses (with a waypoint high above the tier between the
slide and the pinch), not the planner's paths, and the pinch is placed from the simulator's pose of the pack after
the slide: a robot would look again. So a success here is necessary, not sufficient, for a skill.

One JSON line per (engine, product): the gripper (newtons per finger, the pads' friction; ``--gripper`` sets a
proficiency profile's), how far the slide moved the pack towards the robot (``slid_m``), whether it stayed on its
tier, and whether the fingers held it after the lift (``held``, its centre raised ≥ 8 cm); a last line per engine
counts them.

    PYTHONPATH=$PWD python tools/slide_and_pinch_check.py --engines pybullet,mujoco
    PYTHONPATH=$PWD python tools/slide_and_pinch_check.py --engines pybullet --gripper 25,0.25   # p02's fingers
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import time

import numpy as np

FAR_INSET_M = 0.03
"""The fingertips press this far inside the pack's far edge, metres."""
PAD_INSET_M = 0.012
"""The finger pads' centre this far inside the pack's front edge, metres."""
SLOT_V = 0.40
"""Where along the front unit's lowest tier the pack stands, metres."""


def flat_and_wide(spec, opening_m: float) -> bool:
    """A box wider than ``opening_m`` both ways and at most 7 cm tall: a flat pack no grasp fits
    (`config.grasp.flat_pack`, the rule the robot's skill takes such a pack by)."""
    from scone_bt.config.grasp import flat_pack

    sx, sy, sz = spec.size
    return spec.shape.value == "box" and flat_pack(min(sx, sy), sz, opening_m)


class Run:
    """One pack on one engine: the kitchen, the arm's IK and joint-space moves."""

    def __init__(
        self, engine: str, spec, press_m: float, slide_m: float, gripper: tuple[float, float] | None = None
    ) -> None:
        from scone_bt.config import load_kitchen
        from scone_bt.config.robot import load_robot
        from scone_bt.motion.model import ArmModel
        from scone_bt.stocking.place import Placement

        self.kc = load_kitchen("perception/kitchen.yaml")
        self.rc = load_robot("panda")
        if gripper is not None:  # a proficiency profile's (N per finger, the pads' friction)
            force, friction = gripper
            self.rc = dataclasses.replace(
                self.rc,
                gripper=dataclasses.replace(self.rc.gripper, max_force=force, finger_friction=friction),
            )
        self.arm = ArmModel(self.rc)
        if engine == "mujoco":
            from scone_bt.world.mj_kitchen import MjKitchen

            self.k = MjKitchen(self.kc, self.rc)
        else:
            from scone_bt.world.kitchen import Kitchen

            self.k = Kitchen(self.kc, self.rc)
        self.spec, self.press_m, self.slide_m = spec, press_m, slide_m
        self.unit = self.kc.scene.shelves[0]
        self.tier = self.unit.tiers[0]
        sx, sy, self.height = spec.size
        # the stocking turns a pack deeper than its tier: its short side across the tier
        self.du = min(sx, sy)
        x, y = self.unit.to_world(self.tier.center, SLOT_V)
        yaw = np.pi / 2 if sx > sy else 0.0
        self.k.spawn_planned([spec], [Placement(spec.name, (x, y, self.tier.top_z), yaw, self.unit.name, 0)])
        self.k.couple_fingers()
        self.q = np.asarray(self.rc.home, dtype=float)
        self.rng = np.random.default_rng(0)
        self.k.hold_arm(self.q)
        self.k.advance(0.5)

    def u_of(self, position) -> float:
        """The position's coordinate across the tier (away from the robot), metres."""
        u, _ = self.unit.to_unit(float(position[0]), float(position[1]))
        return float(u)

    def position(self) -> np.ndarray:
        return np.array(self.k.object_state(self.spec.name).position)

    def move_to(self, rotation: np.ndarray, u: float, z: float, seconds: float) -> bool:
        """Straight in joint space to the IK pose at (u, SLOT_V, z) in the unit's frame; False if IK fails."""
        from scone_bt.motion.model import IKOptions, pose_matrix

        x, y = self.unit.to_world(u, SLOT_V)
        sol = self.arm.ik(pose_matrix(rotation, (x, y, z)), self.q, self.rng, IKOptions(restarts=4))
        if sol is None:
            return False
        q0, steps = self.q.copy(), max(2, round(seconds * 40))
        for s in np.linspace(0.0, 1.0, steps)[1:]:
            self.k.hold_arm(q0 + s * (sol.q - q0))
            self.k.advance(seconds / steps)
        self.q = sol.q
        self.k.advance(0.2)
        return True

    def run(self) -> dict:
        from scone_bt.motion.grasp import top_down_rotation

        k, g = self.k, self.rc.gripper
        start = self.position()
        top = self.tier.top_z + self.height
        down = top_down_rotation(0.0)
        far = self.u_of(start) + self.du / 2 - FAR_INSET_M
        k.set_gripper_target(g.closed_position)
        k.advance(0.5)
        ok = (
            self.move_to(down, far, top + 0.05, 2.0)
            and self.move_to(down, far, top - self.press_m, 1.0)
            and self.move_to(down, far - self.slide_m, top - self.press_m, 2.0)
            and self.move_to(down, far - self.slide_m, top + 0.05, 1.0)
        )
        k.advance(0.5)
        after = self.position()
        slid = self.u_of(start) - self.u_of(after)
        on_tier = abs(after[2] - start[2]) < 0.01
        front = self.u_of(after) - self.du / 2
        outward = np.subtract(self.unit.to_world(1.0, SLOT_V), self.unit.to_world(0.0, SLOT_V))
        z_axis = np.array([outward[0], outward[1], 0.0]) / np.linalg.norm(outward)
        closing = np.array([0.0, 0.0, 1.0])
        pinch = np.column_stack([np.cross(closing, z_axis), closing, z_axis])
        middle = self.tier.top_z + self.height / 2
        grip_u = front + PAD_INSET_M
        held = False
        if ok and on_tier:
            k.set_gripper_target(g.open_position)
            k.advance(0.5)
            ok = (
                self.move_to(down, grip_u - 0.15, middle + 0.25, 2.0)
                and self.move_to(pinch, grip_u - 0.12, middle + 0.15, 2.0)
                and self.move_to(pinch, grip_u - 0.08, middle, 2.0)
                and self.move_to(pinch, grip_u, middle, 1.0)
            )
            if ok:
                k.set_gripper_target(g.closed_position)
                k.advance(1.0)
                ok = self.move_to(pinch, grip_u, middle + 0.01, 0.5) and self.move_to(
                    pinch, grip_u - 0.10, middle + 0.10, 1.5
                )
                k.advance(1.0)
                held = ok and k.held_object(1.0) == self.spec.name and self.position()[2] - start[2] >= 0.08
        return {
            "product": self.spec.name,
            "size_m": list(self.spec.size),
            "mass_kg": self.spec.mass,
            "slid_m": round(slid, 4),
            "overhang_m": round(self.tier.center - self.unit.tier_depth / 2 - front, 4),
            "on_tier": bool(on_tier),
            "held": bool(held),
            "reached": bool(ok),
        }


def main() -> None:
    from scone_bt.config import load_kitchen
    from scone_bt.config.grasp import DEFAULT_OPENING_M

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--engines", default="pybullet,mujoco")
    ap.add_argument(
        "--press", type=float, default=0.004, help="metres the fingertips press into the pack's top"
    )
    ap.add_argument("--slide", type=float, default=0.045, help="metres the pack is slid towards the robot")
    ap.add_argument("--products", default="", help="comma-separated names (default: every flat wide pack)")
    ap.add_argument(
        "--gripper",
        default="",
        help="FORCE,FRICTION: newtons per finger and the pads' friction (a profile's; default: the robot file's)",
    )
    a = ap.parse_args()
    gripper = tuple(float(x) for x in a.gripper.split(",")) if a.gripper else None
    os.environ.setdefault("MUJOCO_GL", "egl")
    catalogue = load_kitchen("perception/kitchen.yaml").catalogue
    names = [n for n in a.products.split(",") if n] or [
        s.name for s in catalogue.objects if flat_and_wide(s, DEFAULT_OPENING_M)
    ]
    for engine in a.engines.split(","):
        t0, held, n = time.time(), 0, 0
        for name in names:
            run = Run(engine, catalogue.get(name), a.press, a.slide, gripper)  # type: ignore[arg-type]
            line = {"engine": engine, "gripper": [run.rc.gripper.max_force, run.rc.gripper.finger_friction]}
            try:
                line.update(run.run())
            finally:
                run.k.close()  # one kitchen a product: an engine's client holds its memory until closed
            held += line["held"]
            n += 1
            print(json.dumps(line), flush=True)
        summary = {"engine": engine, "gripper": list(gripper) if gripper else "robot file", "products": n}
        print(json.dumps({**summary, "held": held, "wall_s": round(time.time() - t0, 1)}), flush=True)


if __name__ == "__main__":
    main()
