"""The collision world the planner checks joint states against (Pinocchio geometry + coal adapter).

Obstacles are boxes and cylinders fixed in the world: the scene's static boxes (known geometry) and the other
detected objects. An object held in the gripper is attached to the end-effector's joint and moves with the arm.

A state is checked in two phases: spheres around the arm (`motion.spheres`, compiled) leave the pairs that may
touch, and coal's GJK checks those on the collision model's own shapes. Pinocchio's geometry model of the world is
made only where it is asked for (an arm whose joints the compiled kernel does not model, a held object at its tilt
limit to rounding, VAMP's environment).
"""

from __future__ import annotations

import time
import weakref
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from scone_bt.config.catalogue import Shape
from scone_bt.motion.model import ArmModel, pose_matrix
from scone_bt.motion.pair_kinds import PAIR_HELD_OBSTACLE, PAIR_OBSTACLE, PAIR_ROBOT
from scone_bt.motion.spheres import POSITIONS_KEPT, Obstacles, SphereChecks, arm_spheres

ATTACHED_SHRINK_M = 0.005
"""A held object's collision shape is this much (m) smaller on every side than the object: it rests on (touches)
its support when the grasp closes."""

__all__ = ["Obstacle", "CollisionWorld", "HandModel", "fixed_obstacles", "interpolated"]


def interpolated(qa: np.ndarray, qb: np.ndarray, times: np.ndarray) -> np.ndarray:
    """(n, dof) states qa + (qb - qa) t for each t of `times`: the same floats as computing them one by one."""
    qa = np.asarray(qa, dtype=float)
    return qa + (np.asarray(qb, dtype=float) - qa) * np.asarray(times, dtype=float)[:, None]


@dataclass(frozen=True)
class Obstacle:
    """A primitive obstacle.

    Attributes:
        name: Unique name in the world.
        shape: "box" or "cylinder".
        size: Box extents (x, y, z) or cylinder (diameter, diameter, height), metres.
        pose: (4, 4) world pose of the shape's centre (for an attached object: relative to the end-effector frame).
    """

    name: str
    shape: str
    size: tuple[float, float, float]
    pose: np.ndarray


def fixed_obstacles(boxes: Sequence[Any], floor_z: float) -> tuple[Obstacle, ...]:
    """The kitchen's fixed boxes (world.scene_boxes.StaticBox: name, centre, full size; metres) as obstacles, then
    the floor: a 4 m slab 2 cm thick whose top is at ``floor_z``."""
    out = [Obstacle(b.name, "box", tuple(b.size), pose_matrix(np.eye(3), b.center)) for b in boxes]
    out.append(Obstacle("floor", "box", (4.0, 4.0, 0.02), pose_matrix(np.eye(3), (0.0, 0.0, floor_z - 0.01))))
    return tuple(out)


def _geometry(shape: str, size: Sequence[float], padding: float) -> Any:
    import coal

    sx, sy, sz = (float(s) + 2 * padding for s in size)
    if shape == Shape.BOX:
        return coal.Box(sx, sy, sz)
    return coal.Cylinder(sx / 2, sz)


SEEN_STATES = 50_000
"""Most answers a world keeps (`CollisionWorld.is_valid`); about 4 MB, far above a plan's few thousand checks."""
_PLACED: dict[tuple[Any, ...], Any] = {}
"""Obstacle geometry objects already made, by what they are made of (see `_placed`)."""
PLACED_CACHE_SIZE = 4096
"""Most geometry objects kept in `_PLACED` (it is emptied when full; a kitchen holds a few dozen obstacles)."""


