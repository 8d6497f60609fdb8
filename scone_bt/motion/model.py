"""The arm's kinematic and collision model (Pinocchio + coal adapter), built from a robot YAML.

The gripper joints are locked at their open position, so the model has exactly the arm's degrees of freedom; a
collision model with the fingers pre-shaped to a narrower opening is `ArmModel.geometry_with_fingers`.
Self-collision pairs between adjacent links and pairs listed under `collision.disabled_pairs` in the YAML (links
that can never touch, found offline by sampling) are not checked.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from scone_bt.config import RobotConfig
from scone_bt.errors import ConfigError, UnknownNameError

__all__ = [
    "FINGER_MODELS_KEPT",
    "ArmModel",
    "IKOptions",
    "IKSolution",
    "LIMIT_OVERSHOOT_RAD",
    "inverse_small",
    "pose_matrix",
    "solve_small",
]


def _gufunc(name: str) -> Any | None:
    """numpy's own LAPACK gufunc behind `np.linalg.<name>` (None where this numpy has no such private module)."""
    try:
        from numpy.linalg import _umath_linalg
    except ImportError:  # pragma: no cover - a numpy without the private module: the public functions
        return None
    return getattr(_umath_linalg, name, None)


FINGER_MODELS_KEPT = 64
"""Finger positions whose collision-model template an `ArmModel` keeps (as `spheres.POSITIONS_KEPT`)."""
LIMIT_OVERSHOOT_RAD = 0.01
"""How far past a joint limit a measured joint may read and still be taken at the limit (`ArmModel.as_measured`),
radians: a joint driven to its limit overshoots it by a few hundredths of a milliradian in the physics."""
_SOLVE = _gufunc("solve")
_INV = _gufunc("inv")


