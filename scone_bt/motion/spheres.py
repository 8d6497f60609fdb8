"""Spheres around the arm: the broad phase of a collision world's checks, before coal's GJK.

Every robot geometry (a link's convex hull, or a primitive) is enclosed in a few spheres, cut across its principal
axis (`cover_points`), and in one sphere around those. At a state, the compiled kernel (`compiled.pair_candidates`)
places the spheres and keeps the pairs whose spheres meet the other side (another geometry's spheres, a padded
obstacle's box or cylinder, the held object's box); of two robot geometries whose spheres meet, it drops those
whose hulls it proves apart by a distance bound (`compiled.hulls_apart`: the Panda's wrist links, a few
centimetres apart with the wrist folded, meet by their spheres in one state in four). Only the pairs left reach
coal's GJK, on the same shapes the Pinocchio world holds. A pair whose spheres do not meet, or whose hulls are
proven apart, cannot collide, so the answer is the meshes' answer: the spheres and the bound only spare the checks
of what is certainly apart (most pairs of most states), and each world the ~0.3 ms Pinocchio took to make a
collision functor for each of its ~220 pairs.

Arrays are packed for the kernel (`compiled`'s layouts) once per arm and finger position (`ArmSpheres`) and once
per collision world (`SphereChecks`).
"""

from __future__ import annotations

import math
import weakref
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from scone_bt.config.catalogue import Shape
from scone_bt.motion.kernel_layout import ARM_F, ARM_I, WORK, WORLD_F, WORLD_I
from scone_bt.motion.pair_kinds import PAIR_HELD, PAIR_OBSTACLE, PAIR_ROBOT

__all__ = [
    "MAX_SPHERES",
    "POSITIONS_KEPT",
    "Obstacles",
    "SPHERE_SLACK_M",
    "ArmSpheres",
    "SphereChecks",
    "arm_spheres",
    "cover_points",
]

SPHERE_SLACK_M = 1e-4
"""Metres added to every sphere and to the held object's box: GJK's tolerance (1e-6) lies far below it."""
MAX_SPHERES = 8
"""Most spheres around one geometry."""


def cover_points(points: np.ndarray, extra: float = 0.0) -> list[tuple[np.ndarray, float]]:
    """Spheres (centre, radius) that together enclose the convex hull of `points` (n, 3), grown by `extra`.

    The hull is cut into slices across its principal axis. A slice of the hull is the convex hull of the points
    inside the slice and of the points where a segment between two points crosses one of its two planes (each such
    segment lies in the hull, and the hull's edges are among them), so the sphere around those points holds the
    slice. Slices about as long as the hull is wide keep the spheres close to it.
    """
    pts = np.asarray(points, dtype=float).reshape(-1, 3)
    _, _, vt = np.linalg.svd(pts - pts.mean(axis=0), full_matrices=False)
    along = pts @ vt[0]
    lo, hi = float(along.min()), float(along.max())
    width = max(float(np.ptp(pts @ vt[1])), 1e-3)
    n = int(min(MAX_SPHERES, max(1, math.ceil((hi - lo) / width))))
    cuts = np.linspace(lo, hi, n + 1)
    i, j = np.triu_indices(len(pts), 1)
    ta, tb = along[i], along[j]
    spheres = []
    for k in range(n):
        a, b = cuts[k], cuts[k + 1]
        inside = [pts[(along >= a) & (along <= b)]]
        for plane in (a, b):
            crossing = (np.minimum(ta, tb) < plane) & (np.maximum(ta, tb) > plane)
            f = (plane - ta[crossing]) / (tb[crossing] - ta[crossing])
            inside.append(pts[i[crossing]] + (pts[j[crossing]] - pts[i[crossing]]) * f[:, None])
        piece = np.concatenate(inside)
        if len(piece):
            centre = 0.5 * (piece.min(axis=0) + piece.max(axis=0))
            radius = float(np.sqrt(((piece - centre) ** 2).sum(axis=1)).max())
            spheres.append((centre, radius + extra))
    return spheres