def _placed(ob: Obstacle, padding: float, base: np.ndarray) -> Any:
    """The obstacle's padded Pinocchio geometry object in the arm's base frame, made once per obstacle, padding
    and arm and then taken from `_PLACED` (Pinocchio copies it into each world's model, sharing its shape)."""
    import pinocchio as pin

    size = ob.size if type(ob.size) is tuple else tuple(float(v) for v in ob.size)
    key = (ob.name, ob.shape, size, ob.pose.tobytes(), padding, base.tobytes())
    placed = _PLACED.get(key)
    if placed is None:
        pose = ob.pose.copy()
        pose[:3, 3] -= base
        placed = pin.GeometryObject(
            f"obstacle:{ob.name}",
            0,
            0,
            pin.SE3(pose[:3, :3], pose[:3, 3]),
            _geometry(ob.shape, ob.size, padding),
        )
        if len(_PLACED) >= PLACED_CACHE_SIZE:
            _PLACED.clear()
        _PLACED[key] = placed
    return placed


class CollisionWorld:
    """The arm plus fixed obstacles and an optional attached object; answers `is_valid(q)`.

    Args:
        arm: The arm model (its geometry is copied, not modified).
        obstacles: Fixed obstacles in the world frame.
        attached: An object held by the gripper, pose relative to the end-effector frame, or None.
        padding: Metres added on every side of every obstacle (a safety margin for perception error).
        ignore_for_hand: Obstacle names the gripper (hand and fingers) may touch, e.g. the object being grasped.
        max_tilt: If set, the largest angle (rad) between the held object's up axis (without one: the hand's
            approach axis, reversed) and straight up: keeps a carried object upright (a path constraint, checked
            like a collision).
        finger_position: Where each finger stands (m from the centre, as the gripper joints count), the hand
            pre-shaped for the grasp; None: fully open.
    """

    def __init__(
        self,
        arm: ArmModel,
        obstacles: Sequence[Obstacle],
        attached: Obstacle | None = None,
        *,
        padding: float = 0.01,
        ignore_for_hand: Sequence[str] = (),
        max_tilt: float | None = None,
        finger_position: float | None = None,
    ) -> None:
        from scone_bt.motion import compiled

        self.arm = arm
        self.model = arm.model
        self._obstacles = list(obstacles)
        self._attached = attached
        self._padding = padding
        self._finger_position = finger_position
        n_ob = len(self._obstacles)
        poses = np.array([ob.pose for ob in self._obstacles], dtype=float).reshape(n_ob, 4, 4)
        poses[:, :3, 3] -= arm.config.base_position  # the model's frame: the arm's base
        self._sizes = np.array([ob.size for ob in self._obstacles], dtype=float).reshape(n_ob, 3)
        # The pairs to check, in Pinocchio's order, in one compiled pass (`compiled.world_pairs`): the arm's self
        # pairs; each moving geometry with each obstacle whose bounding sphere it can reach (a pair that can never
        # meet, whatever the joints do, is left out), but not the hand with what it may touch; the held object.
        sizes = self._sizes + 2 * padding
        ignored = np.array([ob.name in ignore_for_hand for ob in self._obstacles], dtype=bool)
        self._pairs = np.empty(
            (len(arm.self_pairs) + (len(arm.robot_geometry) + 1) * (n_ob + 1), 3), np.int64
        )
        n_pairs = compiled.world_pairs(
            arm.self_pairs,
            arm.moving_geometry,
            arm.hand_geometry,
            arm.geometry_reach_from_first_joint,
            arm.first_joint_origin,
            np.ascontiguousarray(poses[:, :3, 3]),
            0.5 * np.sqrt((sizes * sizes).sum(axis=1)),
            ignored,
            attached is not None,
            self._pairs,
        )
        self._pairs = self._pairs[:n_pairs]
        ee_in_joint = arm._ee_in_joint
        # The held object's pose in the hand's joint frame; set exactly when an object is attached.
        self._held_pose: np.ndarray | None = None if attached is None else ee_in_joint @ attached.pose
        self.checks = 0
        self.check_time = 0.0  # wall seconds spent in is_valid
        # Answers by the state's bytes: OMPL and the straight-line checks ask about one state again and again (one
        # check in ten of a plan), and a state's answer never changes in a world. Still counted as checks.
        self._seen: dict[bytes, bool] = {}
        self.min_up = None if max_tilt is None else float(np.cos(max_tilt))
        self._ee_joint = arm.ee_joint
        # The axis kept vertical: the held object's up axis, or else the hand's approach axis pointing down.
        up_in_ee = attached.pose[:3, 2] if attached is not None else np.array([0.0, 0.0, -1.0])
        self._up_in_joint = ee_in_joint[:3, :3] @ up_in_ee
        self._pinocchio: tuple[Any, Any, Any, Any] | None = None
        self._spheres = self._sphere_checks(poses)

    def _check_matrix(self) -> np.ndarray:
        """The pairs as Pinocchio's boolean matrix over its geometries (robot, obstacles, held object)."""
        n_robot, n_ob = len(self.arm.robot_geometry), len(self._obstacles)
        held_id = n_robot + n_ob
        check = np.zeros((held_id + (self._attached is not None),) * 2, dtype=bool)
        kinds, a, b = self._pairs.T
        rows = np.where(kinds == PAIR_HELD_OBSTACLE, n_robot + b, a)
        cols = np.where(kinds == PAIR_ROBOT, b, np.where(kinds == PAIR_OBSTACLE, n_robot + b, held_id))
        check[rows, cols] = True
        return check

    def _sphere_checks(self, poses: np.ndarray) -> SphereChecks | None:
        """The spheres' broad phase and coal's GJK for this world (`motion.spheres`), or None: Pinocchio's."""
        arm, attached = self.arm, self._attached
        spheres = arm_spheres(arm, self._finger_position)
        if spheres is None:
            return None
        held = None
        if attached is not None and self._held_pose is not None:
            size = tuple(float(v) - 2 * ATTACHED_SHRINK_M for v in attached.size)
            held = (attached.name, attached.shape, size, self._held_pose, arm.ee_joint)
        return SphereChecks(
            spheres,
            self._pairs,
            Obstacles(
                [ob.name for ob in self._obstacles], [ob.shape for ob in self._obstacles], self._sizes, poses
            ),
            self._padding,
            held,
            None if attached is None else _geometry(attached.shape, attached.size, -ATTACHED_SHRINK_M),
            None if self.min_up is None else (arm.ee_joint, self.min_up, self._up_in_joint),
            _geometry,
        )

    def _meshes(self) -> tuple[Any, Any, Any, Any]:
        """Pinocchio's data, geometry model and data, and broad phase for this world (made on first need)."""
        if self._pinocchio is not None:
            return self._pinocchio
        import pinocchio as pin

        arm = self.arm
        gm = arm.geometry_with_fingers(self._finger_position)
        base = np.asarray(arm.config.base_position)
        for ob in self._obstacles:
            gm.addGeometryObject(_placed(ob, self._padding, base))
        pose = self._held_pose
        if self._attached is not None and pose is not None:
            ee = self.model.frames[arm.ee_frame]
            # Slightly smaller than the object: it rests on (touches) its support when the grasp closes.
            obj = pin.GeometryObject(
                f"attached:{self._attached.name}",
                arm.ee_joint,
                ee.parentFrame,
                pin.SE3(pose[:3, :3], pose[:3, 3]),
                _geometry(self._attached.shape, self._attached.size, -ATTACHED_SHRINK_M),
            )
            gm.addGeometryObject(obj)
        gm.setCollisionPairs(self._check_matrix(), True)
        geom_data = gm.createData()
        # A broad phase: only pairs whose bounding boxes overlap reach the narrow phase (several times faster than
        # checking every pair in a cluttered kitchen); it honours the pair list above. With a few dozen
        # geometries, testing every pair of boxes beats maintaining an AABB tree: 7.8 against 16.0 us per
        # check over 20,000 checks of real plans, with the same answer at every one.
        broadphase = pin.BroadPhaseManager_NaiveCollisionManager(self.model, gm, geom_data)
        self._pinocchio = (self.model.createData(), gm, geom_data, broadphase)
        return self._pinocchio

    @property
    def holds_object(self) -> bool:
        """Whether the hand holds an object in this world (a path found in it is then checked again at a finer
        step: `segments.CARRY_RESOLUTION_SCALE`)."""
        return self._attached is not None

    @property
    def geom_model(self) -> Any:
        """Pinocchio's geometry model of this world: the arm, the padded obstacles and the held object."""
        return self._meshes()[1]

    def is_valid(self, q: np.ndarray) -> bool:
        """True if q is within joint limits and nothing collides (self, obstacles, attached object)."""
        t = time.perf_counter()
        self.checks += 1
        q = np.asarray(q, dtype=float)
        key = q.tobytes()
        valid = self._seen.get(key)
        if valid is None:
            valid = self._remember(key, self._valid(q))
        self.check_time += time.perf_counter() - t
        return valid

    def _remember(self, key: bytes, valid: bool) -> bool:
        """`valid`, kept as the answer for the state whose bytes are `key` (while there is room)."""
        if len(self._seen) < SEEN_STATES:
            self._seen[key] = valid
        return valid

    def _valid(self, q: np.ndarray) -> bool:
        if self._spheres is not None and q.shape == (self.arm.dof,):
            valid = self._spheres.free(q)  # the joint limits too, in the same compiled call
            # None: within the limits, the held object at its tilt limit to rounding: Pinocchio decides
            return self._free_pinocchio(q) if valid is None else valid
        if not self.arm.within_limits(q):
            return False
        return self._free(q)

    def _free(self, q: np.ndarray) -> bool:
        """True if q (within the joint limits) keeps a carried object upright and nothing collides."""
        if self._spheres is not None:
            free = self._spheres.free(q)
            if free is not None:
                return free
        return self._free_pinocchio(q)

    def _free_pinocchio(self, q: np.ndarray) -> bool:
        """`_free` by Pinocchio's world (an arm without spheres, or a held object at its tilt limit)."""
        import pinocchio as pin

        data, _, _, broadphase = self._meshes()
        if self.min_up is not None:
            pin.forwardKinematics(self.model, data, q)
            up = data.oMi[self._ee_joint].rotation @ self._up_in_joint
            if up[2] < self.min_up:
                return False
        return not pin.computeCollisions(self.model, data, broadphase, q, True)

    def states_valid(self, states: np.ndarray) -> bool:
        """True if every row of the (n, dof) `states` is valid; checked in order, up to the first invalid one.

        The same answers and the same count of checks as `is_valid` on each row in turn, with the joint limits
        tested for all rows at once (a segment's states are checked by the hundred per plan).
        """
        t = time.perf_counter()
        states = np.asarray(states, dtype=float)
        if self._spheres is not None and states.ndim == 2 and states.shape[1] == self.arm.dof:
            valid = self._states_valid_spheres(np.ascontiguousarray(states))
            self.check_time += time.perf_counter() - t
            return valid
        within = np.all((states >= self.arm._lower_tol) & (states <= self.arm._upper_tol), axis=1).tolist()
        valid = True
        for q, ok in zip(states, within, strict=True):
            self.checks += 1
            if not ok:
                valid = False
                break
            key = q.tobytes()
            free = self._seen.get(key)
            if free is None:
                free = self._remember(key, self._free(q))
            if not free:
                valid = False
                break
        self.check_time += time.perf_counter() - t
        return valid

    def _states_valid_spheres(self, states: np.ndarray) -> bool:
        """`states_valid` by the spheres: rows free in one compiled call, GJK (or Pinocchio at a tilt limit) where
        spheres meet; counts a check per row up to the first invalid one."""
        spheres = self._spheres
        assert spheres is not None
        start, n = 0, len(states)
        while True:
            row, free = spheres.first_not_free(states, start)
            if row == n:
                self.checks += n
                return True
            if free is None:  # at the tilt limit to rounding: Pinocchio decides
                free = self._free_pinocchio(states[row])
            if not free:
                self.checks += row + 1
                return False
            start = row + 1

    def colliding_pairs(self, q: np.ndarray) -> list[tuple[str, str]]:
        """Names of the geometry pairs in collision at q (for messages)."""
        if self._spheres is not None:
            return self._spheres.colliding(np.asarray(q, dtype=float))
        import pinocchio as pin

        data, gm, geom_data, _ = self._meshes()
        pin.computeCollisions(self.model, data, gm, geom_data, q, False)
        out = []
        for k, res in enumerate(geom_data.collisionResults):
            if res.isCollision():
                pair = gm.collisionPairs[k]
                out.append((gm.geometryObjects[pair.first].name, gm.geometryObjects[pair.second].name))
        return out

    def segment_valid(self, qa: np.ndarray, qb: np.ndarray, resolution: float = 0.02) -> bool:
        """Check a straight joint-space segment at `resolution` rad spacing (max-norm)."""
        n = max(2, int(np.ceil(np.max(np.abs(qb - qa)) / resolution)) + 1)
        return self.states_valid(interpolated(qa, qb, np.linspace(0.0, 1.0, n)))