def solve_small(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """`np.linalg.solve(a, b)` for float64 (n, n) and (n, k), the same LAPACK call without its argument checks.

    IK solves one 6x6 system per iteration: numpy's checks and error-state set-up took twice as long as the
    solve itself. The caller guarantees a non-singular `a` (IK's damping); the result is bit-identical.
    """
    if _SOLVE is None:  # pragma: no cover
        return np.linalg.solve(a, b)
    return _SOLVE(a, b, signature="dd->d")


def inverse_small(a: np.ndarray) -> np.ndarray:
    """`np.linalg.inv(a)` for a non-singular float64 square matrix (a pose), the same LAPACK call, bit-identical."""
    if _INV is None:  # pragma: no cover
        return np.linalg.inv(a)
    return _INV(a, signature="d->d")


def pose_matrix(rotation: np.ndarray, translation: Sequence[float]) -> np.ndarray:
    """A (4, 4) homogeneous transform from a (3, 3) rotation and a translation in metres."""
    out = np.eye(4)
    out[:3, :3] = rotation
    out[:3, 3] = translation
    return out


@dataclass(frozen=True)
class IKOptions:
    """Damped least-squares IK settings.

    Attributes:
        max_iterations: Iterations per seed.
        restarts: Extra random seeds tried after the given one.
        position_tolerance: Metres.
        rotation_tolerance: Radians.
        damping: Levenberg-Marquardt damping (unitless).
        step: Fraction of the Newton step taken per iteration.
        posture_gain: Pull towards the seed in the null space (per iteration, unitless).
        stall_iterations: A seed is abandoned after this many iterations without a 2% improvement.
    """

    max_iterations: int = 150
    restarts: int = 12
    position_tolerance: float = 1e-3
    rotation_tolerance: float = 1e-2
    damping: float = 1e-4
    step: float = 1.0
    posture_gain: float = 0.05
    stall_iterations: int = 20


@dataclass(frozen=True, eq=False)
class IKSolution:
    """An IK answer: joint positions (rad) and the final position (m) and rotation (rad) errors."""

    q: np.ndarray
    position_error: float
    rotation_error: float


class ArmModel:
    """Pinocchio kinematics and coal collision geometry of one arm, with its gripper fixed open.

    Args:
        robot: The robot file's contents.
    """

    def __init__(self, robot: RobotConfig) -> None:
        import pinocchio as pin

        self.config = robot
        try:
            # Collision geometry only: the visual meshes (the Panda's 116k triangles) took 1 s to load, unused.
            full, full_geom = pin.buildModelsFromUrdf(
                str(robot.urdf),
                package_dirs=[str(robot.urdf.parent)],
                geometry_types=pin.GeometryType.COLLISION,
            )
        except (RuntimeError, ValueError) as exc:
            raise ConfigError(f"{robot.source}: Pinocchio could not load {robot.urdf} ({exc})") from None
        names = list(full.names)
        for joint in (*robot.arm_joints, *robot.gripper.joints):
            if joint not in names:
                raise UnknownNameError("joint", joint, names[1:])
        q_ref = pin.neutral(full)
        lock = []
        for i in range(1, full.njoints):
            name = full.names[i]
            if name in robot.gripper.joints:
                q_ref[full.idx_qs[i]] = robot.gripper.open_position
                lock.append(i)
            elif name not in robot.arm_joints:
                lock.append(i)
        self.model, self.geom_model = pin.buildReducedModel(full, full_geom, lock, q_ref)
        self._convexify()
        finger_joints = {full.getJointId(j) for j in robot.gripper.joints}
        finger_links = {
            f.name for f in full.frames if f.type.name == "BODY" and f.parentJoint in finger_joints
        }
        arm_order = [self.model.names[i] for i in range(1, self.model.njoints)]
        if arm_order != list(robot.arm_joints):
            raise ConfigError(
                f"{robot.source}: arm_joints must list the chain's joints in order: {', '.join(arm_order)}"
            )
        if not self.model.existFrame(robot.end_effector_frame):
            raise UnknownNameError("frame", robot.end_effector_frame, [f.name for f in self.model.frames])
        self.ee_frame = self.model.getFrameId(robot.end_effector_frame)
        self.ee_joint = self.model.frames[self.ee_frame].parentJoint
        self._local = threading.local()
        self._finger_models: dict[float | None, Any] = {}  # by finger position; bound: FINGER_MODELS_KEPT
        self.lower = np.array(self.model.lowerPositionLimit, dtype=float)
        self.upper = np.array(self.model.upperPositionLimit, dtype=float)
        self._lower_tol, self._upper_tol = self.lower - 1e-9, self.upper + 1e-9
        self._lower_list, self._upper_list = self._lower_tol.tolist(), self._upper_tol.tolist()
        self.dof = self.model.nq
        self._eye6, self._eye_dof = np.eye(6), np.eye(self.dof)  # IK's, read-only (made once, not per solve)
        # The joints as the compiled kernels read them (`motion.compiled`); None: a joint they do not model.
        self.chain = _revolute_chain(self.model)
        self._ee_in_joint = np.asarray(self.model.frames[self.ee_frame].placement.homogeneous, dtype=float)
        self.robot_geometry = [g.name for g in self.geom_model.geometryObjects]
        self.link_of_geometry = {
            g.name: self.model.frames[g.parentFrame].name for g in self.geom_model.geometryObjects
        }
        self.disabled_pairs = self._disabled_link_pairs(full)
        self.shoulder, self.reach = self._reach_bound()
        # Finger geometries and the side of the closing axis (end-effector y) each sits on, for pre-shaping.
        ee_from_joint = np.linalg.inv(self.model.frames[self.ee_frame].placement.homogeneous)
        self.finger_geometry: dict[int, float] = {}
        for k, g in enumerate(self.geom_model.geometryObjects):
            if self.link_of_geometry[g.name] in finger_links and g.parentJoint == self.ee_joint:
                y = float((ee_from_joint @ g.placement.homogeneous)[1, 3])
                self.finger_geometry[k] = 1.0 if y >= 0 else -1.0
        # Fixed for the arm's lifetime; every collision world of every plan uses them.
        self.self_pairs = np.array(self._self_collision_pairs(), dtype=int).reshape(-1, 2)
        self.gripper_links = frozenset(
            f.name for f in self.model.frames if f.parentJoint == self.ee_joint and f.type.name == "BODY"
        )
        self.geometry_reach = self._geometry_reach()
        # The tighter bound the collision worlds prune their pairs with (see `_reach_around_first_joint`).
        self.first_joint_origin, self.geometry_reach_from_first_joint = self._reach_around_first_joint()
        # Per robot geometry (in geom_model's order, which every collision world keeps): does it move (the base
        # sits on the pedestal), and is it part of the hand (which may touch what it grasps)?
        links = [self.link_of_geometry[g.name] for g in self.geom_model.geometryObjects]
        hand_links = set(robot.hand_links) | self.gripper_links
        self.moving_geometry = np.array([link != links[0] for link in links])
        self.hand_geometry = np.array([link in hand_links for link in links])

    def geometry_with_fingers(self, position: float | None) -> Any:
        """A copy of the collision model with each finger at `position` (m from centre, like the gripper joints).

        None (or the open position) gives the model as loaded, fingers fully open. The fingers move along the
        end-effector's y axis, the closing axis of every robot's end-effector frame.
        """
        key = None if position is None else float(position)
        template = self._finger_models.get(key)
        if template is None:
            if len(self._finger_models) >= FINGER_MODELS_KEPT:
                self._finger_models.clear()
            template = self._finger_models[key] = self._fingers_at(key)
        # A copy for the caller to add to; the template (moved fingers and all) is made once per position.
        return template.copy()

    def _fingers_at(self, position: float | None) -> Any:
        """`geometry_with_fingers(position)` made afresh."""
        import pinocchio as pin

        gm = self.geom_model.copy()
        if position is None:
            return gm
        shift = float(position) - self.config.gripper.open_position
        if abs(shift) < 1e-9:
            return gm
        ee_in_joint = self.model.frames[self.ee_frame].placement
        for k, side in self.finger_geometry.items():
            g = gm.geometryObjects[k]
            offset = pin.SE3(np.eye(3), ee_in_joint.rotation @ np.array([0.0, side * shift, 0.0]))
            g.placement = pin.SE3(offset.homogeneous @ g.placement.homogeneous)
        return gm

    def _reach_bound(self) -> tuple[np.ndarray, float]:
        """The shoulder (second joint's origin, world frame) and an upper bound of its distance to the end-effector.

        The distances between successive joint origins do not depend on q, so their sum bounds the reach: a pose
        farther than that from the shoulder needs no IK to be rejected.
        """
        import pinocchio as pin

        data = self.model.createData()
        pin.framesForwardKinematics(self.model, data, pin.neutral(self.model))
        points = [
            np.asarray(data.oMi[j].translation)
            for j in range(min(2, self.model.njoints - 1), self.model.njoints)
        ]
        points.append(np.asarray(data.oMf[self.ee_frame].translation))
        reach = float(sum(np.linalg.norm(b - a) for a, b in zip(points[:-1], points[1:], strict=True)))
        return points[0] + np.asarray(self.config.base_position), reach

    def _geometry_reach(self) -> np.ndarray:
        """Per robot geometry, an upper bound (m) of the distance of any of its points from the model's origin.

        A joint's origin is its parent's origin plus a fixed offset turned by the joints before it, so its
        distance from the origin is at most the sum of the offsets' lengths along the chain, whatever q; the
        geometry's own bounding sphere (centre and radius in its joint's frame) adds to that. An obstacle
        farther than this (plus its own radius) can never touch the geometry, so no collision pair is needed.
        """
        return self._reach_from(0)

    def _reach_around_first_joint(self) -> tuple[np.ndarray, np.ndarray]:
        """The first joint's origin (model frame) and, per robot geometry, a bound (m) of its distance from it.

        No joint moves the first joint's origin, so a bound measured from there leaves out the first offset (the
        Panda's 0.33 m column) that `geometry_reach` counts from the model's origin: a fifth fewer collision pairs
        with the kitchen's obstacles, each of which costs its functor when a world is built. Where some joint
        does not descend from the first, the bound from the model's origin is kept.
        """
        model = self.model
        if model.njoints < 2 or any(model.parents[j] < 1 for j in range(2, model.njoints)):
            return np.zeros(3), self.geometry_reach.copy()
        return np.asarray(model.jointPlacements[1].translation, dtype=float), self._reach_from(1)

    def _reach_from(self, joint: int) -> np.ndarray:
        """Per robot geometry, a bound (m) of its distance from the origin of ``joint`` (0: the model's origin),
        whatever q, for a model whose joints after ``joint`` all descend from it (see `_geometry_reach`)."""
        model = self.model
        centre = np.asarray(model.jointPlacements[joint].translation, dtype=float) if joint else np.zeros(3)
        origin = np.zeros(model.njoints)  # a bound of each joint's origin's distance from ``joint``'s
        for j in range(joint + 1, model.njoints):
            origin[j] = origin[model.parents[j]] + float(np.linalg.norm(model.jointPlacements[j].translation))
        out = np.empty(self.geom_model.ngeoms)
        for k, g in enumerate(self.geom_model.geometryObjects):
            geom = g.geometry
            geom.computeLocalAABB()
            local = g.placement.act(np.asarray(geom.aabb_center, dtype=float))
            if g.parentJoint < joint:  # fixed with respect to ``joint``'s origin: its own distance
                out[k] = float(np.linalg.norm(local - centre)) + float(geom.aabb_radius)
            else:
                out[k] = origin[g.parentJoint] + float(np.linalg.norm(local)) + float(geom.aabb_radius)
        # A pre-shaped finger stands at most the whole stroke inwards of where it was loaded.
        stroke = abs(self.config.gripper.open_position - self.config.gripper.closed_position)
        for k in self.finger_geometry:
            out[k] += stroke
        return out

    def can_reach(self, position: Sequence[float] | np.ndarray, margin: float = 0.0) -> bool:
        """False if the point (world, metres) is certainly beyond the end-effector's reach."""
        return float(np.linalg.norm(np.asarray(position) - self.shoulder)) <= self.reach + margin

    def _convexify(self) -> None:
        """Replace link meshes by their convex hulls: GJK on hulls is several times faster than BVH traversal,
        and a hull only ever over-approximates the link (conservative for planning)."""
        for geom in self.geom_model.geometryObjects:
            mesh = geom.geometry
            if hasattr(mesh, "buildConvexHull") and mesh.num_vertices > 0:
                mesh.buildConvexHull(False, "Qt")
                geom.geometry = mesh.convex

    @property
    def data(self) -> Any:
        """Pinocchio workspace of the calling thread (planning runs in a worker while the main thread reads FK)."""
        data = getattr(self._local, "data", None)
        if data is None:
            data = self._local.data = self.model.createData()
        return data

    # ------------------------------------------------------------------------------------------ kinematics
    def clamp(self, q: np.ndarray) -> np.ndarray:
        """q within the joint limits (np.clip's values; its argument handling cost more than the clamp)."""
        return np.minimum(np.maximum(q, self.lower), self.upper)

    def as_measured(self, q: np.ndarray) -> np.ndarray:
        """Measured joints ``q`` as a plan may start from them: a joint read past its limit by no more than
        `LIMIT_OVERSHOOT_RAD` (the physics lets a joint driven to its limit overshoot it a little) is taken at the
        limit; farther past, ``q`` is returned as read (a start the planner refuses). Without this, a wrist left
        6e-5 rad past its limit by a slip made every later plan, and the way home, fail at the start."""
        q = np.asarray(q, dtype=float)
        if bool(((q >= self.lower - LIMIT_OVERSHOOT_RAD) & (q <= self.upper + LIMIT_OVERSHOOT_RAD)).all()):
            return self.clamp(q)
        return q

    def within_limits(self, q: np.ndarray, tol: float = 1e-9) -> bool:
        # Called for every validity check: against the tolerance-widened limits, cached as floats (a comparison
        # of seven plain floats costs a third of three numpy operations on (7,) arrays; NaN fails either way).
        if tol != 1e-9:
            return bool(((q >= self.lower - tol) & (q <= self.upper + tol)).all())
        values = q.tolist() if isinstance(q, np.ndarray) else list(q)
        if len(values) != self.dof:  # numpy's broadcasting rules (and errors) for anything else
            return bool(((q >= self._lower_tol) & (q <= self._upper_tol)).all())
        return all(
            lo <= v <= hi for lo, v, hi in zip(self._lower_list, values, self._upper_list, strict=True)
        )

    def fk(self, q: np.ndarray, frame: str | None = None) -> np.ndarray:
        """World (4, 4) pose of a frame (default: the end-effector frame) at joint positions q (rad)."""
        import pinocchio as pin

        fid = self.ee_frame if frame is None else self.model.getFrameId(frame)
        data = self.data
        pin.framesForwardKinematics(self.model, data, np.asarray(q, dtype=float))
        return self._with_base(data.oMf[fid].homogeneous)

    def _with_base(self, pose: np.ndarray) -> np.ndarray:
        out = pose.copy()
        out[:3, 3] += np.asarray(self.config.base_position)
        return out

    def ik(
        self,
        target: np.ndarray,
        seed: np.ndarray,
        rng: np.random.Generator,
        options: IKOptions = IKOptions(),
    ) -> IKSolution | None:
        """Joint positions that put the end-effector frame at `target` (world 4x4), within joint limits.

        Tries the seed first, then `options.restarts` random seeds drawn from `rng`. Returns None if none converged.
        The search runs compiled (`motion.compiled.ik_search`, about 1.4 us an iteration) where the arm's joints
        all turn about one of their frame's axes (`chain`), else with Pinocchio's kinematics from Python; both
        take the same steps, to rounding.
        """
        goal = target.copy()
        goal[:3, 3] -= np.asarray(self.config.base_position)
        seeds = np.empty((1 + options.restarts, self.dof))
        seeds[0] = self.clamp(np.asarray(seed, dtype=float))
        # The random seeds in one draw: the same numbers, in the same order, as one draw per seed. (A draw of none
        # takes no number from rng but costs as much as a draw of seven: skipped.)
        if options.restarts:
            seeds[1:] = rng.uniform(self.lower, self.upper, size=(options.restarts, self.dof))
        if self.chain is not None:
            return self._ik_compiled(goal, seeds, options, self.chain)
        return self._ik_pinocchio(goal, list(seeds), options)

    def _ik_compiled(
        self,
        goal: np.ndarray,
        seeds: np.ndarray,
        options: IKOptions,
        chain: tuple[np.ndarray, np.ndarray, np.ndarray],
    ) -> IKSolution | None:
        """`ik` by the compiled kernel (`motion.compiled.ik_search`) on ``chain`` (`self.chain`): the same steps,
        1.4 us an iteration (~50 us from Python with Pinocchio; 200 solves 44.6 -> 7.7 ms)."""
        from scone_bt.motion.compiled import ik_search

        parents, placements, axes = chain
        settings = np.array(
            [
                options.max_iterations,
                options.position_tolerance,
                options.rotation_tolerance,
                options.damping,
                options.step,
                options.posture_gain,
                options.stall_iterations,
            ],
            dtype=float,
        )
        out = np.empty(self.dof + 2)
        args = (
            self.lower,
            self.upper,
            parents,
            placements,
            axes,
            self.ee_joint,
            self._ee_in_joint,
            settings,
            out,
        )
        if not ik_search(goal, seeds, *args):
            return None
        return IKSolution(out[: self.dof].copy(), float(out[self.dof]), float(out[self.dof + 1]))

    def _ik_pinocchio(
        self, goal: np.ndarray, seeds: list[np.ndarray], options: IKOptions
    ) -> IKSolution | None:
        """`ik` with Pinocchio's kinematics, for a chain the compiled kernel does not model."""
        import pinocchio as pin

        oMgoal = pin.SE3(goal[:3, :3], goal[:3, 3])
        data = self.data
        damping = options.damping * self._eye6
        identity = self._eye_dof
        rhs = np.empty((6, 1 + self.dof))  # [err | jac], the right-hand sides of one damped solve
        lower, upper = self.lower, self.upper
        # Names looked up once: an iteration is a dozen short calls, and attribute look-ups were a tenth of it.
        model, frame, local = self.model, self.ee_frame, pin.LOCAL
        joint_jacobians, frame_placement, frame_jacobian = (
            pin.computeJointJacobians,
            pin.updateFramePlacement,
            pin.getFrameJacobian,
        )
        log6, jlog6 = pin.log6, pin.Jlog6
        pos_tol, rot_tol, stall = (
            options.position_tolerance,
            options.rotation_tolerance,
            options.stall_iterations,
        )
        gain, step = options.posture_gain, options.step
        for q0 in seeds:
            q = q0.copy()
            best, since_best = np.inf, 0
            for _ in range(options.max_iterations):
                # One kinematics pass gives both the pose and the Jacobian (computeFrameJacobian would redo it).
                joint_jacobians(model, data, q)
                current = frame_placement(model, data, frame)
                i_m_goal = current.actInv(oMgoal)
                err = log6(i_m_goal).vector  # twist to the goal, in the end-effector frame
                # Plain floats: six numpy scalar operations cost more than the kinematics pass (same values).
                e0, e1, e2, e3, e4, e5 = err.tolist()
                pos_err = math.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
                rot_err = math.sqrt(e3 * e3 + e4 * e4 + e5 * e5)
                if pos_err < pos_tol and rot_err < rot_tol:
                    return IKSolution(q, pos_err, rot_err)
                # Give up on a seed that stopped improving (unreachable target or stuck at a joint limit).
                total = pos_err + 0.1 * rot_err
                if total < 0.98 * best:
                    best, since_best = total, 0
                else:
                    since_best += 1
                    if since_best > stall:
                        break
                jac = jlog6(i_m_goal.inverse()) @ frame_jacobian(model, data, frame, local)
                rhs[:, 0] = err
                rhs[:, 1:] = jac
                solved = solve_small(jac @ jac.T + damping, rhs)
                # Redundancy: drift towards the seed in the null space, so nearby targets get nearby solutions.
                dq = jac.T @ solved[:, 0] + (identity - jac.T @ solved[:, 1:]) @ (gain * (q0 - q))
                # np.abs(dq).max() for a finite step, at a fifth of the cost (a NaN step leaves q NaN either way)
                norm = max(map(abs, dq.tolist()))
                if norm > 0.5:  # small steps keep the solution on the seed's branch
                    dq *= 0.5 / norm
                if step != 1.0:  # a full step: dq itself (1.0 * dq is dq, bit for bit)
                    dq = step * dq
                q = np.minimum(np.maximum(q + dq, lower), upper)
        return None

    # ------------------------------------------------------------------------------------------ collisions
    def _disabled_link_pairs(self, full: Any) -> set[frozenset[str]]:
        """Link pairs never checked: parent/child links plus the YAML's `collision.disabled_pairs`."""
        pairs: set[frozenset[str]] = set()
        model = full
        links_of_joint: dict[int, list[str]] = {}
        for frame in model.frames:
            if frame.type.name == "BODY":
                links_of_joint.setdefault(frame.parentJoint, []).append(frame.name)
        for j in range(1, model.njoints):
            parent = model.parents[j]
            for a in links_of_joint.get(parent, []):
                for b in links_of_joint.get(j, []):
                    pairs.add(frozenset((a, b)))
        # Links rigidly attached to the same joint cannot move relative to each other.
        for links in links_of_joint.values():
            for a in links:
                for b in links:
                    if a != b:
                        pairs.add(frozenset((a, b)))
        known = {f.name for f in model.frames}
        for a, b in self.config.disabled_collisions:
            for link in (a, b):
                if link not in known:
                    links = sorted(n for names in links_of_joint.values() for n in names)
                    raise UnknownNameError("link in collision.disabled_pairs", link, links)
            pairs.add(frozenset((a, b)))
        return pairs

    def self_collision_pairs(self) -> list[tuple[int, int]]:
        """Index pairs of robot geometries to check against each other."""
        return [(int(i), int(j)) for i, j in self.self_pairs]

    def _self_collision_pairs(self) -> list[tuple[int, int]]:
        out = []
        geoms = self.geom_model.geometryObjects
        for i in range(len(geoms)):
            for j in range(i + 1, len(geoms)):
                a, b = self.link_of_geometry[geoms[i].name], self.link_of_geometry[geoms[j].name]
                if a == b or frozenset((a, b)) in self.disabled_pairs:
                    continue
                out.append((i, j))
        return out


_REVOLUTE_AXES = {
    "JointModelRX": (1.0, 0.0, 0.0),
    "JointModelRY": (0.0, 1.0, 0.0),
    "JointModelRZ": (0.0, 0.0, 1.0),
}


def _revolute_chain(model: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """(parents, placements (nj, 4, 4), axes (nj, 3)) of a model whose joints all turn about one of their frame's
    axes, joint j driven by q[j - 1] (`motion.compiled`'s chain); None for any other model."""
    nj = model.njoints
    axes = np.zeros((nj, 3))
    for j in range(1, nj):
        joint = model.joints[j]
        axis = _REVOLUTE_AXES.get(joint.shortname())
        if axis is None or joint.idx_q != j - 1 or joint.nq != 1:
            return None
        axes[j] = axis
    parents = np.array([max(int(model.parents[j]), 0) for j in range(nj)], dtype=np.int64)
    placements = np.array([model.jointPlacements[j].homogeneous for j in range(nj)], dtype=float)
    return parents, placements, axes