def _cover_geometry(geom: Any, placement: np.ndarray) -> list[tuple[np.ndarray, float]] | None:
    """Spheres around one coal geometry placed at `placement` (4x4) in its joint's frame; None: a shape without."""
    swept = getattr(geom, "getSweptSphereRadius", None)
    extra = float(swept()) if swept is not None else 0.0
    kind = type(geom).__name__
    if kind.startswith("Convex"):
        local = np.asarray(geom.points(), dtype=float).reshape(-1, 3)
    elif kind == "Box":
        hx, hy, hz = (float(v) for v in geom.halfSide)
        local = np.array([[sx * hx, sy * hy, sz * hz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    elif kind == "Sphere":
        return [(placement[:3, 3].copy(), float(geom.radius) + extra)]
    elif kind in ("Cylinder", "Capsule"):
        radius, half = float(geom.radius), float(geom.halfLength)
        if kind == "Capsule":
            half += radius  # its end caps lie inside the longer cylinder
        # Slices of the cylinder itself (rim points would not hold its curved side).
        n = int(min(MAX_SPHERES, max(1, math.ceil(2 * half / max(2 * radius, 1e-3)))))
        h = half / n
        big = math.sqrt(radius * radius + h * h) + extra
        axis, origin = placement[:3, 2], placement[:3, 3]
        return [(origin + axis * (-half + h * (2 * k + 1)), big) for k in range(n)]
    else:
        return None
    return cover_points(local @ placement[:3, :3].T + placement[:3, 3], extra)


def _hull_vertices(geom: Any) -> np.ndarray:
    """(k, 3) points in the geometry's frame whose convex hull is the shape (its swept sphere aside): a convex
    mesh's vertices, a box's corners; (0, 3) for a curved shape (the kernel leaves its pairs to coal)."""
    kind = type(geom).__name__
    if kind.startswith("Convex"):
        return np.asarray(geom.points(), dtype=float).reshape(-1, 3)
    if kind == "Box":
        hx, hy, hz = (float(v) for v in geom.halfSide)
        return np.array([[sx * hx, sy * hy, sz * hz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    return np.zeros((0, 3))


@dataclass(frozen=True, eq=False)
class ArmSpheres:
    """The arm's spheres and geometry with the fingers at one position, packed for `compiled.pair_candidates`.

    Attributes:
        arm_f, arm_i: The arm's packed floats and ints (`compiled`'s layouts).
        shapes: Each robot geometry's coal shape (the collision model's own).
        placements: (g, 4, 4) each robot geometry in its joint's frame (m).
        joints: (g,) each robot geometry's joint.
        names: Each robot geometry's name.
        n_joints: Joints of the chain, the universe included.
        n_spheres: Spheres in all.
    """

    arm_f: np.ndarray
    arm_i: np.ndarray
    shapes: tuple[Any, ...]
    placements: np.ndarray
    joints: np.ndarray
    names: tuple[str, ...]
    n_joints: int
    n_spheres: int


@dataclass(frozen=True, eq=False)
class _Cover:
    """Spheres of the open hand: centre (s, 3) in their joint's frame, radius (s,), joint (s,), and per robot
    geometry its first sphere and count."""

    centre: np.ndarray
    radius: np.ndarray
    joint: np.ndarray
    first: np.ndarray
    count: np.ndarray


_OPEN: weakref.WeakKeyDictionary[Any, _Cover | None] = weakref.WeakKeyDictionary()
_BY_POSITION: weakref.WeakKeyDictionary[Any, dict[float | None, ArmSpheres]] = weakref.WeakKeyDictionary()
POSITIONS_KEPT = 64
"""Finger positions whose `ArmSpheres` an arm keeps (each plan pre-shapes the hand to its own)."""


def arm_spheres(arm: Any, finger_position: float | None) -> ArmSpheres | None:
    """The arm's `ArmSpheres` with its fingers at `finger_position` (m, as `ArmModel.geometry_with_fingers`);
    None where the arm has no compiled chain or a geometry's shape has no cover (the world asks Pinocchio)."""
    if getattr(arm, "chain", None) is None:
        return None
    if arm not in _OPEN:
        _OPEN[arm] = _open_cover(arm)
    cover = _OPEN[arm]
    if cover is None:
        return None
    kept = _BY_POSITION.setdefault(arm, {})
    key = None if finger_position is None else float(finger_position)
    spheres = kept.get(key)
    if spheres is None:
        if len(kept) >= POSITIONS_KEPT:
            kept.clear()
        spheres = kept[key] = _pack(arm, cover, key)
    return spheres


def _open_cover(arm: Any) -> _Cover | None:
    gm = arm.geometry_with_fingers(None)
    centre: list[np.ndarray] = []
    radius: list[float] = []
    joint: list[int] = []
    first: list[int] = []
    count: list[int] = []
    for g in gm.geometryObjects:
        spheres = _cover_geometry(g.geometry, np.asarray(g.placement.homogeneous, dtype=float))
        if not spheres:
            return None
        first.append(len(radius))
        count.append(len(spheres))
        for c, r in spheres:
            centre.append(c)
            radius.append(r + SPHERE_SLACK_M)
            joint.append(int(g.parentJoint))
    return _Cover(
        np.array(centre, dtype=float),
        np.array(radius, dtype=float),
        np.array(joint, dtype=np.int64),
        np.array(first, dtype=np.int64),
        np.array(count, dtype=np.int64),
    )


def _pack(arm: Any, cover: _Cover, finger_position: float | None) -> ArmSpheres:
    """The open hand's cover with the fingers' spheres moved as their geometry moves (along the end-effector's
    closing axis, `ArmModel.geometry_with_fingers`), packed with the chain."""
    gm = arm.geometry_with_fingers(finger_position)
    geoms = list(gm.geometryObjects)
    placements = np.array([g.placement.homogeneous for g in geoms], dtype=float)
    centre = cover.centre.copy()
    if finger_position is not None:
        shift = finger_position - arm.config.gripper.open_position
        rotation = np.asarray(arm.model.frames[arm.ee_frame].placement.rotation)
        for k, side in arm.finger_geometry.items():
            rows = slice(int(cover.first[k]), int(cover.first[k] + cover.count[k]))
            centre[rows] += rotation @ np.array([0.0, side * shift, 0.0])
    # One sphere around each geometry's spheres: a pair whose two bounding spheres are apart needs no other test.
    bound_centre = np.empty((len(geoms), 3))
    bound_radius = np.empty(len(geoms))
    for k in range(len(geoms)):
        rows = slice(int(cover.first[k]), int(cover.first[k] + cover.count[k]))
        c = 0.5 * (centre[rows].min(axis=0) + centre[rows].max(axis=0))
        bound_centre[k] = c
        bound_radius[k] = float((np.sqrt(((centre[rows] - c) ** 2).sum(axis=1)) + cover.radius[rows]).max())
    parents, chain_placements, axes = arm.chain
    joints = np.array([int(g.parentJoint) for g in geoms], dtype=np.int64)
    nj, ns, ng = len(parents), len(cover.radius), len(geoms)
    hulls = [_hull_vertices(g.geometry) for g in geoms]
    hull_count = np.array([len(h) for h in hulls], dtype=np.int64)
    hull_first = np.concatenate([[0], np.cumsum(hull_count)[:-1]]).astype(np.int64)
    swept = [float(getattr(g.geometry, "getSweptSphereRadius", lambda: 0.0)()) for g in geoms]
    sizes = {"nj": nj, "ns": ns, "ng": ng}
    arm_i = ARM_I.pack(
        sizes,
        {
            "nj": [nj],
            "ns": [ns],
            "ng": [ng],
            "parents": parents,
            "sphere_joint": cover.joint,
            "first": cover.first,
            "count": cover.count,
            "geom_joint": joints,
            "hull_first": hull_first,
            "hull_count": hull_count,
        },
        np.int64,
    )
    arm_f = ARM_F.pack(
        sizes,
        {
            "placements": chain_placements,
            "axes": axes,
            "sphere_local": centre,
            "radius": cover.radius,
            "bound_local": bound_centre,
            "bound_radius": bound_radius,
            "geom_placement": placements,
            "lowest": arm._lower_tol,
            "highest": arm._upper_tol,
            "swept": swept,
            "hull": np.concatenate(hulls),
        },
        float,
    )
    return ArmSpheres(
        arm_f=arm_f,
        arm_i=arm_i,
        shapes=tuple(g.geometry for g in geoms),
        placements=placements,
        joints=joints,
        names=tuple(g.name for g in geoms),
        n_joints=nj,
        n_spheres=ns,
    )


@dataclass(frozen=True, eq=False)
class Obstacles:
    """A world's obstacles as arrays: names, shapes ("box" or "cylinder"), (n, 3) sizes (m, unpadded) and
    (n, 4, 4) poses in the model frame."""

    names: list[str]
    shapes: list[str]
    sizes: np.ndarray
    poses: np.ndarray


_NO_HELD_POSE, _NO_HELD_HALF = np.eye(4), np.zeros(3)
_NO_HELD_POSE.flags.writeable = _NO_HELD_HALF.flags.writeable = False


@dataclass(frozen=True, eq=False)
class _PackedWorld:
    """A collision world packed for `compiled.pair_candidates` (`kernel_layout.WORLD_F`, `WORLD_I`): its floats,
    its ints, the ints with the joint-limit and tilt checks off (for messages: every colliding pair), and the held
    object's name ("" when none)."""

    world_f: np.ndarray
    world_i: np.ndarray
    world_i_pairs_only: np.ndarray
    held_name: str


def _pack_world(
    pairs: np.ndarray,
    obstacles: Obstacles,
    padding: float,
    held: tuple[str, str, Sequence[float], np.ndarray, int] | None,
    tilt: tuple[int, float, np.ndarray] | None,
) -> _PackedWorld:
    """`SphereChecks`' world arrays (its arguments of the same names)."""
    n_ob = len(obstacles.names)
    half = obstacles.sizes / 2 + padding
    box = np.array([shape == Shape.BOX for shape in obstacles.shapes], dtype=bool)
    # A cylinder's (radius, half height, -1), as the kernel reads it.
    sizes = half.copy()
    cylinder = ~box
    sizes[cylinder, 1] = half[cylinder, 2]
    sizes[cylinder, 2] = -1.0
    held_local, held_half, held_joint = _NO_HELD_POSE, _NO_HELD_HALF, -1
    held_name = ""
    if held is not None:
        held_name, shape, dims, pose, held_joint = held
        sx, sy, sz = (float(v) for v in dims)
        # The held shape's bounding box (a cylinder's too), grown by the slack.
        held_half = np.array([sx / 2, sy / 2 if shape == Shape.BOX else sx / 2, sz / 2]) + SPHERE_SLACK_M
        held_local = np.asarray(pose, dtype=float)
    tilt_joint, min_up, up = (0, 0.0, np.zeros(3)) if tilt is None else tilt
    world_f = WORLD_F.pack(
        {"n_ob": n_ob},
        {
            "ob_pose": obstacles.poses,
            "ob_size": sizes,
            "held_local": held_local,
            "held_half": held_half,
            "held_joint": [float(held_joint)],
            "tilt_joint": [float(tilt_joint)],
            "min_up": [float(min_up)],
            "up_axis": up,
            # Bounding radii: of the padded shape's bounding box, a hair over (rounding never decides).
            "ob_radius": np.sqrt((half * half).sum(axis=1)) + 1e-9,
            "held_radius": [math.sqrt(float(held_half @ held_half)) + 1e-9],
        },
        float,
    )
    counts = {"n_ob": n_ob, "n_pairs": len(pairs)}
    world_i = WORLD_I.pack(
        counts,
        {
            "n_ob": [n_ob],
            "n_pairs": [len(pairs)],
            "tilt_checked": [int(tilt is not None)],
            "limits_checked": [1],
            "pairs": pairs,
        },
        np.int64,
    )
    # For messages: every colliding pair, whatever the joints and the tilt.
    pairs_only = world_i.copy()
    for check in ("tilt_checked", "limits_checked"):
        start, end = WORLD_I.span(check, counts)
        pairs_only[start:end] = 0
    return _PackedWorld(world_f, world_i, pairs_only, held_name)


class SphereChecks:
    """One collision world's checks: the spheres' broad phase, then coal's GJK on the pairs it leaves.

    Args:
        spheres: The arm's spheres at the world's finger position.
        pairs: (k, 3) rows (kind, a, b) of the pairs to check, in the order their collisions are reported.
        obstacles: The world's obstacles, in the model frame.
        padding: Metres added on every side of every obstacle.
        held: The held object, (name, shape, size (m), pose (4, 4) in its joint's frame, joint), or None.
        held_shape: Its coal shape (the world's: slightly smaller than the object).
        tilt: (joint, cosine of the largest tilt, up axis (3,) in that joint's frame), or None.
        shape_of: Makes an obstacle's padded coal shape: (shape, size, padding) -> shape.
    """

    def __init__(
        self,
        spheres: ArmSpheres,
        pairs: np.ndarray,
        obstacles: Obstacles,
        padding: float,
        held: tuple[str, str, Sequence[float], np.ndarray, int] | None,
        held_shape: Any | None,
        tilt: tuple[int, float, np.ndarray] | None,
        shape_of: Any,
    ) -> None:
        import coal

        from scone_bt.motion import compiled

        self._coal = coal
        self._kernel = compiled.pair_candidates
        self._first = compiled.first_candidates
        self._spheres = spheres
        self._pairs = np.asarray(pairs, dtype=np.int64).reshape(-1, 3)
        packed = _pack_world(self._pairs, obstacles, padding, held, tilt)
        self._held_name = packed.held_name
        self._world_f, self._world_i = packed.world_f, packed.world_i
        self._world_i_pairs_only = packed.world_i_pairs_only
        nj, ns, ng = spheres.n_joints, spheres.n_spheres, len(spheres.shapes)
        work_sizes = {"nj": nj, "ns": ns, "ng": ng}
        self._work = np.empty(WORK.span("scratch", work_sizes)[1])
        work = WORK.unpack(self._work, work_sizes)
        self._held_pose = work["held"][0]
        self._rotations = work["rotation"]
        self._translations = work["translation"]
        # One coal transform per geometry (made when first needed), set from the kernel's poses once per state that
        # needs it.
        self._transforms: list[Any | None] = [None] * (ng + 1)  # the held object's last
        self._set_at = [0] * (ng + 1)
        self._state = 0
        self._out = np.empty(max(len(self._pairs), 1), dtype=np.int64)
        self._obstacles = obstacles
        self._padding = padding
        self._shape_of = shape_of
        self._obstacle_shapes: dict[int, tuple[Any, Any]] = {}  # made when first a candidate
        self._held_shape = held_shape
        # coal's default request: without contacts coal missed a 0.15 mm penetration that Pinocchio's request
        # (with its cached GJK guess) and this one both find (a motion benchmark plan's state)
        self._request = coal.CollisionRequest()
        self._result = coal.CollisionResult()
        self.narrow = 0  # GJK calls made

    def candidates(self, q: np.ndarray, checks: bool = True) -> int:
        """The kernel's answer at q: how many pairs' spheres meet (in ``self._out``); with `checks`, -1 / -2 for
        the tilt, -3 for a joint beyond its limits (`compiled.pair_candidates`)."""
        self._state += 1
        return int(
            self._kernel(
                q,
                self._spheres.arm_f,
                self._spheres.arm_i,
                self._world_f,
                self._world_i if checks else self._world_i_pairs_only,
                self._work,
                self._out,
            )
        )

    def free(self, q: np.ndarray) -> bool | None:
        """True if q (a float64 (dof,) array) is within the joint limits, nothing collides and a held object stays
        upright; None where the held object stands at its tilt limit to rounding (the caller asks Pinocchio)."""
        return self._answer(self.candidates(q))

    def first_not_free(self, states: np.ndarray, start: int = 0) -> tuple[int, bool | None]:
        """The first row of the C-ordered float64 (n, dof) `states`, from `start` on, that `free` does not call
        free, and `free`'s answer there (False, or None); (n, True) if every row is free. One compiled call
        checks the rows up to the first whose spheres meet (most states of a segment: none do)."""
        n = len(states)
        while start < n:
            self._state += 1
            row, found = self._first(
                states,
                start,
                self._spheres.arm_f,
                self._spheres.arm_i,
                self._world_f,
                self._world_i,
                self._work,
                self._out,
            )
            if row == n:
                break
            answer = self._answer(int(found))
            if answer is not True:
                return int(row), answer
            start = int(row) + 1
        return n, True

    def _answer(self, n: int) -> bool | None:
        """`free`'s answer from the kernel's `n` at the state it last placed (GJK on the candidate pairs)."""
        if n == 0:
            return True
        if n == -2:
            return None
        if n < 0:
            return False
        return not any(self._collides(row) for row in self._pairs[self._out[:n]].tolist())

    def colliding(self, q: np.ndarray) -> list[tuple[str, str]]:
        """Names of the pairs in collision at q, in pair order (for messages)."""
        n = self.candidates(q, checks=False)
        return [self._names(row) for row in self._pairs[self._out[:n]].tolist() if self._collides(row)]

    def _collides(self, pair: list[int]) -> bool:
        """Whether the pair's (kind, a, b) meshes collide at the state the kernel last placed."""
        kind, a, b = pair
        if kind == PAIR_ROBOT:
            (shape_a, tf_a), (shape_b, tf_b) = self._robot(a), self._robot(b)
        elif kind == PAIR_OBSTACLE:
            (shape_a, tf_a), (shape_b, tf_b) = self._robot(a), self._obstacle(b)
        elif kind == PAIR_HELD:
            (shape_a, tf_a), (shape_b, tf_b) = self._robot(a), self._held()
        else:
            (shape_a, tf_a), (shape_b, tf_b) = self._obstacle(b), self._held()
        self.narrow += 1
        self._result.clear()
        return bool(self._coal.collide(shape_a, tf_a, shape_b, tf_b, self._request, self._result))

    def _robot(self, g: int) -> tuple[Any, Any]:
        tf = self._transforms[g]
        if tf is None:
            tf = self._transforms[g] = self._coal.Transform3s()
        if self._set_at[g] != self._state:
            tf.setRotation(self._rotations[g])
            tf.setTranslation(self._translations[g])
            self._set_at[g] = self._state
        return self._spheres.shapes[g], tf

    def _held(self) -> tuple[Any, Any]:
        tf = self._transforms[-1]
        if tf is None:
            tf = self._transforms[-1] = self._coal.Transform3s()
        if self._set_at[-1] != self._state:
            tf.setRotation(self._held_pose[:3, :3])
            tf.setTranslation(self._held_pose[:3, 3])
            self._set_at[-1] = self._state
        return self._held_shape, tf

    def _obstacle(self, o: int) -> tuple[Any, Any]:
        made = self._obstacle_shapes.get(o)
        if made is None:
            obstacles = self._obstacles
            pose = obstacles.poses[o]
            tf = self._coal.Transform3s(pose[:3, :3].copy(), pose[:3, 3].copy())
            shape = self._shape_of(obstacles.shapes[o], obstacles.sizes[o], self._padding)
            made = self._obstacle_shapes[o] = (shape, tf)
        return made

    def _names(self, pair: list[int]) -> tuple[str, str]:
        """The Pinocchio world's names of the pair's two geometries, in its order (the lower index first)."""
        kind, a, b = pair
        names = self._spheres.names
        if kind == PAIR_ROBOT:
            return names[a], names[b]
        if kind == PAIR_OBSTACLE:
            return names[a], f"obstacle:{self._obstacles.names[b]}"
        if kind == PAIR_HELD:
            return names[a], f"attached:{self._held_name}"
        return f"obstacle:{self._obstacles.names[b]}", f"attached:{self._held_name}"