class HandModel:
    """The gripper alone (every geometry rigidly attached to the end-effector's joint), checked at a hand pose.

    Grasp filtering uses it before any IK: a pose where the hand itself would collide is dropped for the price
    of a few GJK calls instead of an IK solve, and the colliding obstacles name what blocks the grasp.

    Args:
        arm: The arm model.
        obstacles: Fixed obstacles in the world frame.
        padding: Metres added on every side of every obstacle.
        finger_position: Each finger's position (m from the centre), the hand pre-shaped; None: fully open.
    """

    def __init__(
        self,
        arm: ArmModel,
        obstacles: Sequence[Obstacle],
        padding: float = 0.0,
        finger_position: float | None = None,
    ) -> None:
        import coal

        from scone_bt.motion import compiled

        hand = _hand_parts(arm, finger_position)
        self._parts = hand.parts
        # The hand's reach from the end-effector frame's origin: obstacles farther than this never touch it.
        self._reach = hand.reach
        # Each part's bounding sphere in the end-effector frame: a part whose sphere misses an obstacle's box cannot
        # touch it, so most (part, obstacle) pairs need no GJK call (the answer is the same).
        self._part_centres = hand.centres
        self._part_reach = hand.radii + SPHERE_SLACK
        self._padding = padding
        self._obstacle_list = list(obstacles)
        # An obstacle's coal shape is made the first time the hand comes near it (most never do).
        self._shapes: dict[int, tuple[Any, Any]] = {}
        n = len(self._obstacle_list)
        poses = np.array([ob.pose for ob in self._obstacle_list], dtype=float).reshape(n, 4, 4)
        sizes = np.array([ob.size for ob in self._obstacle_list], dtype=float).reshape(n, 3)
        # Centres and bounding radii: an obstacle farther than the hand's reach is not near.
        self._centres = np.ascontiguousarray(poses[:, :3, 3])
        self._radii = 0.5 * np.sqrt((sizes * sizes).sum(axis=1)) + padding
        # Each padded shape's world-aligned bounding box (around its own box, which bounds a cylinder too): half
        # extents, for the sphere-against-box test that spares most GJK calls.
        halves = sizes / 2 + padding
        self._extents = (np.abs(poses[:, :3, :3]) * halves[:, None, :]).sum(axis=2)
        self._names = [ob.name for ob in self._obstacle_list]
        self._near = np.empty(n, dtype=np.int64)
        self._pairs = np.empty((len(self._parts) * n, 2), dtype=np.int64)
        self._kernel = compiled.hand_candidates
        self._request = coal.CollisionRequest()
        self._coal = coal
        self.checks = 0

    def _shape(self, k: int) -> tuple[Any, Any]:
        """Obstacle k's padded coal geometry and its world transform (made once)."""
        shape = self._shapes.get(k)
        if shape is None:
            ob = self._obstacle_list[k]
            tf = self._coal.Transform3s(ob.pose[:3, :3].copy(), ob.pose[:3, 3].copy())
            shape = self._shapes[k] = (_geometry(ob.shape, ob.size, self._padding), tf)
        return shape

    def colliding(self, ee_pose: np.ndarray, ignore: Sequence[str] = ()) -> list[str]:
        """Names of the obstacles the hand touches with the end-effector frame at `ee_pose` (world (4, 4))."""
        coal = self._coal
        self.checks += 1
        pose = np.ascontiguousarray(ee_pose, dtype=float)
        # The near obstacles, and each part's bounding sphere against each near obstacle's bounding box, in one
        # compiled call; GJK only on the pairs that may touch.
        n = self._kernel(
            pose,
            self._part_centres,
            self._part_reach,
            self._centres,
            self._radii,
            self._extents,
            self._reach,
            self._near,
            self._pairs,
        )
        hits: list[str] = []
        if n == 0:
            return hits
        result = coal.CollisionResult()
        placed, geom, tf = -1, None, None
        for part, k in self._pairs[:n].tolist():
            name = self._names[k]
            if name in hits or name in ignore:
                continue
            if part != placed:
                geom, local = self._parts[part]
                world = pose @ local
                tf = coal.Transform3s(world[:3, :3].copy(), world[:3, 3].copy())
                placed = part
            ogeom, otf = self._shape(k)
            result.clear()
            if coal.collide(geom, tf, ogeom, otf, self._request, result):
                hits.append(name)
        return hits


