"""The simulated arm's control and sensors for execution (`motion.executor.ArmExecutor`, PyBullet adapter).

What the robot can sense about itself in the simulator: joint states, finger contacts (what it holds), arm
contacts (what it hits); and how its joints are commanded: position control with velocity feed-forward, and a gear
constraint that keeps the two fingers symmetric. `world.Kitchen` exposes these as its executor methods. Grasp
success comes from contacts and friction only; nothing attaches the object to the hand.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from scone_bt.world.parts import BulletParts

__all__ = ["FINGER_COUPLING_FORCE", "PUSH_CHAIN", "ArmIO", "pushed_along"]

_POSITION_CONTROL = 2
"""pybullet.POSITION_CONTROL (a constant of its C API), named here so that a command does not import pybullet."""
FINGER_COUPLING_FORCE = 50.0
"""Largest force (N) of the coupling that keeps the two fingers symmetric (the gearing of a parallel gripper)."""


PUSH_CHAIN = 3
"""Products in a row the robot's push is followed through (`ArmIO.products_touched`)."""


def pushed_along(sources: Sequence[int], touching: Callable[[Sequence[int]], set[int]]) -> set[int]:
    """The product bodies a push from the bodies ``sources`` reaches, one product pushed into the next, up to
    `PUSH_CHAIN` deep; ``touching(bodies)`` is the product bodies in contact with any of ``bodies`` (both engines'
    `products_touched`)."""
    seen = set(sources)
    found: set[int] = set()
    for _ in range(PUSH_CHAIN):
        nxt = touching(sources) - seen
        if not nxt:
            break
        found |= nxt
        seen |= nxt
        sources = sorted(nxt)
    return found


