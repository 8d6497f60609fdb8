"""Joint-space planning with VAMP (adapter): the same scene OMPL plans in, solved by KavrakiLab's SIMD planner.

VAMP (PyPI ``vamp-planner``, built here by ``make vamp``: tools/build_vamp.sh) checks a robot made of spheres
against an environment of primitives, several configurations at once with SIMD instructions. Its Panda model is
built in (``vamp.panda``, end-effector frame ``panda_grasptarget`` as in robots/panda.yaml, base at the origin);
it has no model of the other arms.

The environment is read from a `CollisionWorld`, so VAMP plans around exactly what OMPL's validity checker sees:
every ``obstacle:*`` geometry (already padded by the world) becomes a cuboid (a box as it is, a cylinder as the
box around it, which contains it), grown by `VampOptions.extra_padding`; an ``attached:*`` object (the carried
product) becomes a VAMP attachment made of spheres that cover it. What VAMP cannot express is left to the mesh
check: the carry's tilt limit (`CollisionWorld.min_up`), the project's joint limits where they are narrower than
VAMP's, and the mesh geometry of the links. `mesh_check` re-checks a VAMP path with the project's own checker at
the step OMPL's motion validator uses, and `plan_vamp` reports the answer with the path.

``import vamp`` happens only inside this module's functions; without it they raise `VampUnavailableError`.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from scone_bt.errors import SconeError
from scone_bt.motion.collision import CollisionWorld
from scone_bt.motion.segments import MOTION_RESOLUTION, motion_step, segment_times
from scone_bt.motion.types import PlanResult, PlanStatus

__all__ = [
    "VAMP_ROBOTS",
    "VampOptions",
    "VampPlan",
    "MeshCheck",
    "VampUnavailableError",
    "vamp_available",
    "vamp_environment",
    "plan_vamp",
    "mesh_check",
]

VAMP_ROBOTS = ("panda",)
"""Robot files whose arm VAMP has a model of (the wheel `make vamp` builds holds only the Panda)."""
ATTACHMENT_CELL = 0.025
"""Edge of the cells (m) a carried object is split into; each cell is covered by one sphere (its circumsphere)."""


class VampUnavailableError(SconeError):
    """VAMP is not installed in this environment (``make vamp`` builds it), or has no model of this arm."""


@dataclass(frozen=True)
class VampOptions:
    """Settings of one VAMP query.

    Attributes:
        rng_seed: Seed: how many draws of VAMP's Halton sampler are skipped before the search (the same seed gives
            the same path).
        simplify: Shortcut and smooth the path afterwards (VAMP's default routine: shortcut, B-spline).
        extra_padding: Metres added on every side of every obstacle, on top of the world's own padding (VAMP's
            spheres approximate the links' meshes; a margin buys back the difference: without it half the paths
            of a test query touched the mesh, with 1 cm none). Where the start or every goal lies within that
            margin, the query is planned with the world's own padding instead (`VampPlan.padding` says which).
        max_iterations: RRT-Connect iterations before VAMP gives up.
        resolution: Step of the mesh re-check as a fraction of the joint space's largest extent (L2), as
            `PlannerOptions.resolution` (OMPL's motion validator).
    """

    rng_seed: int = 0
    simplify: bool = True
    extra_padding: float = 0.01
    max_iterations: int = 100_000
    resolution: float = MOTION_RESOLUTION


@dataclass(frozen=True)
class MeshCheck:
    """A path re-checked with the project's mesh collision checker.

    Attributes:
        valid: Every interpolated state is collision-free, within the project's joint limits and (when carrying)
            upright enough.
        states: States checked.
        first_invalid: The first invalid state (dof,), radians, or None.
        why: The colliding pair(s) at that state, "outside the joint limits" or "carried object tilted" (beyond
            the world's `max_tilt`), or "".
    """

    valid: bool
    states: int
    first_invalid: np.ndarray | None = None
    why: str = ""


@dataclass(frozen=True, eq=False)
class VampPlan:
    """One VAMP query and its mesh re-check.

    Attributes:
        result: The plan as OMPL's adapter reports one (status, (N, dof) path in radians, planning_time = wall
            seconds of the start and goal checks, VAMP's search and simplification, message, goal_index).
        environment_s: Wall seconds spent building VAMP's environment from the collision world.
        vamp_ns: Nanoseconds VAMP itself reports for the search plus the simplification.
        iterations: RRT-Connect iterations.
        mesh: The path re-checked with the mesh checker (None when there is no path).
        padding: The extra padding (m) VAMP planned with: `VampOptions.extra_padding`, or 0.0 where the start
            or the goals lay within it.
    """

    result: PlanResult
    environment_s: float
    padding: float = 0.0
    vamp_ns: int = 0
    iterations: int = 0
    mesh: MeshCheck | None = None

    @property
    def success(self) -> bool:
        return self.result.success

    @property
    def mesh_valid(self) -> bool:
        """Solved and the path passes the mesh check."""
        return self.result.success and self.mesh is not None and self.mesh.valid


def _vamp() -> Any:
    try:
        import vamp
    except ImportError as e:
        raise VampUnavailableError(
            f"VAMP is not installed ({e}); build it with `make vamp` (tools/build_vamp.sh)"
        ) from None
    return vamp


def vamp_available() -> bool:
    """True if ``import vamp`` works and has the Panda model."""
    try:
        return hasattr(_vamp(), "panda")
    except VampUnavailableError:
        return False


def _robot(vamp: Any, world: CollisionWorld) -> Any:
    name = world.arm.config.name
    if name not in VAMP_ROBOTS or not hasattr(vamp, name):
        raise VampUnavailableError(
            f"VAMP has no model of the {name!r} arm (it has: {', '.join(VAMP_ROBOTS)})"
        )
    return getattr(vamp, name)


def _euler_xyz(r: np.ndarray) -> list[float]:
    """Angles (rho, theta, phi) with R = Rz(phi) Ry(theta) Rx(rho), the convention of VAMP's factories."""
    r20 = float(r[2, 0])
    theta = math.asin(min(1.0, max(-1.0, -r20)))
    if abs(r20) < 1.0 - 1e-9:
        return [math.atan2(float(r[2, 1]), float(r[2, 2])), theta, math.atan2(float(r[1, 0]), float(r[0, 0]))]
    return [0.0, theta, math.atan2(-float(r[0, 1]), float(r[1, 1]))]  # gimbal lock: the rotation about z


def _half_extents(geometry: Any) -> np.ndarray:
    """Half extents (m) of a coal Box, or of the box around a coal Cylinder (axis along z)."""
    if hasattr(geometry, "halfSide"):
        return np.asarray(geometry.halfSide, dtype=float)
    r, h = float(geometry.radius), float(geometry.halfLength)
    return np.array([r, r, h])


def _cover_spheres(half: np.ndarray, pose: np.ndarray, cell: float) -> list[tuple[np.ndarray, float]]:
    """Spheres covering a box of half extents `half` at `pose` ((4, 4)): one circumsphere per grid cell."""
    n = np.maximum(1, np.ceil(2 * half / cell)).astype(int)
    step = 2 * half / n
    radius = float(np.linalg.norm(step / 2))
    axes = [np.linspace(-h + s / 2, h - s / 2, k) for h, s, k in zip(half, step, n, strict=True)]
    out = []
    for x in axes[0]:
        for y in axes[1]:
            for z in axes[2]:
                out.append((pose[:3, :3] @ np.array([x, y, z]) + pose[:3, 3], radius))
    return out


_BASE_SPHERES: dict[str, np.ndarray] = {}


def _base_spheres(robot: Any) -> np.ndarray:
    """(k, 4) x, y, z, radius of the robot's spheres that no joint moves (its base link), in the base frame."""
    key = robot.__name__
    if key not in _BASE_SPHERES:
        qs = [np.zeros(7), np.full(7, 0.5), np.array([2.0, -1.0, 1.0, -2.0, 1.0, 2.0, 1.0])]
        spheres = [np.array([[s.x, s.y, s.z, s.r] for s in robot.fk(q.astype(np.float32))]) for q in qs]
        fixed = np.all([np.all(np.abs(spheres[0] - o) < 1e-6, axis=1) for o in spheres[1:]], axis=0)
        _BASE_SPHERES[key] = spheres[0][fixed]
    return _BASE_SPHERES[key]


def _below_base(
    centre: np.ndarray, rotation: np.ndarray, half: np.ndarray, base: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Centre and half extents of an upright box cut down to just below the base's spheres, if it holds the base.

    The mesh checker never pairs the base link with obstacles (it cannot move), but VAMP checks every sphere: a
    padded pedestal under the arm overlaps the base's lowest sphere in every configuration. Such a box (upright,
    under the base, touching one of its spheres) keeps its footprint and bottom and loses the top few centimetres.
    """
    if not len(base) or abs(abs(float(rotation[2, 2])) - 1.0) > 1e-6:
        return centre, half
    top, bottom = float(centre[2] + half[2]), float(centre[2] - half[2])
    if top >= float(base[:, 2].max()) or top <= float((base[:, 2] - base[:, 3]).min()):
        return centre, half  # not under the base's centres, or already below its spheres
    local = np.abs((base[:, :3] - centre) @ rotation)
    gap = np.linalg.norm(np.maximum(local - half, 0.0), axis=1)
    touching = (gap < base[:, 3]) & (base[:, 2] > top)
    if not touching.any():
        return centre, half
    new_top = float(np.min(base[:, 2] - base[:, 3])) - 0.001
    if new_top <= bottom:
        return centre, half
    centre = centre.copy()
    centre[2] = (new_top + bottom) / 2
    return centre, np.array([half[0], half[1], (new_top - bottom) / 2])


def vamp_environment(world: CollisionWorld, extra_padding: float = 0.0) -> Any:
    """VAMP's environment holding what `world` checks: its obstacles as cuboids, its carried object attached.

    Poses are read in the arm's base frame (the world's geometry is placed there), which is VAMP's frame. A box
    the arm stands on is cut to just below the base's spheres (`_below_base`).
    """
    vamp = _vamp()
    robot = _robot(vamp, world)
    base = _base_spheres(robot)
    env = vamp.Environment()
    ee = world.model.frames[world.arm.ee_frame]
    ee_from_joint = np.linalg.inv(ee.placement.homogeneous)
    for g in world.geom_model.geometryObjects:
        pose = g.placement.homogeneous
        if g.name.startswith("obstacle:"):
            half = _half_extents(g.geometry) + extra_padding
            centre, half = _below_base(pose[:3, 3], pose[:3, :3], half, base)
            cuboid = vamp.Cuboid(centre.tolist(), _euler_xyz(pose[:3, :3]), half.tolist())
            cuboid.name = g.name
            env.add_cuboid(cuboid)
        elif g.name.startswith("attached:"):
            in_ee = ee_from_joint @ pose  # the object's pose in the end-effector frame
            attachment = vamp.Attachment(np.eye(4, dtype=np.float32))
            for centre, radius in _cover_spheres(_half_extents(g.geometry), in_ee, ATTACHMENT_CELL):
                attachment.add_sphere(vamp.Sphere(centre.tolist(), radius))
            env.attach(attachment)
    return env


def mesh_check(world: CollisionWorld, path: np.ndarray, resolution: float = MOTION_RESOLUTION) -> MeshCheck:
    """Check every segment of `path` with the mesh checker at OMPL's motion-validation step.

    The step is `resolution` x the L2 extent of the arm's joint space, as OMPL's discrete motion validator and
    `plan_joint_path`'s direct check take it.
    """
    arm = world.arm
    step = motion_step(arm.lower, arm.upper, resolution)
    states = 0
    for k, (qa, qb) in enumerate(zip(path[:-1], path[1:], strict=True)):
        for t in segment_times(qa, qb, step)[(1 if k else 0) :]:
            q = qa + (qb - qa) * t
            states += 1
            if not world.is_valid(q):
                pairs = world.colliding_pairs(q)
                why = " / ".join(f"{a} ~ {b}" for a, b in pairs[:2])
                if not why:
                    why = "outside the joint limits" if not arm.within_limits(q) else "carried object tilted"
                return MeshCheck(False, states, q, why)
    return MeshCheck(True, states)


def plan_vamp(
    start: np.ndarray, goal: np.ndarray, world: CollisionWorld, options: VampOptions = VampOptions()
) -> VampPlan:
    """Plan from start to a goal (or to any goal of a (k, dof) goal set) with VAMP RRT-Connect, then mesh-check.

    Start and goals are first checked with VAMP's own model (START_INVALID, GOAL_INVALID as OMPL's adapter
    reports them), with `VampOptions.extra_padding` and, where that leaves no valid start and goal, without it;
    goals VAMP finds invalid are left out of the goal set.

    Raises:
        VampUnavailableError: vamp is not installed, or has no model of the world's arm.
    """
    vamp = _vamp()
    robot = _robot(vamp, world)
    start = np.asarray(start, dtype=float)
    goals = np.atleast_2d(np.asarray(goal, dtype=float))
    f32 = np.float32
    env_s = 0.0
    for padding in dict.fromkeys((float(options.extra_padding), 0.0)):
        t0 = time.perf_counter()
        env = vamp_environment(world, padding)
        env_s += time.perf_counter() - t0
        t1 = time.perf_counter()
        start_ok = bool(robot.validate(start.astype(f32), env, True))
        valid = (
            [i for i, g in enumerate(goals) if robot.validate(g.astype(f32), env, True)] if start_ok else []
        )
        check_s = time.perf_counter() - t1
        if valid:
            break

    def fail(status: PlanStatus, why: str, t: float, **kw: Any) -> VampPlan:
        return VampPlan(PlanResult(status, None, t, f"VAMP: {why}"), env_s, padding, **kw)

    if not start_ok:
        return fail(PlanStatus.START_INVALID, "start configuration is in collision", check_s)
    if not valid:
        what = "goal configuration is" if len(goals) == 1 else f"all {len(goals)} goal configurations are"
        return fail(PlanStatus.GOAL_INVALID, f"{what} in collision", check_s)
    settings = vamp.RRTCSettings()
    settings.range = float(getattr(vamp, "ROBOT_RRT_RANGES", {}).get(world.arm.config.name, settings.range))
    settings.max_iterations = int(options.max_iterations)
    settings.max_samples = int(options.max_iterations)
    rng = robot.halton()
    rng.reset()
    rng.skip(int(options.rng_seed) % 1_000_003 * 97)
    t1 = time.perf_counter()
    targets = [goals[i].astype(f32) for i in valid]
    planned = robot.rrtc(start.astype(f32), targets[0] if len(targets) == 1 else targets, env, settings, rng)
    ns, iterations = int(planned.nanoseconds), int(planned.iterations)
    if not planned.solved:
        return fail(
            PlanStatus.TIMED_OUT,
            f"RRT-Connect found no path in {iterations} iterations",
            check_s + time.perf_counter() - t1,
            vamp_ns=ns,
            iterations=iterations,
        )
    path = planned.path
    if options.simplify:
        simplified = robot.simplify(path, env, vamp.SimplifySettings(), rng)
        ns += int(simplified.nanoseconds)
        path = simplified.path
    solve_s = check_s + time.perf_counter() - t1
    points = np.asarray(path.numpy(), dtype=float).reshape(-1, len(start))
    k = int(np.argmin(np.max(np.abs(goals[valid] - points[-1]), axis=1)))
    index = valid[k]
    points[0], points[-1] = start, goals[index]  # VAMP works in float32
    result = PlanResult(PlanStatus.SUCCESS, points, solve_s, f"VAMP rrtc: {len(points)} waypoints", index)
    return VampPlan(result, env_s, padding, ns, iterations, mesh_check(world, points, options.resolution))