@dataclass(frozen=True, eq=False)
class _HandParts:
    """The hand's geometries at one finger position: (coal shape, (4, 4) pose in the end-effector frame) each, its
    reach (m) from the end-effector frame's origin, and each part's bounding sphere there ((k, 3), (k,))."""

    parts: list[tuple[Any, np.ndarray]]
    reach: float
    centres: np.ndarray
    radii: np.ndarray


_HANDS: weakref.WeakKeyDictionary[ArmModel, dict[float | None, _HandParts]] = weakref.WeakKeyDictionary()


def _hand_parts(arm: ArmModel, finger_position: float | None) -> _HandParts:
    """The arm's `_HandParts` with its fingers at `finger_position` (made once per position, a few kept)."""
    kept = _HANDS.setdefault(arm, {})
    key = None if finger_position is None else float(finger_position)
    hand = kept.get(key)
    if hand is None:
        ee = arm.model.frames[arm.ee_frame]
        ee_from_joint = np.linalg.inv(ee.placement.homogeneous)
        parts = [
            (g.geometry, ee_from_joint @ g.placement.homogeneous)
            for g in arm.geometry_with_fingers(key).geometryObjects
            if g.parentJoint == arm.ee_joint
        ]
        reach = max((float(np.linalg.norm(p[:3, 3])) + 0.12 for _, p in parts), default=0.3)
        if len(kept) >= POSITIONS_KEPT:
            kept.clear()
        hand = kept[key] = _HandParts(parts, reach, *_bounding_spheres(parts))
    return hand


SPHERE_SLACK = 1e-3
"""Metres added to a part's bounding radius before a pair is skipped (GJK's tolerance is far below it)."""


def _bounding_spheres(parts: Sequence[tuple[Any, np.ndarray]]) -> tuple[np.ndarray, np.ndarray]:
    """(k, 3) centres in the end-effector frame and (k,) radii of spheres around each hand part's geometry."""
    centres, radii = [], []
    for geom, local in parts:
        geom.computeLocalAABB()
        centre = np.asarray(geom.aabb_center, dtype=float)
        centres.append(local[:3, :3] @ centre + local[:3, 3])
        radii.append(float(geom.aabb_radius))
    return np.array(centres, dtype=float).reshape(-1, 3), np.array(radii, dtype=float)