class ArmIO:
    """Commands and sensors of one kitchen's arm (the joint and link indices are read once).

    Args:
        kitchen: The simulated kitchen whose robot this drives.
    """

    def __init__(self, kitchen: BulletParts) -> None:
        self.kitchen = kitchen
        self._products: tuple[tuple[str, int], ...] = ()
        self._product_names: dict[int, str] = {}  # body id → product name (`products_touched`)
        bc = kitchen.bc
        rid = kitchen.robot_id
        cfg = kitchen.robot_config
        self.arm_ids = [kitchen.joint_index[n] for n in cfg.arm_joints]
        self.finger_ids = [kitchen.joint_index[n] for n in cfg.gripper.joints]
        # Links at or below the last arm joint's child that are not on the arm chain: hand and fingers.
        last = self.arm_ids[-1]
        self.gripper_links = set(self.finger_ids)
        for j in range(bc.getNumJoints(rid)):
            if j > last and j not in self.arm_ids:
                self.gripper_links.add(j)
        self._coupling: int | None = None
        n = len(self.arm_ids)
        ctl = cfg.control
        self._forces = [ctl.max_joint_force] * n
        self._gains = [ctl.position_gain] * n
        self._zeros = [0.0] * n
        # The last (positions, velocities) sent: a motor keeps its target, so sending the same one again (the
        # executor holds a pose for many steps) changes nothing and is skipped. `forget_command` clears it.
        self._last: tuple[list[float], list[float]] | None = None

    # ------------------------------------------------------------------------------------------ commands
    def command_arm(self, q: np.ndarray, qd: np.ndarray | None = None) -> None:
        """Position control towards q with velocity feed-forward qd (zero when None)."""
        positions = np.asarray(q, dtype=float).tolist()
        velocities = self._zeros if qd is None else np.asarray(qd, dtype=float).tolist()
        if self._last is not None and self._last[0] == positions and self._last[1] == velocities:
            return
        k = self.kitchen
        k.bc.setJointMotorControlArray(
            k.robot_id,
            self.arm_ids,
            _POSITION_CONTROL,
            targetPositions=positions,
            targetVelocities=velocities,
            forces=self._forces,
            positionGains=self._gains,
        )
        self._last = (positions, velocities)

    def forget_command(self) -> None:
        """Send the next `command_arm` even if it repeats the last (the motors were set or restored otherwise)."""
        self._last = None

    def couple_fingers(self) -> int | None:
        """Couple the two fingers so that they move symmetrically, as a parallel gripper's gearing does; the id.

        Both grippers are parallel grippers whose fingers one drive moves together (the Franka Hand through a rack,
        the iiwa7's primitive gripper by design), but the URDFs give each finger its own joint: closed with equal
        forces, a held object and both fingers then slide sideways together under the carry's accelerations until
        a finger meets its limit, and a light object is shoved across while closing and released off-centre. A
        gear constraint (PyBullet's way to model that gearing) keeps the joints equal; it is made once and kept
        for the kitchen's life. None without exactly two fingers.
        """
        import pybullet as p

        bc, rid = self.kitchen.bc, self.kitchen.robot_id
        if self._coupling is not None:
            try:
                bc.getConstraintInfo(self._coupling)
                return self._coupling
            except Exception:  # noqa: BLE001 (pybullet raises a plain error for a removed constraint)
                pass
        if len(self.finger_ids) != 2:
            return None
        a, b = self.finger_ids
        cid = bc.createConstraint(
            rid, a, rid, b, p.JOINT_GEAR, [1.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]
        )
        # Both finger joints open with a positive position along mirrored axes: equal joint positions are symmetric.
        bc.changeConstraint(cid, gearRatio=-1.0, erp=0.1, maxForce=FINGER_COUPLING_FORCE)
        self._coupling = cid
        return cid

    # ------------------------------------------------------------------------------------------ sensors
    def held_body(self, min_force: float) -> int | None:
        """A body touched by every finger with at least min_force newtons, else None."""
        bc, rid = self.kitchen.bc, self.kitchen.robot_id
        common: set[int] | None = None
        for f in self.finger_ids:
            bodies = {
                c[2]
                for c in bc.getContactPoints(bodyA=rid, linkIndexA=f)
                if c[2] != rid and c[9] >= min_force
            }
            common = bodies if common is None else common & bodies
        return min(common) if common else None

    def finger_forces(self, held: str) -> tuple[float, float]:
        """(vertical load, grip) in newtons the fingers feel from ``held``: the upward force their contacts
        exert on it (what they carry of its weight) and the sum of their normal forces (how hard they squeeze).
        What a fingertip force sensor measures; (0, 0) when the fingers do not touch it."""
        k = self.kitchen
        body = k.objects.get(held)
        if body is None:
            return 0.0, 0.0
        load = grip = 0.0
        for f in self.finger_ids:
            for c in k.bc.getContactPoints(bodyA=k.robot_id, bodyB=body, linkIndexA=f):
                load += _upward(c)
                grip += c[9]
        return float(load), float(grip)

    def wrist_load(self) -> float:
        """The vertical force, in newtons, all the hand's contacts exert on what they touch (fingers, palm and
        the other hand links): what a wrist force/torque sensor reads, tared for the hand's own weight."""
        k = self.kitchen
        return float(
            sum(
                _upward(c)
                for c in k.bc.getContactPoints(bodyA=k.robot_id)
                if c[2] != k.robot_id and c[3] in self.gripper_links
            )
        )

    def pad_contacts(self, held: str) -> tuple[tuple[float, float, float] | None, ...]:
        """Where on each finger ``held`` touches it: the contacts' mean position weighted by their normal force,
        in that finger's own frame (metres; None where the finger does not touch it). What a tactile pad reads."""
        k = self.kitchen
        bc = k.bc
        body = k.objects.get(held)
        pads: list[tuple[float, float, float] | None] = []
        for f in self.finger_ids:
            contacts = [] if body is None else bc.getContactPoints(bodyA=k.robot_id, bodyB=body, linkIndexA=f)
            total = sum(c[9] for c in contacts)
            if total <= 0.0:
                pads.append(None)
                continue
            state = bc.getLinkState(k.robot_id, f)
            to_finger = bc.invertTransform(state[4], state[5])
            mean = np.zeros(3)
            for c in contacts:
                mean += c[9] * np.asarray(bc.multiplyTransforms(*to_finger, c[5], (0, 0, 0, 1))[0])
            x, y, z = (mean / total).tolist()
            pads.append((x, y, z))
        return tuple(pads)

    def held_object(self, min_force: float) -> str | None:
        """The name of `held_body`."""
        body = self.held_body(min_force)
        return None if body is None else self.body_name(body)

    def unexpected_contact(self, allow_gripper: bool, held: str | None, min_force: float) -> str | None:
        """'<link> hit <what>' for the first robot link pushing on something it should not touch, else None."""
        bc, rid = self.kitchen.bc, self.kitchen.robot_id
        for c in bc.getContactPoints(bodyA=rid):
            body, link, force = c[2], c[3], c[9]
            if body == rid or link < 0 or force < min_force:
                continue
            if link in self.gripper_links and (
                allow_gripper or (held is not None and self.body_name(body) == held)
            ):
                continue
            return f"{bc.getJointInfo(rid, link)[12].decode()} hit {self.body_name(body)}"
        return None

    def products_touched(self, held: str | None) -> frozenset[str]:
        """Products (not ``held``) the robot pushes on: in contact with a robot link or the held product ``held``,
        or with such a product (one product pushed into the next, up to `PUSH_CHAIN` deep)."""
        k = self.kitchen
        bc = k.bc
        products = tuple(k.objects.items())
        # Keyed by names and ids: a restocked kitchen hands its new products the old ids (`clear_products`), and a
        # map keyed by ids alone named the last execution's products (the generator then asked the kitchen about
        # a product it no longer held: UnknownNameError).
        if products != self._products:  # products spawned (or restocked) since: the body → name map anew
            self._products = products
            self._product_names = {b: n for n, b in products}
        names = self._product_names
        held_body = None if held is None else k.objects.get(held)
        sources = [k.robot_id] if held_body is None else [k.robot_id, held_body]

        def touching(bodies: Sequence[int]) -> set[int]:
            return {c[2] for src in bodies for c in bc.getContactPoints(bodyA=src) if c[2] in names}

        return frozenset(names[b] for b in pushed_along(sources, touching))

    def body_name(self, body: int) -> str:
        """A product's or a static box's name, 'the floor', or 'body <id>' (names are unique per body)."""
        k = self.kitchen
        for name, bid in (*k.objects.items(), *k.static_body_ids.items()):
            if bid == body:
                return name
        return "the floor" if body == k.floor_id else f"body {body}"


def _upward(c: Sequence[Any]) -> float:
    """The vertical force a PyBullet contact point (robot link A, other body B) exerts on B, newtons."""
    # the contact normal points from B to A: the force on B along it is −normal·n; friction acts on B along its
    # directions with the reported signs reversed (PyBullet reports them on A)
    normal, f1, d1, f2, d2 = c[9], c[10], c[11], c[12], c[13]
    return float(-(normal * c[7][2]) - (f1 * d1[2] + f2 * d2[2]))
