"""A PyBullet kitchen: a robot on a pedestal between stepped shelf units and a table.

This module is the only place (besides the perception and motion adapters) that talks to PyBullet. The robot's
own stages never read ground truth from here; the simulated human, outcome checks and tests do.
"""

from __future__ import annotations

import contextlib
import itertools
from collections.abc import Callable, Iterator, Sequence
from typing import Any

import numpy as np

from scone_bt.config import KitchenConfig, ObjectSpec, RobotConfig
from scone_bt.config.catalogue import Shape
from scone_bt.errors import ConfigError, UnknownNameError
from scone_bt.perception.images import CameraImage, PinholeView
from scone_bt.quiet import c_stdout_silenced
from scone_bt.stocking import Placement
from scone_bt.world.arm_io import ArmIO
from scone_bt.world.camera import camera_image
from scone_bt.world.ground_truth import GroundTruth, ObjectState
from scone_bt.world.scene_boxes import FLOOR_FRICTION, SCENE_FRICTION, StaticBox, box_colour, static_boxes
from scone_bt.world.sim_clock import REST_ANGULAR_RAD_S, REST_JOINT_RAD_S, REST_LINEAR_M_S, WAKE_S, SimClock
from scone_bt.world.visuals import create_object_visual

__all__ = [
    "FULL_RATE_STEP_S",
    "Controller",
    "Kitchen",
    "ObjectState",
    "StaticBox",
    "full_rate_physics",
]

Controller = Callable[["Kitchen"], None]
"""Called before every physics step, e.g. to send joint targets. Returns nothing."""

SOLVER_ITERATIONS = 150
"""PyBullet constraint-solver iterations per step (the grasp tests and the motion benchmark were tuned with it)."""
FULL_RATE_SOLVER_ITERATIONS = 150
"""Solver iterations of the reference simulation (`full_rate_physics`)."""
FULL_RATE_SOLVER_RESIDUAL = 1e-7
"""The constraint solver's residual threshold of the reference simulation: PyBullet's default."""
FREEZE_MARGIN_M = 0.08
"""A resting object is frozen only if no robot link or moving object comes within this of it (bounding boxes).
(Awake object-steps in the seeded `scone-run --seed 0` episode: 12,408 with 0.15 m, 7,140 with 0.08 m; the outcomes
of `scone-bench physics` are those of the full-rate simulation with either.)"""
FREEZE_CHECK_S = 0.025
"""Simulated seconds between freeze checks: the hand (under 1.7 m/s) moves well under FREEZE_MARGIN_M meanwhile."""
FULL_RATE_STEP_S = 1.0 / 240.0
"""The physics step the grasps were first tuned at (PyBullet's default): the reference `full_rate_physics` runs."""
_KITCHEN_IDS = itertools.count()


@contextlib.contextmanager
def full_rate_physics() -> Iterator[None]:
    """Kitchens made meanwhile (without explicit arguments) step every body at FULL_RATE_STEP_S, freeze nothing and
    solve contacts to PyBullet's default residual: the reference the physics shortcuts are compared with
    (`scone-bench physics`, tests)."""
    names = (
        "TIME_STEP_DEFAULT",
        "FREEZE_RESTING_DEFAULT",
        "SOLVER_ITERATIONS_DEFAULT",
        "SOLVER_RESIDUAL_DEFAULT",
    )
    saved = {name: getattr(Kitchen, name) for name in names}
    reference = (FULL_RATE_STEP_S, False, FULL_RATE_SOLVER_ITERATIONS, FULL_RATE_SOLVER_RESIDUAL)
    for name, value in zip(names, reference, strict=True):
        setattr(Kitchen, name, value)
    try:
        yield
    finally:
        for name, value in saved.items():
            setattr(Kitchen, name, value)


def _bullet_client(connection_mode: int) -> Any:
    """A pybullet BulletClient that binds each function to its client once, not on every attribute access.

    BulletClient.__getattr__ builds a new functools.partial per call; the physics loop makes hundreds of thousands
    of calls per episode, and the lookup was about 2 % of a self-confidence execution's CPU time.
    """
    import functools

    from pybullet_utils.bullet_client import BulletClient

    class _BoundClient(BulletClient):
        def __getattr__(self, name: str) -> Any:
            attribute = super().__getattr__(name)
            if name != "disconnect" and isinstance(attribute, functools.partial):
                self.__dict__[name] = attribute  # found by normal lookup from now on
            return attribute

    return _BoundClient(connection_mode=connection_mode)


