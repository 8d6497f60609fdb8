"""A MuJoCo kitchen: the same robot, shelves, table, cameras and products as `world.Kitchen`, on MuJoCo.

`MjKitchen` offers what the motion system (`motion.executor.Workcell`), the cameras (`perception.images.ImageSource`),
a recording (`viz.scene.SceneView`) and the test rig (`robot.rig.SimWorld`) use of a kitchen, with the same names and
meanings as the PyBullet `Kitchen`, so none of them changes. The arm follows its joint targets through MuJoCo
position actuators with gravity compensation; grasps hold by contact friction only; outcomes are read from MuJoCo's
contacts. Products are compiled into the model when the shelf is stocked (one compile per stocking); covers are
mocap boxes the model keeps ready.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from scone_bt.config import KitchenConfig, ObjectSpec, RobotConfig
from scone_bt.errors import ConfigError
from scone_bt.perception.images import CameraImage, PinholeView
from scone_bt.stocking import Placement
from scone_bt.world.ground_truth import GroundTruth, ObjectState
from scone_bt.world.mj_model import (
    ARM_GAINS,
    COVER_SLOTS,
    PAD_TORSION_M,
    PARK_Z_M,
    StaticBox,
    build_model,
    import_mujoco,
)
from scone_bt.world.sim_clock import REST_ANGULAR_RAD_S, REST_JOINT_RAD_S, REST_LINEAR_M_S, SimClock

if TYPE_CHECKING:
    from scone_bt.world.mj_camera import MjCameras

__all__ = ["MjKitchen"]

Controller = Callable[["MjKitchen"], None]
"""Called before every control step, e.g. to send joint targets."""

_KITCHEN_IDS = itertools.count()


class MjKitchen(GroundTruth, SimClock):
    """The simulated world on MuJoCo. Create with `MjKitchen(kitchen_cfg, robot_cfg)`; stock it with `spawn`.

    Args:
        kitchen: Scene, cameras and catalogue.
        robot: The arm to load.
        time_step: Control step in seconds (default: the robot file's, 1 / control.physics_hz).
    """

    def __init__(self, kitchen: KitchenConfig, robot: RobotConfig, *, time_step: float | None = None) -> None:
        self.mujoco = import_mujoco()
        self.config = kitchen
        self.robot_config = robot
        self.time_step = float(time_step or 1.0 / robot.control.physics_hz)
        self.sim_time = 0.0
        self.steps = 0
        self.steps_skipped = 0
        self.state_version = 0
        self.uid = next(_KITCHEN_IDS)
        self.model_version = 0
        self.objects: dict[str, int] = {}
        self.specs: dict[str, ObjectSpec] = {}
        self.spawn_slots: dict[str, tuple[float, float, float]] = {}
        self._controllers: list[Controller] = []
        self._awake_until = 0.0
        self._covers: dict[int, int] = {}  # handle → cover slot
        self._cover_ids = itertools.count()
        self._cameras: MjCameras | None = None
        self._build(())
        self.hold_arm(robot.home)
        self.set_gripper_target(robot.gripper.open_position)

    # ----------------------------------------------------------------------------------------- model
    def _build(self, products: Sequence[ObjectSpec]) -> None:
        """Compile the kitchen with ``products`` and carry the arm's state over (its joints, targets, the clock)."""
        mj = self.mujoco
        old = getattr(self, "data", None)
        old_index = getattr(self, "_qpos_of", None)
        model, parts = build_model(self.config, self.robot_config, products, self.time_step)
        data = mj.MjData(model)
        self.model, self.data, self.parts = model, data, parts
        self.substeps = max(1, round(self.time_step / model.opt.timestep))
        cfg = self.robot_config
        joint = {n: model.joint(n).id for n in (*cfg.arm_joints, *cfg.gripper.joints)}
        self._qpos_of = {n: int(model.jnt_qposadr[j]) for n, j in joint.items()}
        self._dof_of = {n: int(model.jnt_dofadr[j]) for n, j in joint.items()}
        self.arm_qpos = np.array([self._qpos_of[n] for n in cfg.arm_joints])
        self.arm_dof = np.array([self._dof_of[n] for n in cfg.arm_joints])
        self.finger_qpos = np.array([self._qpos_of[n] for n in cfg.gripper.joints])
        self.finger_dof = np.array([self._dof_of[n] for n in cfg.gripper.joints])
        self.arm_act = np.array([model.actuator(n).id for n in cfg.arm_joints])
        self.finger_act = np.array([model.actuator(n).id for n in cfg.gripper.joints])
        self._feed_forward = ARM_GAINS.damping / ARM_GAINS.stiffness
        # The robot's bodies: the URDF's (every body before the first scene body), the base first.
        root = int(model.body_parentid[model.jnt_bodyid[joint[cfg.arm_joints[0]]]])
        robot_bodies = [b for b in range(1, model.nbody) if _is_descendant(model, b, root)]
        self.robot_root = int(root)
        self.robot_bodies = frozenset(robot_bodies)
        finger_bodies = {int(model.jnt_bodyid[joint[n]]) for n in cfg.gripper.joints}
        self.finger_bodies = tuple(sorted(finger_bodies))
        last_arm_body = int(model.jnt_bodyid[joint[cfg.arm_joints[-1]]])
        self.gripper_bodies = frozenset(
            b for b in robot_bodies if b != last_arm_body and _is_descendant(model, b, last_arm_body)
        )
        self.static_boxes: list[StaticBox] = list(parts.boxes)
        self._names: dict[int, str] = {}  # body id → product name
        self.objects = {}
        for name in parts.products:
            body = model.body(name).id
            self.objects[name] = body
            self._names[body] = name
        self._static_geom_names = {model.geom(b.name).id: b.name for b in parts.boxes} | {
            model.geom("floor").id: "the floor"
        }
        self._free_qpos = {n: int(model.jnt_qposadr[model.body_jntadr[b]]) for n, b in self.objects.items()}
        self._free_dof = {n: int(model.jnt_dofadr[model.body_jntadr[b]]) for n, b in self.objects.items()}
        self._cover_mocap = [int(model.body_mocapid[model.body(f"cover{i}").id]) for i in range(COVER_SLOTS)]
        self._cover_geom = [model.geom(f"cover{i}").id for i in range(COVER_SLOTS)]
        if old is not None and old_index is not None:
            for n, adr in old_index.items():
                data.qpos[self._qpos_of[n]] = old.qpos[adr]
            data.ctrl[self.arm_act] = old.ctrl[self.arm_act]
            data.ctrl[self.finger_act] = old.ctrl[self.finger_act]
            data.time = old.time
        else:
            for n, q in zip(cfg.arm_joints, cfg.home, strict=True):
                data.qpos[self._qpos_of[n]] = q
            data.qpos[self.finger_qpos] = cfg.gripper.open_position
        self.set_gripper_properties()
        self.model_version += 1
        if self._cameras is not None:  # bound to the old model: its renderers go with it
            self._cameras.close()
        self._cameras = None
        self._covers.clear()
        self.uid = next(_KITCHEN_IDS)
        self.mujoco.mj_forward(model, data)

    # ----------------------------------------------------------------------------------------- objects
    def spawn_planned(
        self, specs: Sequence[ObjectSpec], places: Sequence[Placement]
    ) -> dict[str, tuple[float, float, float]]:
        """Put ``specs`` where a stocking plan says and let them settle (one model compile for all of them).

        Returns:
            name → surface point under the object's centre (x, y, z), metres.
        """
        self._refuse_present(specs)
        kept = {n: self.object_state(n) for n in self.objects}
        self._build([*self.specs.values(), *specs])
        for name, st in kept.items():
            self._set_pose(name, st.position, st.orientation)
        for spec, place in zip(specs, places, strict=True):
            x, y, z = place.position
            self.specs[spec.name] = spec
            self.spawn_slots[spec.name] = (x, y, z)
            half = place.yaw / 2
            self._set_pose(
                spec.name, (x, y, z + spec.height / 2 + 1e-3), (0, 0, math.sin(half), math.cos(half))
            )
        self.mujoco.mj_forward(self.model, self.data)
        self.wake()
        self.advance(0.5)
        return dict(self.spawn_slots)

    def _set_pose(self, name: str, position: Sequence[float], orientation: Sequence[float]) -> None:
        """Put a product's free body at a pose (quaternion x, y, z, w) at rest."""
        a, v = self._free_qpos[name], self._free_dof[name]
        x, y, z, w = orientation
        self.data.qpos[a : a + 7] = [*position, w, x, y, z]
        self.data.qvel[v : v + 6] = 0.0

    def object_state(self, name: str) -> ObjectState:
        body = self._body(name)
        w, x, y, z = (float(c) for c in self.data.xquat[body])
        return ObjectState(name, body, tuple(float(c) for c in self.data.xpos[body]), (x, y, z, w))  # type: ignore[arg-type]

    def ray_bodies(self, start: Sequence[float] | np.ndarray, ends: np.ndarray) -> list[int]:
        """The body id each ray from ``start`` to a row of ``ends`` (n, 3) hits first, -1 where none (metres).

        Every geom counts, the products' looks and covers included (a cover hides what is behind it)."""
        mj, m, d = self.mujoco, self.model, self.data
        origin = np.asarray(start, dtype=float)
        hit = np.zeros(1, dtype=np.int32)
        out = []
        for end in np.asarray(ends, dtype=float):
            vec = end - origin
            distance = mj.mj_ray(m, d, origin, vec, None, 1, -1, hit)
            # mj_ray measures in units of vec: a hit beyond the end point (1) is not on the way there.
            out.append(int(m.geom_bodyid[hit[0]]) if distance >= 0 and distance <= 1.0 + 1e-9 else -1)
        return out

    def place_object(self, name: str, surface: Sequence[float], yaw: float = 0.0) -> None:
        """Stand the product upright on ``surface`` (x, y, z under its centre, metres), turned by ``yaw``, at rest."""
        self._body(name)
        x, y, z = (float(v) for v in surface)
        half = float(yaw) / 2
        self._set_pose(
            name, (x, y, z + self.specs[name].height / 2 + 1e-3), (0, 0, math.sin(half), math.cos(half))
        )
        self.mujoco.mj_forward(self.model, self.data)
        self.wake()

    def touches_robot(self, name: str) -> bool:
        """True if the object touches the robot (in or against the gripper: a person does not grab it away)."""
        body = self._body(name)
        for a, b, _ in self._contacts():
            if (a == body and b in self.robot_bodies) or (b == body and a in self.robot_bodies):
                return True
        return False

    # ----------------------------------------------------------------------------------------- covers
    def add_cover(
        self,
        center: Sequence[float],
        size: Sequence[float],
        rgba: Sequence[float] = (0.2, 0.2, 0.2, 1.0),
        orientation: Sequence[float] = (0.0, 0.0, 0.0, 1.0),
    ) -> int:
        """An opaque box the cameras see but nothing collides with; ``orientation`` a quaternion (x, y, z, w).

        Returns:
            Its handle for `remove_cover`.
        """
        used = set(self._covers.values())
        free = [i for i in range(COVER_SLOTS) if i not in used]
        if not free:
            raise ConfigError(f"at most {COVER_SLOTS} covers at a time in the MuJoCo kitchen")
        slot = free[0]
        geom = self._cover_geom[slot]
        half = [float(s) / 2 for s in size]
        self.model.geom_size[geom] = half
        self.model.geom_rbound[geom] = float(np.linalg.norm(half))
        self.model.geom_rgba[geom] = [float(c) for c in rgba]
        x, y, z, w = (float(c) for c in orientation)
        self.data.mocap_pos[self._cover_mocap[slot]] = [float(c) for c in center]
        self.data.mocap_quat[self._cover_mocap[slot]] = [w, x, y, z]
        self.mujoco.mj_forward(self.model, self.data)
        handle = next(self._cover_ids)
        self._covers[handle] = slot
        self._scene_changed()
        return handle

    def remove_cover(self, handle: int) -> None:
        """Take away a cover `add_cover` made."""
        slot = self._covers.pop(handle, None)
        if slot is None:
            return
        self.data.mocap_pos[self._cover_mocap[slot]] = [0.0, 0.0, PARK_Z_M - slot]
        self.mujoco.mj_forward(self.model, self.data)
        self._scene_changed()

    def _scene_changed(self) -> None:
        self.uid = next(_KITCHEN_IDS)
        self.state_version += 1

    def set_gripper_properties(
        self, max_force: float | None = None, finger_friction: float | None = None
    ) -> None:
        """Change the gripper's force limit (N per finger) and the finger pads' friction from now on."""
        g = self._replace_gripper(max_force, finger_friction)
        m = self.model
        for act in self.finger_act:
            m.actuator_forcerange[act] = [-g.max_force, g.max_force]
        for p in range(m.npair):
            product = self._names.get(int(m.geom_bodyid[m.pair_geom2[p]]))
            if product is not None:
                mu = self.specs[product].friction * g.finger_friction if product in self.specs else None
                if mu is not None:
                    m.pair_friction[p, :3] = [mu, mu, mu * PAD_TORSION_M]
        self._keep_stepping()

    # ----------------------------------------------------------------------------------------- robot
    def arm_joint_positions(self) -> np.ndarray:
        return self.data.qpos[self.arm_qpos].copy()

    def arm_joint_velocities(self) -> np.ndarray:
        return self.data.qvel[self.arm_dof].copy()

    def gripper_positions(self) -> np.ndarray:
        return self.data.qpos[self.finger_qpos].copy()

    def hold_arm(self, q: Sequence[float]) -> None:
        """Command arm joint position targets (zero velocity feed-forward)."""
        self.command_arm(np.asarray(q, dtype=float))
        self._keep_stepping()

    def command_arm(self, q: np.ndarray, qd: np.ndarray | None = None) -> None:
        """Position control towards q with velocity feed-forward qd (zero when None).

        The servo pushes kp (q - q_now) + kd (qd - qd_now): the affine actuator's target is q + kd / kp qd.
        """
        target = np.asarray(q, dtype=float)
        if qd is not None:
            target = target + self._feed_forward * np.asarray(qd, dtype=float)
        self.data.ctrl[self.arm_act] = target

    def set_gripper_target(self, position: float, force: float | None = None) -> None:
        g = self.robot_config.gripper
        f = g.max_force if force is None else float(force)
        for act in self.finger_act:
            self.model.actuator_forcerange[act] = [-f, f]
        self.data.ctrl[self.finger_act] = float(position)
        self._keep_stepping()

    def couple_fingers(self) -> None:
        """The fingers are coupled by the model's joint equality (made with the model): nothing to do."""

    # ----------------------------------------------------------------------------------------- contacts
    def _contacts(self) -> list[tuple[int, int, float]]:
        """(body a, body b, normal force N) of every active contact now."""
        return [(a, b, f) for _, _, a, b, f in self._contact_geoms()]

    def _contact_geoms(self) -> list[tuple[int, int, int, int, float]]:
        """(geom a, geom b, body a, body b, normal force N) of every active contact now."""
        d, m = self.data, self.model
        n = d.ncon
        if not n:
            return []
        geoms = d.contact.geom[:n]
        addr = d.contact.efc_address[:n]
        forces = np.where(addr >= 0, d.efc_force[np.maximum(addr, 0)], 0.0)
        bodies = m.geom_bodyid[geoms]
        return [
            (int(ga), int(gb), int(ba), int(bb), float(f))
            for (ga, gb), (ba, bb), f in zip(geoms, bodies, forces, strict=True)
        ]

    def held_object(self, min_force: float) -> str | None:
        """What every finger touches with at least min_force newtons, by name, else None."""
        touching: dict[int, set[int]] = {f: set() for f in self.finger_bodies}
        for a, b, force in self._contacts():
            if force < min_force:
                continue
            if a in touching and b in self._names:
                touching[a].add(b)
            elif b in touching and a in self._names:
                touching[b].add(a)
        common = set.intersection(*touching.values()) if touching else set()
        return self._names[min(common)] if common else None

    def finger_forces(self, held: str) -> tuple[float, float]:
        """(vertical load, grip) in newtons the fingers feel from ``held`` (`motion.probe.ForceSensing`, as
        `world.arm_io.ArmIO.finger_forces`): the upward force their contacts exert on it and the sum of their normal
        forces; (0, 0) when they do not touch it."""
        body = self.objects.get(held)
        if body is None:
            return 0.0, 0.0
        fingers = set(self.finger_bodies)
        load = grip = 0.0
        for link, other, up, normal, _at in self._hand_contacts():
            if link in fingers and other == body:
                load += up
                grip += normal
        return load, grip

    def wrist_load(self) -> float:
        """The vertical force, in newtons, all the hand's contacts exert on what they touch (a wrist force/torque
        sensor's reading; `motion.probe.ForceSensing`, as `world.arm_io.ArmIO.wrist_load`)."""
        return float(sum(up for _link, _other, up, _normal, _at in self._hand_contacts()))

    def _hand_contacts(self) -> list[tuple[int, int, float, float, np.ndarray]]:
        """(hand body, other body, upward force on the other, normal force, world position) of every contact of
        the hand with something not the robot."""
        m, d = self.model, self.data
        wrench = np.zeros(6)
        out = []
        for i in range(d.ncon):
            c = d.contact[i]
            a, b = int(m.geom_bodyid[c.geom1]), int(m.geom_bodyid[c.geom2])
            # MuJoCo's contact force acts on geom2's body as given (in the contact frame), on geom1's reversed
            if a in self.gripper_bodies and b not in self.robot_bodies:
                sign, link, other = 1.0, a, b
            elif b in self.gripper_bodies and a not in self.robot_bodies:
                sign, link, other = -1.0, b, a
            else:
                continue
            self.mujoco.mj_contactForce(m, d, i, wrench)
            world = np.asarray(c.frame).reshape(3, 3).T @ wrench[:3]
            out.append((link, other, sign * float(world[2]), float(wrench[0]), np.asarray(c.pos)))
        return out

    def pad_contacts(self, held: str) -> tuple[tuple[float, float, float] | None, ...]:
        """Where ``held`` touches each finger (`motion.probe.ForceSensing`, as `world.arm_io.ArmIO.pad_contacts`):
        the contacts' mean position weighted by their normal force, in the finger's frame (metres; None where the
        finger does not touch it)."""
        body = self.objects.get(held)
        d = self.data
        sums = {f: (np.zeros(3), 0.0) for f in self.finger_bodies}
        for link, other, _up, normal, at in self._hand_contacts() if body is not None else []:
            if link in sums and other == body:
                where, total = sums[link]
                sums[link] = (where + normal * at, total + normal)
        pads: list[tuple[float, float, float] | None] = []
        for f in self.finger_bodies:
            where, total = sums[f]
            if total <= 0.0:
                pads.append(None)
                continue
            local = d.xmat[f].reshape(3, 3).T @ (where / total - d.xpos[f])
            x, y, z = local.tolist()
            pads.append((x, y, z))
        return tuple(pads)

    def _what(self, geom: int, body: int) -> str:
        if body in self._names:
            return self._names[body]
        return self._static_geom_names.get(geom, f"body {body}")

    def unexpected_contact(self, allow_gripper: bool, held: str | None, min_force: float) -> str | None:
        """'<link> hit <what>' for the first robot link pushing on something it should not touch, else None."""
        robot = self.robot_bodies
        for ga, gb, ba, bb, force in self._contact_geoms():
            if force < min_force:
                continue
            if ba in robot and bb not in robot:
                link, other, other_geom = ba, bb, gb
            elif bb in robot and ba not in robot:
                link, other, other_geom = bb, ba, ga
            else:
                continue
            if link == self.robot_root:
                continue  # the base stands on its pedestal
            if link in self.gripper_bodies and (
                allow_gripper or (held is not None and self._names.get(other) == held)
            ):
                continue
            return f"{self.model.body(link).name} hit {self._what(other_geom, other)}"
        return None

    def products_touched(self, held: str | None) -> frozenset[str]:
        """Products (not ``held``) the robot pushes on, or pushes into the next (three deep, as `world.arm_io`)."""
        from scone_bt.world.arm_io import pushed_along

        pairs = self._contacts()
        products = self._names
        held_body = None if held is None else self.objects.get(held)
        sources = set(self.robot_bodies) | ({held_body} if held_body is not None else set())

        def touching(bodies: Sequence[int]) -> set[int]:
            among = set(bodies)
            return {b for a, b, _ in pairs if a in among and b in products} | {
                a for a, b, _ in pairs if b in among and a in products
            }

        return frozenset(products[b] for b in pushed_along(sorted(sources), touching))

    # ----------------------------------------------------------------------------------------- cameras
    def camera_image(self, camera: PinholeView) -> CameraImage:
        """The camera's noise-free image of the kitchen now (`perception.images.ImageSource`; world.mj_camera)."""
        if self._cameras is None:
            from scone_bt.world.mj_camera import MjCameras

            self._cameras = MjCameras(self)
        return self._cameras.image(camera)

    def link_poses(self) -> dict[str, tuple[tuple[float, ...], tuple[float, ...]]]:
        """World pose (position, quaternion xyzw) of every robot link, by link name; the base is 'base'.

        As on PyBullet (`world.Kitchen.link_poses`), the links are at their URDF link frames and the base at its
        centre of mass, in its inertial frame: a recording shifts it back by the URDF's inertial origin.
        """
        mj = import_mujoco()
        out: dict[str, tuple[tuple[float, ...], tuple[float, ...]]] = {}
        m, d = self.model, self.data
        for b in sorted(self.robot_bodies):
            if b == self.robot_root:
                ipos, iquat = self.parts.root_inertial
                name, position, quat = "base", np.empty(3), np.empty(4)
                mj.mju_rotVecQuat(position, np.asarray(ipos), d.xquat[b])
                position += d.xpos[b]
                mj.mju_mulQuat(quat, d.xquat[b], np.asarray(iquat))
            else:
                name, position, quat = m.body(b).name, d.xpos[b], d.xquat[b]
            w, x, y, z = (float(c) for c in quat)
            out[name] = (tuple(float(c) for c in position), (x, y, z, w))
        return out

    # ----------------------------------------------------------------------------------------- time
    def at_rest(self) -> bool:
        """True if no object and no robot joint moves faster than the rest thresholds (ground truth)."""
        qvel = self.data.qvel
        for name in self.objects:
            v = self._free_dof[name]
            if (
                np.abs(qvel[v : v + 3]).max() > REST_LINEAR_M_S
                or np.abs(qvel[v + 3 : v + 6]).max() > REST_ANGULAR_RAD_S
            ):
                return False
        joints = np.concatenate([self.arm_dof, self.finger_dof])
        return bool(np.abs(qvel[joints]).max() <= REST_JOINT_RAD_S)

    def advance(self, seconds: float) -> None:
        """Advance simulated time by ``seconds``, running the controllers before each control step.

        A sleeping scene (no controller, no pending `wake`, everything at rest) is not stepped: the clock moves on
        and the world stays as it is, decided from the simulated state alone (seeded runs repeat exactly).
        """
        n = max(1, round(seconds / self.time_step))
        if not self._controllers and self.sim_time >= self._awake_until and self.at_rest():
            self.steps_skipped += n
            self.steps += n
            self.sim_time += n * self.time_step
            return
        mj, m, d, sub = self.mujoco, self.model, self.data, self.substeps
        for _ in range(n):
            for controller in list(self._controllers):
                controller(self)
            mj.mj_step(m, d, nstep=sub)
            self.steps += 1
            self.sim_time += self.time_step
        # mj_step leaves positions one integration ahead of the kinematics it computed: bring them level, so
        # object_state and the cameras see the state the next step starts from.
        mj.mj_kinematics(m, d)
        self.state_version += 1

    def bodies(self) -> int:
        """Bodies in the compiled model now (the world, the scene, the arm's links, the products)."""
        return int(self.model.nbody)

    def constraints(self) -> int:
        """Equality constraints in the model now (the fingers' coupling; a grasp is contacts, not a constraint)."""
        return int(self.model.neq)

    def close(self) -> None:
        if self._cameras is not None:
            self._cameras.close()
            self._cameras = None

    def __enter__(self) -> MjKitchen:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _is_descendant(model: Any, body: int, ancestor: int) -> bool:
    """True if ``body`` is ``ancestor`` or below it in the kinematic tree."""
    while True:
        if body == ancestor:
            return True
        if body == 0:
            return False
        body = int(model.body_parentid[body])