class Kitchen(GroundTruth, SimClock):
    """The simulated world. Create with `Kitchen(kitchen_cfg, robot_cfg)`; spawn objects with `spawn`.

    Args:
        kitchen: Scene, camera and catalogue.
        robot: The arm to load.
        gui: Open PyBullet's own window (debugging only; scone-run uses rerun instead).
        time_step: Physics step in seconds (default: the robot file's, 1 / control.physics_hz).
        freeze_resting: Freeze resting objects far from anything moving (see `advance`); off only to compare.
    """

    FREEZE_RESTING_DEFAULT = True
    """`freeze_resting` when not given (benchmarks flip it to compare outcomes with and without freezing)."""
    SOLVER_ITERATIONS_DEFAULT = SOLVER_ITERATIONS
    """Constraint-solver iterations per step of the kitchens made from now on."""
    SOLVER_RESIDUAL_DEFAULT: float | None = None
    """The constraint solver's residual threshold of the kitchens made from now on; None: the robot file's
    (control.solver_residual)."""
    TIME_STEP_DEFAULT: float | None = None
    """`time_step` when not given; None: the robot file's (1 / control.physics_hz). `full_rate_physics` sets it
    to FULL_RATE_STEP_S to compare outcomes."""

    def __init__(
        self,
        kitchen: KitchenConfig,
        robot: RobotConfig,
        *,
        gui: bool = False,
        time_step: float | None = None,
        freeze_resting: bool | None = None,
    ) -> None:
        with c_stdout_silenced():
            import pybullet as p

            bc = _bullet_client(p.GUI if gui else p.DIRECT)
        self.config = kitchen
        self.robot_config = robot
        self.bc = bc
        if time_step is None:
            time_step = self.TIME_STEP_DEFAULT or 1.0 / robot.control.physics_hz
        self.time_step = float(time_step)
        self.sim_time = 0.0
        self.steps = 0
        self._controllers: list[Controller] = []
        self._arm_io: ArmIO | None = None
        self.objects: dict[str, int] = {}
        self.specs: dict[str, ObjectSpec] = {}
        self.spawn_slots: dict[str, tuple[float, float, float]] = {}
        self.steps_skipped = 0  # physics steps not taken because the scene was asleep
        # Bumped whenever the world may look different (a step taken, a body moved): cameras re-render only then.
        self.state_version = 0
        # Unlike id(), never reused by a later Kitchen; renewed when covers change what the cameras see, and when
        # the kitchen is restocked.
        self.uid = next(_KITCHEN_IDS)
        # What the cameras see of the kitchen without products: the same for every kitchen of one scene and robot
        # (body ids included: the scene's boxes, then the robot), until a cover comes or goes.
        self.static_key: tuple[object, ...] = (
            repr(kitchen.scene),
            str(robot.urdf),
            robot.camera_shapes,
            tuple(robot.base_position),
        )
        # Each camera's first image of a stocked kitchen is the products patched over its image of the empty
        # kitchen (world.camera.keep_background), rendered when products are first put in, once per scene and
        # process. Always so, never only from the second kitchen on: a patched image differs from a whole render
        # by an edge pixel and the depth buffer's rounding, which can change a decision, so an episode must see
        # the same images whether or not another kitchen of its scene ran before it in the process.
        self.keep_backgrounds = True
        self._awake_until = 0.0
        self._frozen: dict[str, tuple[object, object]] = {}  # name -> pose when frozen
        self._frozen_boxes: dict[str, _Box] = {}  # name -> bounding box when frozen (it stands still)
        self._settle_until = 0.0
        self.freeze_resting = self.FREEZE_RESTING_DEFAULT if freeze_resting is None else freeze_resting

        bc = self.bc
        bc.resetSimulation()
        bc.setGravity(0, 0, -9.81)
        bc.setTimeStep(self.time_step)
        bc.setPhysicsEngineParameter(
            numSolverIterations=self.SOLVER_ITERATIONS_DEFAULT,
            solverResidualThreshold=self.SOLVER_RESIDUAL_DEFAULT or robot.control.solver_residual,
            deterministicOverlappingPairs=1,
        )
        self.static_boxes = self._build_static_scene()
        self.robot_id, self.joint_index = self._load_robot()
        self._robot_links = range(-1, bc.getNumJoints(self.robot_id))  # base (-1) and every link

    # ----------------------------------------------------------------------------------------- scene
    def _build_static_scene(self) -> list[StaticBox]:
        import pybullet as p

        scene = self.config.scene
        boxes = static_boxes(self.config)
        self.static_body_ids: dict[str, int] = {}
        for box in boxes:
            half = [s / 2 for s in box.size]
            col = self.bc.createCollisionShape(p.GEOM_BOX, halfExtents=half)
            vis = self.bc.createVisualShape(p.GEOM_BOX, halfExtents=half, rgbaColor=box_colour(box.name))
            body = self.bc.createMultiBody(0, col, vis, basePosition=box.center)
            self.bc.changeDynamics(body, -1, lateralFriction=SCENE_FRICTION)
            self.static_body_ids[box.name] = body
        plane = self.bc.createCollisionShape(p.GEOM_PLANE)
        plane_vis = self.bc.createVisualShape(
            p.GEOM_BOX, halfExtents=[2, 2, 0.001], rgbaColor=(0.9, 0.9, 0.9, 1)
        )
        self.floor_id = self.bc.createMultiBody(0, plane, plane_vis, basePosition=(0, 0, scene.floor_z))
        self.bc.changeDynamics(self.floor_id, -1, lateralFriction=FLOOR_FRICTION)
        return boxes

    def _load_robot(self) -> tuple[int, dict[str, int]]:
        import pybullet as p

        cfg = self.robot_config
        flags = p.URDF_USE_SELF_COLLISION_EXCLUDE_PARENT
        if cfg.camera_shapes == "collision":
            # PyBullet then draws the collision shapes: the same bodies and physics, far fewer triangles to render.
            flags |= p.URDF_IGNORE_VISUAL_SHAPES
        from scone_bt.quiet import c_stdout_silenced

        try:
            # PyBullet prints its parser's complaints on the C streams, glued to our one-line error
            with c_stdout_silenced():
                rid = self.bc.loadURDF(
                    str(cfg.urdf), basePosition=cfg.base_position, useFixedBase=True, flags=flags
                )
        except p.error as exc:
            raise ConfigError(f"{cfg.source}: PyBullet could not load URDF {cfg.urdf} ({exc})") from None
        index = {}
        for j in range(self.bc.getNumJoints(rid)):
            info = self.bc.getJointInfo(rid, j)
            index[info[1].decode()] = j
        missing = [n for n in (*cfg.arm_joints, *cfg.gripper.joints) if n not in index]
        if missing:
            raise UnknownNameError("joint", missing[0], index)
        for name, q in zip(cfg.arm_joints, cfg.home, strict=True):
            self.bc.resetJointState(rid, index[name], q)
        for name in cfg.gripper.joints:
            self.bc.resetJointState(rid, index[name], cfg.gripper.open_position)
            self.bc.changeDynamics(rid, index[name], lateralFriction=cfg.gripper.finger_friction)
        self.robot_id, self.joint_index = rid, index
        self._moving_joints = [index[n] for n in (*cfg.arm_joints, *cfg.gripper.joints)]
        self.hold_arm(cfg.home)
        self.set_gripper_target(cfg.gripper.open_position)
        return rid, index

    # ----------------------------------------------------------------------------------------- objects
    def spawn_planned(
        self, specs: Sequence[ObjectSpec], places: Sequence[Placement]
    ) -> dict[str, tuple[float, float, float]]:
        """Put ``specs`` where a stocking plan (`plan_stocking`, one place per spec, in order) says, and let them
        settle (`spawn` plans and calls this).

        Returns:
            name → surface point under the object's centre (x, y, z), metres.
        """
        import pybullet as p

        self._refuse_present(specs)
        if self.keep_backgrounds and not self.objects:
            from scone_bt.perception.camera import Camera
            from scone_bt.world.camera import keep_background

            for camera_spec in self.config.cameras:
                keep_background(self, Camera(camera_spec))
        for spec, place in zip(specs, places, strict=True):
            x, y, z = place.position
            sx, sy, sz = spec.size
            if spec.shape == Shape.BOX:
                col = self.bc.createCollisionShape(p.GEOM_BOX, halfExtents=[sx / 2, sy / 2, sz / 2])
            else:
                col = self.bc.createCollisionShape(p.GEOM_CYLINDER, radius=sx / 2, height=sz)
            vis = create_object_visual(self.bc, spec)
            body = self.bc.createMultiBody(
                spec.mass,
                col,
                vis,
                basePosition=(x, y, z + sz / 2 + 1e-3),
                baseOrientation=self.bc.getQuaternionFromEuler((0, 0, place.yaw)),
            )
            self.bc.changeDynamics(
                body, -1, lateralFriction=spec.friction, spinningFriction=0.001, rollingFriction=0.0005
            )
            self.objects[spec.name] = body
            self.specs[spec.name] = spec
            self.spawn_slots[spec.name] = (x, y, z)
        self.wake()
        self.advance(0.5)
        return dict(self.spawn_slots)

    def object_state(self, name: str) -> ObjectState:
        body = self._body(name)
        pos, orn = self.bc.getBasePositionAndOrientation(body)
        return ObjectState(name, body, tuple(pos), tuple(orn))

    def ray_bodies(self, start: Sequence[float] | np.ndarray, ends: np.ndarray) -> list[int]:
        """The body id each ray from ``start`` to a row of ``ends`` (n, 3) hits first, -1 where none (metres)."""
        hits = self.bc.rayTestBatch([list(map(float, start))] * len(ends), np.asarray(ends).tolist())
        return [int(hit[0]) for hit in hits]

    def _yaw(self, orientation: tuple[float, float, float, float]) -> float:
        return float(self.bc.getEulerFromQuaternion(orientation)[2])

    def _rotation(self, orientation: tuple[float, float, float, float]) -> np.ndarray:
        return np.array(self.bc.getMatrixFromQuaternion(orientation)).reshape(3, 3)

    def touches_robot(self, name: str) -> bool:
        """True if the object touches the robot (in or against the gripper: a person does not grab it away)."""
        return bool(self.bc.getContactPoints(bodyA=self._body(name), bodyB=self.robot_id))

    # ----------------------------------------------------------------------------------------- test rig
    # Changes a test rig (`scone_bt.robot.rig`) makes from outside the robot, the way a person would in a real
    # kitchen: put a product somewhere by hand, take it away, hold something in front of a camera or over a lid.

    def place_object(self, name: str, surface: Sequence[float], yaw: float = 0.0) -> None:
        """Stand the product upright on the surface point ``surface`` (x, y, z of the surface under its centre,
        metres), turned by ``yaw`` (radians), at rest: what a person putting it there by hand does."""
        body = self._body(name)
        spec = self.specs[name]
        x, y, z = (float(v) for v in surface)
        orientation = self.bc.getQuaternionFromEuler((0.0, 0.0, float(yaw)))
        self.bc.resetBasePositionAndOrientation(body, (x, y, z + spec.height / 2 + 1e-3), orientation)
        self.bc.resetBaseVelocity(body, (0, 0, 0), (0, 0, 0))
        self.wake()

    def add_cover(
        self,
        center: Sequence[float],
        size: Sequence[float],
        rgba: Sequence[float] = (0.2, 0.2, 0.2, 1.0),
        orientation: Sequence[float] = (0.0, 0.0, 0.0, 1.0),
    ) -> int:
        """An opaque box the cameras see but nothing collides with (a hand over a lid, a cloth over a lens);
        ``center`` and ``size`` in metres, ``orientation`` a quaternion (x, y, z, w).

        Returns:
            Its handle for `remove_cover`.
        """
        import pybullet as p

        half = [float(s) / 2 for s in size]
        visual = self.bc.createVisualShape(p.GEOM_BOX, halfExtents=half, rgbaColor=list(rgba))
        handle = int(
            self.bc.createMultiBody(
                0,
                -1,
                visual,
                basePosition=[float(c) for c in center],
                baseOrientation=[float(q) for q in orientation],
            )
        )
        self._scene_changed()
        return handle

    def remove_cover(self, handle: int) -> None:
        """Take away a cover `add_cover` made."""
        self.bc.removeBody(handle)
        self._scene_changed()

    def _scene_changed(self) -> None:
        """A body the cameras see but no product is (a cover) came or went: no camera may reuse an earlier render.

        A camera reuses its last render while the same products and links stand in view unmoved, keyed by
        ``uid`` (`world.camera.camera_image`); a new ``uid`` voids every such render.
        """
        self.uid = next(_KITCHEN_IDS)
        self.static_key = ("covered", self.uid)  # a scene of its own
        self.state_version += 1

    def set_gripper_properties(
        self, max_force: float | None = None, finger_friction: float | None = None
    ) -> None:
        """Change the gripper's force limit (N per finger) and the finger pads' friction from now on (a worn motor,
        greasy pads). The next grasp closes with the new force; ``None`` keeps a value."""
        g = self._replace_gripper(max_force, finger_friction)
        for joint in g.joints:
            self.bc.changeDynamics(self.robot_id, self.joint_index[joint], lateralFriction=g.finger_friction)
        self._keep_stepping()

    # ----------------------------------------------------------------------------------------- robot
    def arm_joint_positions(self) -> np.ndarray:
        ids = [self.joint_index[n] for n in self.robot_config.arm_joints]
        return np.array([s[0] for s in self.bc.getJointStates(self.robot_id, ids)])

    def arm_joint_velocities(self) -> np.ndarray:
        ids = [self.joint_index[n] for n in self.robot_config.arm_joints]
        return np.array([s[1] for s in self.bc.getJointStates(self.robot_id, ids)])

    def gripper_positions(self) -> np.ndarray:
        ids = [self.joint_index[n] for n in self.robot_config.gripper.joints]
        return np.array([s[0] for s in self.bc.getJointStates(self.robot_id, ids)])

    def hold_arm(self, q: Sequence[float] | np.ndarray) -> None:
        """Command arm joint position targets (PyBullet position control, zero velocity feed-forward)."""
        self.command_arm(np.asarray(q, dtype=float))
        self._keep_stepping()

    def set_gripper_target(self, position: float, force: float | None = None) -> None:
        import pybullet as p

        g = self.robot_config.gripper
        ids = [self.joint_index[n] for n in g.joints]
        f = g.max_force if force is None else force
        self.bc.setJointMotorControlArray(
            self.robot_id,
            ids,
            p.POSITION_CONTROL,
            targetPositions=[position] * len(ids),
            forces=[f] * len(ids),
        )
        self._keep_stepping()

    # ----------------------------------------------------------------------------------------- executor
    # What executing a plan drives and senses (`motion.executor.ArmExecutor`); the PyBullet side is world.arm_io.
    @property
    def arm_io(self) -> ArmIO:
        """The arm's commands and sensors (joint and link indices read on first use)."""
        if self._arm_io is None:
            self._arm_io = ArmIO(self)
        return self._arm_io

    def command_arm(self, q: np.ndarray, qd: np.ndarray | None = None) -> None:
        """Position control of the arm towards q with velocity feed-forward qd (zero when None)."""
        self.arm_io.command_arm(q, qd)

    def couple_fingers(self) -> None:
        """Keep the two fingers symmetric (a gear constraint, made once per kitchen)."""
        self.arm_io.couple_fingers()

    def held_object(self, min_force: float) -> str | None:
        """What every finger touches with at least min_force newtons, by name, else None."""
        return self.arm_io.held_object(min_force)

    def finger_forces(self, held: str) -> tuple[float, float]:
        """(vertical load, grip) in newtons the fingers feel from ``held`` (`motion.probe.ForceSensing`)."""
        return self.arm_io.finger_forces(held)

    def wrist_load(self) -> float:
        """The vertical force all the hand's contacts exert, newtons (`motion.probe.ForceSensing`)."""
        return self.arm_io.wrist_load()

    def pad_contacts(self, held: str) -> tuple[tuple[float, float, float] | None, ...]:
        """Where ``held`` touches each finger, in the finger's frame, metres (`motion.probe.ForceSensing`)."""
        return self.arm_io.pad_contacts(held)

    def unexpected_contact(self, allow_gripper: bool, held: str | None, min_force: float) -> str | None:
        """'<link> hit <what>' for the first robot link pushing on something it should not touch, else None."""
        return self.arm_io.unexpected_contact(allow_gripper, held, min_force)

    def products_touched(self, held: str | None) -> frozenset[str]:
        """Products (not ``held``) touching a robot link or the held product ``held`` now."""
        return self.arm_io.products_touched(held)

    # ----------------------------------------------------------------------------------------- cameras
    def camera_image(self, camera: PinholeView) -> CameraImage:
        """The camera's noise-free image of the kitchen now (`perception.images.ImageSource`; world.camera)."""
        return camera_image(self, camera)

    def link_poses(self) -> dict[str, tuple[tuple[float, ...], tuple[float, ...]]]:
        """World pose (position, quaternion xyzw) of every robot link, by link name; the base is 'base'."""
        out = {}
        pos, orn = self.bc.getBasePositionAndOrientation(self.robot_id)
        out["base"] = (tuple(pos), tuple(orn))
        for j in range(self.bc.getNumJoints(self.robot_id)):
            name = self.bc.getJointInfo(self.robot_id, j)[12].decode()
            st = self.bc.getLinkState(self.robot_id, j, computeForwardKinematics=True)
            out[name] = (tuple(st[4]), tuple(st[5]))
        return out

    # ----------------------------------------------------------------------------------------- time
    def wake(self, seconds: float = WAKE_S) -> None:
        """Step the physics for at least `seconds` from now, even if all is at rest, and freeze nothing meanwhile.

        Call it after changing the world from outside the physics (moving a body): a resting scene is otherwise
        not stepped (see `advance`). A frozen object that was moved from outside thaws at the next step.
        """
        self._settle_until = max(self._settle_until, self.sim_time + seconds)
        self._keep_stepping(seconds)

    def at_rest(self) -> bool:
        """True if no object and no robot joint moves faster than the rest thresholds (ground truth)."""
        if not all(self._body_at_rest(body) for body in self.objects.values()):
            return False
        states = self.bc.getJointStates(self.robot_id, self._moving_joints)
        return all(abs(st[1]) <= REST_JOINT_RAD_S for st in states)

    def _body_at_rest(self, body: int) -> bool:
        linear, angular = self.bc.getBaseVelocity(body)
        return max(map(abs, linear)) <= REST_LINEAR_M_S and max(map(abs, angular)) <= REST_ANGULAR_RAD_S

    @property
    def frozen(self) -> frozenset[str]:
        """Objects currently frozen (made static while at rest and far from the robot)."""
        return frozenset(self._frozen)

    def _freeze(self, name: str) -> None:
        body = self.objects[name]
        self.bc.changeDynamics(body, -1, mass=0.0)
        # A massless body keeps integrating the velocity it had: it must stand still to stay where it was.
        self.bc.resetBaseVelocity(body, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
        self._frozen[name] = self.bc.getBasePositionAndOrientation(body)
        self._frozen_boxes[name] = self.bc.getAABB(body)

    def _thaw(self, name: str) -> None:
        # Restoring the mass restores the inertia PyBullet computed from the collision shape at creation.
        self.bc.changeDynamics(self.objects[name], -1, mass=self.specs[name].mass)
        del self._frozen[name]
        del self._frozen_boxes[name]

    def _update_frozen(self) -> None:
        """Freeze resting objects that nothing moving comes near; thaw frozen ones something moving approaches.

        "Near" is FREEZE_MARGIN_M between bounding boxes: more than the hand travels between two checks
        (FREEZE_CHECK_S), so the arm never meets a frozen object.
        """
        if not self.freeze_resting:
            return
        settling = (
            self.sim_time < self._settle_until
        )  # the world was just changed from outside: freeze nothing
        bc, objects, frozen = self.bc, self.objects, self._frozen
        # One AABB and one velocity query per awake body per check: freezing and thawing below move nothing. A
        # frozen body's box is the one it had when frozen (a frozen body moved from outside is thawed below all
        # the same).
        frozen_boxes, get_aabb = self._frozen_boxes, bc.getAABB
        names = list(objects)
        boxes: list[_Box] = []
        resting: dict[str, bool] = {}
        rid = self.robot_id
        movers = [get_aabb(rid, j) for j in self._robot_links]
        for name in names:
            box = frozen_boxes.get(name)
            if box is None:
                body = objects[name]
                box = get_aabb(body)
                resting[name] = at_rest = self._body_at_rest(body)
                if not at_rest:
                    movers.append(box)
            boxes.append(box)
        near = _near_any(boxes, movers, FREEZE_MARGIN_M)
        for name, is_near in zip(names, near, strict=True):
            if name in frozen:
                # Thaw when something moving comes near, or when the object was moved from outside the physics.
                if is_near or bc.getBasePositionAndOrientation(objects[name]) != frozen[name]:
                    self._thaw(name)
            elif not settling and resting[name] and not is_near:
                self._freeze(name)

    def advance(self, seconds: float) -> None:
        """Advance simulated time by `seconds`, running the active controllers before each physics step.

        Two shortcuts keep a mostly idle kitchen cheap, both decided from the simulated state alone (so seeded
        runs still repeat exactly):
        - a sleeping scene is not stepped: with no controller registered, no `wake()` pending and everything at
          rest (`at_rest`), the clock moves on and the world stays as it is (what stepping it would give, up to
          solver jitter of micrometres);
        - a resting object that neither the robot nor a moving object comes within FREEZE_MARGIN_M of is frozen
          (static) until something does: the contacts of products standing on the shelf are most of the
          constraint solver's work, and they do not change the motion of anything else.
        """
        n = max(1, round(seconds / self.time_step))
        check_every = max(1, round(FREEZE_CHECK_S / self.time_step))
        if not self._controllers and self.sim_time >= self._awake_until and self.at_rest():
            self.steps_skipped += n
            self.steps += n
            self.sim_time += n * self.time_step
            return
        for i in range(n):
            if i % check_every == 0:
                self._update_frozen()
            for controller in list(self._controllers):
                controller(self)
            self.bc.stepSimulation()
            self.steps += 1
            self.sim_time += self.time_step
        self.state_version += 1

    def clear_products(self, physics_state: int) -> None:
        """Remove every product and restore the physics to `physics_state` (a ``bc.saveState()`` id taken when the
        kitchen held no product).

        Bodies are removed newest first, so PyBullet hands the next products the same body ids a new kitchen
        would. The world is close to a new one, not identical: PyBullet's solver keeps state across removed bodies
        and a restored state, and in the self-confidence generator about 1 execution in 60 ended otherwise in a
        restocked kitchen than in a new one. What must repeat exactly builds a new kitchen (it takes about
        0.04 s), as the generator does since.
        """
        for body in sorted(self.objects.values(), reverse=True):
            self.bc.removeBody(body)
        self.objects.clear()
        self.specs.clear()
        self.spawn_slots.clear()
        self._frozen.clear()
        self._frozen_boxes.clear()
        self._controllers.clear()
        self.bc.restoreState(stateId=physics_state)
        if self._arm_io is not None:
            self._arm_io.forget_command()
        self.sim_time = 0.0
        self.steps = self.steps_skipped = 0
        self._awake_until = self._settle_until = 0.0
        # The next products get the same body ids: a camera must not take one for the product it saw before.
        self.uid = next(_KITCHEN_IDS)
        self.state_version += 1

    def bodies(self) -> int:
        """Bodies in the simulation now (the scene's boxes, the arm, the products)."""
        return int(self.bc.getNumBodies())

    def constraints(self) -> int:
        """Constraints in the simulation now (a held product's grasp)."""
        return int(self.bc.getNumConstraints())

    def close(self) -> None:
        with contextlib.suppress(Exception):  # already disconnected: closing twice must be harmless
            self.bc.disconnect()

    def __enter__(self) -> Kitchen:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


_Box = tuple[Sequence[float], Sequence[float]]
"""An axis-aligned box as PyBullet's getAABB gives it: ((min x, y, z), (max x, y, z)), metres."""


def _near_any(boxes: Sequence[_Box], movers: Sequence[_Box], margin: float) -> list[bool]:
    """For each box, whether some mover's box comes within `margin` of it (overlap on every axis).

    Plain floats, not numpy: a check has a dozen boxes, where numpy's per-call cost is most of the work. A box
    beyond the margin of the box around all movers meets none of them, which rules out most products at once;
    the comparisons are those of the per-pair test, so the answer is the same.
    """
    if not movers:
        return [False] * len(boxes)
    lo_x = min(b[0][0] for b in movers)
    lo_y = min(b[0][1] for b in movers)
    lo_z = min(b[0][2] for b in movers)
    hi_x = max(b[1][0] for b in movers)
    hi_y = max(b[1][1] for b in movers)
    hi_z = max(b[1][2] for b in movers)
    out = []
    for (ax, ay, az), (bx, by, bz) in boxes:
        ax, ay, az, bx, by, bz = ax - margin, ay - margin, az - margin, bx + margin, by + margin, bz + margin
        if ax > hi_x or ay > hi_y or az > hi_z or lo_x > bx or lo_y > by or lo_z > bz:
            out.append(False)
            continue
        out.append(
            any(
                ax <= mx and ay <= my and az <= mz and nx <= bx and ny <= by and nz <= bz
                for (nx, ny, nz), (mx, my, mz) in movers
            )
        )
    return out
