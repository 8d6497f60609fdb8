"""Compiled kernels (numba adapter): a serial arm's forward kinematics and damped least-squares IK.

The only module that imports numba. Its kernels take plain arrays (`ArmModel` builds them) and are compiled once,
on first use, into numba's on-disk cache (`cache=True`: later processes load them in milliseconds); they release
the GIL, so a plan's IK does not stall the simulator's thread.

Conventions: a chain of ``nj`` joints (index 0 the universe), each joint ``j >= 1`` revolute about the unit axis
``axes[j]`` of its own frame, placed at ``placements[j]`` (4x4) in its parent's frame at q = 0 and driven by
``q[j - 1]``; poses are in the arm's model frame (its base), lengths in metres, angles in radians. The logarithm
and its Jacobian are Pinocchio's (``log6``, ``Jlog6``), so the IK takes the steps `ArmModel.ik` took with
Pinocchio's kinematics, to rounding.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from scone_bt.motion.kernel_layout import ARM_F, ARM_I, REST, WORK, WORLD_F, WORLD_I, layout_digest
from scone_bt.motion.pair_kinds import PAIR_HELD, PAIR_HELD_OBSTACLE, PAIR_OBSTACLE, PAIR_ROBOT

__all__ = [
    "chain_poses",
    "field_span",
    "first_candidates",
    "hand_candidates",
    "hulls_apart",
    "ik_search",
    "jlog6",
    "log6",
    "pair_candidates",
    "sample_segment",
    "world_pairs",
]

_SMALL = 1e-4  # below this angle (rad) the series forms are exact to double precision (Pinocchio's threshold order)


@njit(cache=True, nogil=True)
def chain_poses(q, parents, placements, axes, out):  # pragma: no cover - compiled
    """Fill ``out[j]`` (nj, 4, 4) with joint j's pose in the model frame at joint positions ``q``."""
    nj = parents.shape[0]
    for r in range(4):
        for c in range(4):
            out[0, r, c] = 1.0 if r == c else 0.0
    local = np.empty((3, 4))
    for j in range(1, nj):
        x, y, z = axes[j, 0], axes[j, 1], axes[j, 2]
        s, c = math.sin(q[j - 1]), math.cos(q[j - 1])
        t = 1.0 - c
        m00, m01, m02 = t * x * x + c, t * x * y - s * z, t * x * z + s * y
        m10, m11, m12 = t * x * y + s * z, t * y * y + c, t * y * z - s * x
        m20, m21, m22 = t * x * z - s * y, t * y * z + s * x, t * z * z + c
        for r in range(3):
            a0, a1, a2 = placements[j, r, 0], placements[j, r, 1], placements[j, r, 2]
            local[r, 0] = a0 * m00 + a1 * m10 + a2 * m20
            local[r, 1] = a0 * m01 + a1 * m11 + a2 * m21
            local[r, 2] = a0 * m02 + a1 * m12 + a2 * m22
            local[r, 3] = placements[j, r, 3]
        p = parents[j]
        for r in range(3):
            b0, b1, b2 = out[p, r, 0], out[p, r, 1], out[p, r, 2]
            for cc in range(4):
                out[j, r, cc] = b0 * local[0, cc] + b1 * local[1, cc] + b2 * local[2, cc]
            out[j, r, 3] += out[p, r, 3]
        out[j, 3, 0] = out[j, 3, 1] = out[j, 3, 2] = 0.0
        out[j, 3, 3] = 1.0


@njit(cache=True, nogil=True, inline="always")
def _compose(a, b, out):  # pragma: no cover - compiled
    """``out`` (4x4) = the rigid transform ``a`` (4x4) after ``b`` (4x4), ``a @ b``."""
    for r in range(3):
        for c in range(4):
            v = a[r, 0] * b[0, c] + a[r, 1] * b[1, c] + a[r, 2] * b[2, c]
            out[r, c] = v + a[r, 3] if c == 3 else v
    out[3, 0] = out[3, 1] = out[3, 2] = 0.0
    out[3, 3] = 1.0


@njit(cache=True, nogil=True)
def _log3(rot, w):  # pragma: no cover - compiled
    """Rotation vector of ``rot`` (3x3) into ``w``; returns its angle."""
    tr = rot[0, 0] + rot[1, 1] + rot[2, 2]
    cos_t = min(1.0, max(-1.0, 0.5 * (tr - 1.0)))
    theta = math.acos(cos_t)
    vx, vy, vz = rot[2, 1] - rot[1, 2], rot[0, 2] - rot[2, 0], rot[1, 0] - rot[0, 1]
    if theta < _SMALL:
        f = 0.5 * (1.0 + theta * theta / 6.0)
        w[0], w[1], w[2] = f * vx, f * vy, f * vz
        return theta
    if theta > math.pi - 1e-3:
        # Near a half turn the antisymmetric part vanishes: the axis from the symmetric part (R = 2aa^T - I).
        best = 0
        for i in range(1, 3):
            if rot[i, i] > rot[best, best]:
                best = i
        i1, i2 = (best + 1) % 3, (best + 2) % 3
        a = math.sqrt(max(0.0, (rot[best, best] - cos_t) / (1.0 - cos_t)))
        axis = np.empty(3)
        axis[best] = a
        axis[i1] = (rot[i1, best] + rot[best, i1]) / (2.0 * a * (1.0 - cos_t))
        axis[i2] = (rot[i2, best] + rot[best, i2]) / (2.0 * a * (1.0 - cos_t))
        sign = axis[0] * vx + axis[1] * vy + axis[2] * vz
        if sign < 0.0:
            axis = -axis
        w[0], w[1], w[2] = theta * axis[0], theta * axis[1], theta * axis[2]
        return theta
    f = 0.5 * theta / math.sin(theta)
    w[0], w[1], w[2] = f * vx, f * vy, f * vz
    return theta


@njit(cache=True, nogil=True)
def log6(rot, p, out):  # pragma: no cover - compiled
    """Pinocchio's ``log6`` of the transform (rot, p) into ``out`` = [linear, angular]; returns the angle."""
    w = np.empty(3)
    t = _log3(rot, w)
    t2 = t * t
    if t < _SMALL:
        alpha = 1.0 - t2 / 12.0 - t2 * t2 / 720.0
        beta = 1.0 / 12.0 + t2 / 720.0
    else:
        st, ct = math.sin(t), math.cos(t)
        alpha = t * st / (2.0 * (1.0 - ct))
        beta = 1.0 / t2 - st / (2.0 * t * (1.0 - ct))
    wp = w[0] * p[0] + w[1] * p[1] + w[2] * p[2]
    cx = w[1] * p[2] - w[2] * p[1]
    cy = w[2] * p[0] - w[0] * p[2]
    cz = w[0] * p[1] - w[1] * p[0]
    out[0] = alpha * p[0] - 0.5 * cx + beta * wp * w[0]
    out[1] = alpha * p[1] - 0.5 * cy + beta * wp * w[1]
    out[2] = alpha * p[2] - 0.5 * cz + beta * wp * w[2]
    out[3], out[4], out[5] = w[0], w[1], w[2]
    return t


@njit(cache=True, nogil=True, inline="always")
def _add_half_skew(out, v):  # pragma: no cover - compiled
    """``out`` (3x3) += half the cross-product matrix of ``v`` ([v]x / 2)."""
    out[0, 1] -= 0.5 * v[2]
    out[0, 2] += 0.5 * v[1]
    out[1, 0] += 0.5 * v[2]
    out[1, 2] -= 0.5 * v[0]
    out[2, 0] -= 0.5 * v[1]
    out[2, 1] += 0.5 * v[0]


@njit(cache=True, nogil=True)
def _jlog3(t, w, out):  # pragma: no cover - compiled
    """Pinocchio's ``Jlog3`` at the rotation vector ``w`` of angle ``t`` into ``out`` (3x3)."""
    if t < _SMALL:
        a, b = 1.0 - t * t / 12.0, 1.0 / 12.0 + t * t / 720.0
    else:
        st, ct = math.sin(t), math.cos(t)
        st_1mct = st / (1.0 - ct)
        a = 0.5 * t * st_1mct
        b = 1.0 / (t * t) - 0.5 * st_1mct / t
    for i in range(3):
        for k in range(3):
            out[i, k] = b * w[i] * w[k]
        out[i, i] += a
    _add_half_skew(out, w)


@njit(cache=True, nogil=True)
def jlog6(rot, p, out):  # pragma: no cover - compiled
    """Pinocchio's ``Jlog6`` of the transform (rot, p) into ``out`` (6x6)."""
    w = np.empty(3)
    t = _log3(rot, w)
    a = np.empty((3, 3))
    _jlog3(t, w, a)
    t2 = t * t
    if t < _SMALL:
        beta = 1.0 / 12.0 + t2 / 720.0
        beta_dot_over_theta = 1.0 / 360.0
    else:
        st, ct = math.sin(t), math.cos(t)
        tinv = 1.0 / t
        t2inv = tinv * tinv
        inv_2_2ct = 1.0 / (2.0 * (1.0 - ct))
        beta = t2inv - st * tinv * inv_2_2ct
        beta_dot_over_theta = -2.0 * t2inv * t2inv + (1.0 + st * tinv) * t2inv * inv_2_2ct
    wp = w[0] * p[0] + w[1] * p[1] + w[2] * p[2]
    v = np.empty(3)
    for i in range(3):
        v[i] = beta_dot_over_theta * wp * w[i] - (t2 * beta_dot_over_theta + 2.0 * beta) * p[i]
    c = np.empty((3, 3))
    for i in range(3):
        for k in range(3):
            c[i, k] = v[i] * w[k] + beta * w[i] * p[k]
        c[i, i] += wp * beta
    _add_half_skew(c, p)
    for i in range(6):
        for k in range(6):
            out[i, k] = 0.0
    for i in range(3):
        for k in range(3):
            out[i, k] = a[i, k]
            out[3 + i, 3 + k] = a[i, k]
            s = 0.0
            for m in range(3):
                s += c[i, m] * a[m, k]
            out[i, 3 + k] = s


@njit(cache=True, nogil=True)
def _solve_spd(a, b, n_rhs):  # pragma: no cover - compiled
    """Solve a x = b in place of b for a symmetric positive definite 6x6 ``a`` (Cholesky; ``a`` overwritten)."""
    for j in range(6):
        s = a[j, j]
        for k in range(j):
            s -= a[j, k] * a[j, k]
        d = math.sqrt(s)
        a[j, j] = d
        for i in range(j + 1, 6):
            s = a[i, j]
            for k in range(j):
                s -= a[i, k] * a[j, k]
            a[i, j] = s / d
    for c in range(n_rhs):
        for i in range(6):
            s = b[i, c]
            for k in range(i):
                s -= a[i, k] * b[k, c]
            b[i, c] = s / a[i, i]
        for i in range(5, -1, -1):
            s = b[i, c]
            for k in range(i + 1, 6):
                s -= a[k, i] * b[k, c]
            b[i, c] = s / a[i, i]


@njit(cache=True, nogil=True)
def ik_search(
    goal,
    seeds,
    lower,
    upper,
    parents,
    placements,
    axes,
    ee_joint,
    ee_placement,
    settings,
    out,
):  # pragma: no cover - compiled
    """`ArmModel.ik`'s damped least-squares search from each row of ``seeds`` in turn.

    Args:
        goal: (4, 4) the end-effector frame's target in the model frame.
        seeds: (k, dof) start positions, the given seed first.
        ee_joint, ee_placement: the end-effector frame's joint and its placement (4x4) there.
        settings: (7,) max iterations, position and rotation tolerances, damping, step, posture gain, stall
            iterations (`IKOptions`).
        out: (dof + 2,) the answer: joint positions, then the position and rotation errors.

    Returns:
        True when some seed converged (the answer is in ``out``).
    """
    dof = seeds.shape[1]
    nj = parents.shape[0]
    max_iterations, pos_tol, rot_tol = int(settings[0]), settings[1], settings[2]
    damping, step, gain, stall = settings[3], settings[4], settings[5], int(settings[6])
    poses = np.empty((nj, 4, 4))
    # The joints that move the end-effector (its chain), as columns of the Jacobian.
    moves = np.zeros(nj, dtype=np.bool_)
    j = ee_joint
    while j > 0:
        moves[j] = True
        j = parents[j]
    rot, p, err = np.empty((3, 3)), np.empty(3), np.empty(6)
    rinv, pinv = np.empty((3, 3)), np.empty(3)
    jl = np.empty((6, 6))
    jac_local = np.empty((6, dof))
    jac = np.empty((6, dof))
    a = np.empty((6, 6))
    rhs = np.empty((6, 1 + dof))
    frame = np.empty((4, 4))
    dq = np.empty(dof)
    drift = np.empty(dof)
    for s in range(seeds.shape[0]):
        q0 = seeds[s]
        q = q0.copy()
        best, since_best = np.inf, 0
        for _ in range(max_iterations):
            chain_poses(q, parents, placements, axes, poses)
            _compose(poses[ee_joint], ee_placement, frame)
            # The goal seen from the current frame: frame^-1 goal.
            for r in range(3):
                for c in range(3):
                    rot[r, c] = frame[0, r] * goal[0, c] + frame[1, r] * goal[1, c] + frame[2, r] * goal[2, c]
                dx0, dx1, dx2 = goal[0, 3] - frame[0, 3], goal[1, 3] - frame[1, 3], goal[2, 3] - frame[2, 3]
                p[r] = frame[0, r] * dx0 + frame[1, r] * dx1 + frame[2, r] * dx2
            log6(rot, p, err)
            pos_err = math.sqrt(err[0] * err[0] + err[1] * err[1] + err[2] * err[2])
            rot_err = math.sqrt(err[3] * err[3] + err[4] * err[4] + err[5] * err[5])
            if pos_err < pos_tol and rot_err < rot_tol:
                for i in range(dof):
                    out[i] = q[i]
                out[dof], out[dof + 1] = pos_err, rot_err
                return True
            total = pos_err + 0.1 * rot_err
            if total < 0.98 * best:
                best, since_best = total, 0
            else:
                since_best += 1
                if since_best > stall:
                    break
            # The frame's Jacobian in its own axes: joint j turns about its axis a through its origin o.
            for c in range(dof):
                jj = c + 1
                if not moves[jj]:
                    for r in range(6):
                        jac_local[r, c] = 0.0
                    continue
                ax = (
                    poses[jj, 0, 0] * axes[jj, 0]
                    + poses[jj, 0, 1] * axes[jj, 1]
                    + poses[jj, 0, 2] * axes[jj, 2]
                )
                ay = (
                    poses[jj, 1, 0] * axes[jj, 0]
                    + poses[jj, 1, 1] * axes[jj, 1]
                    + poses[jj, 1, 2] * axes[jj, 2]
                )
                az = (
                    poses[jj, 2, 0] * axes[jj, 0]
                    + poses[jj, 2, 1] * axes[jj, 1]
                    + poses[jj, 2, 2] * axes[jj, 2]
                )
                ox, oy, oz = (
                    frame[0, 3] - poses[jj, 0, 3],
                    frame[1, 3] - poses[jj, 1, 3],
                    frame[2, 3] - poses[jj, 2, 3],
                )
                vx, vy, vz = ay * oz - az * oy, az * ox - ax * oz, ax * oy - ay * ox
                for r in range(3):
                    jac_local[r, c] = frame[0, r] * vx + frame[1, r] * vy + frame[2, r] * vz
                    jac_local[3 + r, c] = frame[0, r] * ax + frame[1, r] * ay + frame[2, r] * az
            # Jlog6 of the inverse transform (rot^T, -rot^T p).
            for r in range(3):
                for c in range(3):
                    rinv[r, c] = rot[c, r]
                pinv[r] = -(rot[0, r] * p[0] + rot[1, r] * p[1] + rot[2, r] * p[2])
            jlog6(rinv, pinv, jl)
            for r in range(6):
                for c in range(dof):
                    v = 0.0
                    for m in range(6):
                        v += jl[r, m] * jac_local[m, c]
                    jac[r, c] = v
            for r in range(6):
                rhs[r, 0] = err[r]
                for c in range(dof):
                    rhs[r, 1 + c] = jac[r, c]
                for c in range(6):
                    v = 0.0
                    for m in range(dof):
                        v += jac[r, m] * jac[c, m]
                    a[r, c] = v + (damping if r == c else 0.0)
            _solve_spd(a, rhs, 1 + dof)
            # dq = J^T x0 + (I - J^T X) (gain (q0 - q)): the step, and a drift towards the seed in the null space.
            for i in range(dof):
                drift[i] = gain * (q0[i] - q[i])
            norm = 0.0
            for i in range(dof):
                v = 0.0
                for r in range(6):
                    v += jac[r, i] * rhs[r, 0]
                v += drift[i]
                for k in range(dof):
                    jx = 0.0
                    for r in range(6):
                        jx += jac[r, i] * rhs[r, 1 + k]
                    v -= jx * drift[k]
                dq[i] = v
                if abs(v) > norm:
                    norm = abs(v)
            scale = 0.5 / norm if norm > 0.5 else 1.0
            for i in range(dof):
                d = dq[i] * scale
                if step != 1.0:
                    d = step * d
                q[i] = min(max(q[i] + d, lower[i]), upper[i])
    return False


# ------------------------------------------------------------------------------------------ sphere broad phase
# Packed layouts (one float and one int array each for the arm, the world and the workspace: a compiled call's
# price grows with its number of array arguments, about 60 ns each):
#   arm_i:   [nj, ns, ng, parents (nj), sphere joint (ns), geometry's first sphere (ng), its count (ng),
#             geometry joint (ng), geometry's first hull vertex (ng), its count (ng: 0 where it has none)]
#   arm_f:   [joint placements (nj x 16), axes (nj x 3), sphere centres (ns x 3), radii (ns),
#             geometry bounding centres (ng x 3), bounding radii (ng), geometry placements (ng x 16),
#             lowest and highest joint positions (2 x (nj - 1)), their tolerance included,
#             each geometry's swept-sphere radius (ng), hull vertices in their geometry's frame (nh x 3)]
#   world_i: [obstacles no, pairs np, tilt checked (0/1), joint limits checked (0/1), pairs (np x 3: kind, a, b)]
#   world_f: [obstacle poses (no x 16), sizes (no x 3), held pose in its joint (16), held half extents (3),
#             held joint, tilt joint, min up, up axis (3), obstacle bounding radii (no), held bounding radius]
#   work:    [joint poses (nj x 16), sphere centres (ns x 3), bounding centres (ng x 3), held pose (16),
#             geometry rotations (ng x 9) and translations (ng x 3): set only where two hulls are tested or some
#             pair is a candidate, scratch (24)]
# Pair kinds: 0 robot geometry a ~ robot geometry b, 1 robot a ~ obstacle b, 2 robot a ~ held object,
# 3 held object ~ obstacle b. An obstacle's size is its half extents, or (radius, half height, -1) for a cylinder.


@njit(cache=True, nogil=True, inline="always")
def _gap2_to(px, py, pz, pose, size):  # pragma: no cover - compiled
    """Squared distance from a point to a solid box (half extents) or cylinder ((radius, half height, -1))."""
    dx, dy, dz = px - pose[0, 3], py - pose[1, 3], pz - pose[2, 3]
    lx = dx * pose[0, 0] + dy * pose[1, 0] + dz * pose[2, 0]
    ly = dx * pose[0, 1] + dy * pose[1, 1] + dz * pose[2, 1]
    lz = dx * pose[0, 2] + dy * pose[1, 2] + dz * pose[2, 2]
    total = 0.0
    if size[2] < 0.0:
        radial = math.sqrt(lx * lx + ly * ly) - size[0]
        axial = abs(lz) - size[1]
        if radial > 0.0:
            total += radial * radial
        if axial > 0.0:
            total += axial * axial
        return total
    for over in (abs(lx) - size[0], abs(ly) - size[1], abs(lz) - size[2]):
        if over > 0.0:
            total += over * over
    return total


@njit(cache=True, nogil=True)
def _boxes_apart(pa, ha, pb, hb, scratch):  # pragma: no cover - compiled
    """True if two oriented boxes (poses 4x4, half extents) are certainly apart: one of the 15 separating axes
    (each box's face normals and the cross products of their edges) shows a gap between them. ``scratch``: 21
    floats of workspace."""
    rot = scratch[:9].reshape((3, 3))  # b's axes in a's frame
    absr = scratch[9:18].reshape((3, 3))
    for i in range(3):
        for j in range(3):
            rot[i, j] = pa[0, i] * pb[0, j] + pa[1, i] * pb[1, j] + pa[2, i] * pb[2, j]
            absr[i, j] = abs(rot[i, j]) + 1e-9  # near-parallel edges: the face axes decide
    dx, dy, dz = pb[0, 3] - pa[0, 3], pb[1, 3] - pa[1, 3], pb[2, 3] - pa[2, 3]
    t = scratch[18:21]
    for i in range(3):
        t[i] = dx * pa[0, i] + dy * pa[1, i] + dz * pa[2, i]
    for i in range(3):
        if abs(t[i]) > ha[i] + hb[0] * absr[i, 0] + hb[1] * absr[i, 1] + hb[2] * absr[i, 2]:
            return True
    for j in range(3):
        reach = ha[0] * absr[0, j] + ha[1] * absr[1, j] + ha[2] * absr[2, j] + hb[j]
        if abs(t[0] * rot[0, j] + t[1] * rot[1, j] + t[2] * rot[2, j]) > reach:
            return True
    for i in range(3):
        i1, i2 = (i + 1) % 3, (i + 2) % 3
        for j in range(3):
            j1, j2 = (j + 1) % 3, (j + 2) % 3
            reach = ha[i1] * absr[i2, j] + ha[i2] * absr[i1, j] + hb[j1] * absr[i, j2] + hb[j2] * absr[i, j1]
            if abs(t[i2] * rot[i1, j] - t[i1] * rot[i2, j]) > reach:
                return True
    return False


HULL_MARGIN_M = 1e-4
"""Metres by which two robot hulls must be proven apart for the kernel to drop their pair (coal's GJK answers to
about 1e-6 m: a pair this far apart is apart to coal too)."""
HULL_ITERATIONS = 16
"""Most steps of the hulls' distance bound before the pair goes to coal."""


@njit(cache=True, nogil=True, inline="always")
def _pose_geometries(poses, geom_joint, geom_placement, rotation, translation):  # pragma: no cover - compiled
    """Each robot geometry's rotation and translation in the model frame, from its joint's pose."""
    for g in range(geom_joint.shape[0]):
        j = geom_joint[g]
        for r in range(3):
            for c in range(3):
                rotation[g, r, c] = (
                    poses[j, r, 0] * geom_placement[g, 0, c]
                    + poses[j, r, 1] * geom_placement[g, 1, c]
                    + poses[j, r, 2] * geom_placement[g, 2, c]
                )
            translation[g, r] = (
                poses[j, r, 0] * geom_placement[g, 0, 3]
                + poses[j, r, 1] * geom_placement[g, 1, 3]
                + poses[j, r, 2] * geom_placement[g, 2, 3]
                + poses[j, r, 3]
            )


@njit(cache=True, nogil=True, inline="always")
def _support(rotation, translation, hull, first, count, g, vx, vy, vz, sign):  # pragma: no cover - compiled
    """The vertex of geometry g's hull furthest along ``sign * v`` (world frame), as (x, y, z)."""
    lx = (rotation[g, 0, 0] * vx + rotation[g, 1, 0] * vy + rotation[g, 2, 0] * vz) * sign
    ly = (rotation[g, 0, 1] * vx + rotation[g, 1, 1] * vy + rotation[g, 2, 1] * vz) * sign
    lz = (rotation[g, 0, 2] * vx + rotation[g, 1, 2] * vy + rotation[g, 2, 2] * vz) * sign
    best, k_best = -np.inf, first[g]
    for k in range(first[g], first[g] + count[g]):
        d = lx * hull[k, 0] + ly * hull[k, 1] + lz * hull[k, 2]
        if d > best:
            best, k_best = d, k
    px, py, pz = hull[k_best, 0], hull[k_best, 1], hull[k_best, 2]
    return (
        rotation[g, 0, 0] * px + rotation[g, 0, 1] * py + rotation[g, 0, 2] * pz + translation[g, 0],
        rotation[g, 1, 0] * px + rotation[g, 1, 1] * py + rotation[g, 1, 2] * pz + translation[g, 1],
        rotation[g, 2, 0] * px + rotation[g, 2, 1] * py + rotation[g, 2, 2] * pz + translation[g, 2],
    )


@njit(cache=True, nogil=True)
def hulls_apart(rotation, translation, hull, first, count, margin, a, b, vx, vy, vz):  # pragma: no cover
    """True if the convex hulls of geometries a and b (placed by ``rotation``/``translation``) are proven more than
    ``margin`` apart; False where not proven (they may still be apart: coal decides).

    A proof is a direction: for any v, the distance between the hulls is at least the smallest v . c / |v| over
    the Minkowski difference A - B (c = the support point of A towards -v minus that of B towards v). Starting
    from ``v`` (a point of A minus a point of B), Frank-Wolfe steps move v to the point of the segment [v, c]
    closest to the origin, which tends to the closest point of A - B: the bound tends to the distance.
    """
    for _ in range(HULL_ITERATIONS):
        vv = vx * vx + vy * vy + vz * vz
        if vv <= 1e-24:
            return False
        ax, ay, az = _support(rotation, translation, hull, first, count, a, vx, vy, vz, -1.0)
        bx, by, bz = _support(rotation, translation, hull, first, count, b, vx, vy, vz, 1.0)
        wx, wy, wz = ax - bx, ay - by, az - bz
        vw = vx * wx + vy * wy + vz * wz
        if vw > 0.0 and vw * vw > margin * margin * vv:
            return True
        if vv - vw <= 1e-9 * vv:  # v is (to rounding) the closest point: no better bound exists
            return False
        dx, dy, dz = wx - vx, wy - vy, wz - vz
        t = -(vx * dx + vy * dy + vz * dz) / (dx * dx + dy * dy + dz * dz)
        if t > 1.0:
            t = 1.0
        vx, vy, vz = vx + t * dx, vy + t * dy, vz + t * dz
    return False


# The flat arrays' offset tables (`kernel_layout`), numpy globals that numba compiles in as constants, and each
# field's row in them. numba's on-disk cache keeps them as they were when it compiled and refreshes only when this
# file changes: LAYOUT_DIGEST, checked at import, makes a change of layout a change of this file.
LAYOUT_DIGEST = "ef043c033c443461"
if layout_digest() != LAYOUT_DIGEST:
    raise RuntimeError(
        f"scone_bt/motion/compiled.py: LAYOUT_DIGEST is {LAYOUT_DIGEST!r} but the kernel's layouts "
        f"(motion/kernel_layout.py) hash to {layout_digest()!r}; set it to that (this refreshes numba's cache)"
    )
_AI, _AF, _WI, _WF, _WK = ARM_I.table(), ARM_F.table(), WORLD_I.table(), WORLD_F.table(), WORK.table()
_AI_NJ, _AI_NS, _AI_NG, _AI_PARENTS, _AI_SPHERE_JOINT, _AI_FIRST, _AI_COUNT = (
    ARM_I.index(n) for n in ("nj", "ns", "ng", "parents", "sphere_joint", "first", "count")
)
_AI_GEOM_JOINT, _AI_HULL_FIRST, _AI_HULL_COUNT = (
    ARM_I.index(n) for n in ("geom_joint", "hull_first", "hull_count")
)
_AF_PLACEMENTS, _AF_AXES, _AF_SPHERE_LOCAL, _AF_RADIUS, _AF_BOUND_LOCAL, _AF_BOUND_RADIUS = (
    ARM_F.index(n) for n in ("placements", "axes", "sphere_local", "radius", "bound_local", "bound_radius")
)
_AF_GEOM_PLACEMENT, _AF_LOWEST, _AF_HIGHEST, _AF_SWEPT, _AF_HULL = (
    ARM_F.index(n) for n in ("geom_placement", "lowest", "highest", "swept", "hull")
)
_WI_N_OB, _WI_N_PAIRS, _WI_TILT_CHECKED, _WI_LIMITS_CHECKED, _WI_PAIRS = (
    WORLD_I.index(n) for n in ("n_ob", "n_pairs", "tilt_checked", "limits_checked", "pairs")
)
_WF_OB_POSE, _WF_OB_SIZE, _WF_HELD_LOCAL, _WF_HELD_HALF, _WF_HELD_JOINT = (
    WORLD_F.index(n) for n in ("ob_pose", "ob_size", "held_local", "held_half", "held_joint")
)
_WF_TILT_JOINT, _WF_MIN_UP, _WF_UP_AXIS, _WF_OB_RADIUS, _WF_HELD_RADIUS = (
    WORLD_F.index(n) for n in ("tilt_joint", "min_up", "up_axis", "ob_radius", "held_radius")
)
_WK_POSES, _WK_CENTRES, _WK_BOUNDS, _WK_HELD, _WK_ROTATION, _WK_TRANSLATION, _WK_SCRATCH = (
    WORK.index(n) for n in ("poses", "centres", "bounds", "held", "rotation", "translation", "scratch")
)


@njit(cache=True, nogil=True, inline="always")
def field_span(table, k, a, b, c, total):  # pragma: no cover - compiled
    """[start, end) of field ``k`` of a flat array of length ``total`` by its layout's offset ``table``
    (`kernel_layout.Layout.table`), for the layout's sizes (a, b, c); as `kernel_layout.Layout.span`."""
    start = table[k, 0, 0] + table[k, 0, 1] * a + table[k, 0, 2] * b + table[k, 0, 3] * c
    if table[k, 1, 0] == REST:  # the rest of the array
        return start, total
    return start, start + table[k, 1, 0] + table[k, 1, 1] * a + table[k, 1, 2] * b + table[k, 1, 3] * c


@njit(cache=True, nogil=True, inline="always")
def _field(array, table, k, a, b, c):  # pragma: no cover - compiled
    """Field ``k`` of the flat ``array`` (1-D) by its layout's offset ``table``, for sizes (a, b, c)."""
    start, end = field_span(table, k, a, b, c, array.shape[0])
    return array[start:end]


@njit(cache=True, nogil=True)
def pair_candidates(q, arm_f, arm_i, world_f, world_i, work, out):  # pragma: no cover - compiled
    """The pairs whose spheres meet at ``q`` and, for two robot geometries, whose hulls are not proven apart (their
    indices into ``out``), in pair order; the meshes of every other pair are certainly apart.

    Returns:
        How many candidates there are; -1 when the held object tilts beyond its limit; -2 when it stands within
        1e-12 of the limit (rounding decides: the caller asks Pinocchio); -3 when a joint is beyond its limits
        (or NaN).
    """
    nj, ns, ng = (
        _field(arm_i, _AI, _AI_NJ, 0, 0, 0)[0],
        _field(arm_i, _AI, _AI_NS, 0, 0, 0)[0],
        _field(arm_i, _AI, _AI_NG, 0, 0, 0)[0],
    )
    parents = _field(arm_i, _AI, _AI_PARENTS, nj, ns, ng)
    sphere_joint = _field(arm_i, _AI, _AI_SPHERE_JOINT, nj, ns, ng)
    first = _field(arm_i, _AI, _AI_FIRST, nj, ns, ng)
    count = _field(arm_i, _AI, _AI_COUNT, nj, ns, ng)
    geom_joint = _field(arm_i, _AI, _AI_GEOM_JOINT, nj, ns, ng)
    hull_first = _field(arm_i, _AI, _AI_HULL_FIRST, nj, ns, ng)
    hull_count = _field(arm_i, _AI, _AI_HULL_COUNT, nj, ns, ng)
    placements = _field(arm_f, _AF, _AF_PLACEMENTS, nj, ns, ng).reshape((nj, 4, 4))
    axes = _field(arm_f, _AF, _AF_AXES, nj, ns, ng).reshape((nj, 3))
    sphere_local = _field(arm_f, _AF, _AF_SPHERE_LOCAL, nj, ns, ng).reshape((ns, 3))
    radius = _field(arm_f, _AF, _AF_RADIUS, nj, ns, ng)
    bound_local = _field(arm_f, _AF, _AF_BOUND_LOCAL, nj, ns, ng).reshape((ng, 3))
    bound_radius = _field(arm_f, _AF, _AF_BOUND_RADIUS, nj, ns, ng)
    geom_placement = _field(arm_f, _AF, _AF_GEOM_PLACEMENT, nj, ns, ng).reshape((ng, 4, 4))
    dof = nj - 1
    lowest = _field(arm_f, _AF, _AF_LOWEST, nj, ns, ng)
    highest = _field(arm_f, _AF, _AF_HIGHEST, nj, ns, ng)
    swept = _field(arm_f, _AF, _AF_SWEPT, nj, ns, ng)
    hull = _field(arm_f, _AF, _AF_HULL, nj, ns, ng).reshape((-1, 3))
    n_ob = _field(world_i, _WI, _WI_N_OB, 0, 0, 0)[0]
    n_pairs = _field(world_i, _WI, _WI_N_PAIRS, 0, 0, 0)[0]
    tilt_checked = _field(world_i, _WI, _WI_TILT_CHECKED, 0, 0, 0)[0]
    limits_checked = _field(world_i, _WI, _WI_LIMITS_CHECKED, 0, 0, 0)[0]
    pairs = _field(world_i, _WI, _WI_PAIRS, n_ob, n_pairs, 0).reshape((n_pairs, 3))
    ob_pose = _field(world_f, _WF, _WF_OB_POSE, n_ob, 0, 0).reshape((n_ob, 4, 4))
    ob_size = _field(world_f, _WF, _WF_OB_SIZE, n_ob, 0, 0).reshape((n_ob, 3))
    held_local = _field(world_f, _WF, _WF_HELD_LOCAL, n_ob, 0, 0).reshape((4, 4))
    held_half = _field(world_f, _WF, _WF_HELD_HALF, n_ob, 0, 0)
    held_joint = int(_field(world_f, _WF, _WF_HELD_JOINT, n_ob, 0, 0)[0])
    tilt_joint = int(_field(world_f, _WF, _WF_TILT_JOINT, n_ob, 0, 0)[0])
    min_up = _field(world_f, _WF, _WF_MIN_UP, n_ob, 0, 0)[0]
    up_axis = _field(world_f, _WF, _WF_UP_AXIS, n_ob, 0, 0)
    ob_radius = _field(world_f, _WF, _WF_OB_RADIUS, n_ob, 0, 0)
    held_radius = _field(world_f, _WF, _WF_HELD_RADIUS, n_ob, 0, 0)[0]
    poses = _field(work, _WK, _WK_POSES, nj, ns, ng).reshape((nj, 4, 4))
    centres = _field(work, _WK, _WK_CENTRES, nj, ns, ng).reshape((ns, 3))
    bounds = _field(work, _WK, _WK_BOUNDS, nj, ns, ng).reshape((ng, 3))
    held = _field(work, _WK, _WK_HELD, nj, ns, ng).reshape((4, 4))
    rotation = _field(work, _WK, _WK_ROTATION, nj, ns, ng).reshape((ng, 3, 3))
    translation = _field(work, _WK, _WK_TRANSLATION, nj, ns, ng).reshape((ng, 3))
    scratch = _field(work, _WK, _WK_SCRATCH, nj, ns, ng)

    if limits_checked:
        for i in range(dof):
            if not (lowest[i] <= q[i] <= highest[i]):  # NaN too
                return -3
    chain_poses(q, parents, placements, axes, poses)
    if tilt_checked:
        up = (
            poses[tilt_joint, 2, 0] * up_axis[0]
            + poses[tilt_joint, 2, 1] * up_axis[1]
            + poses[tilt_joint, 2, 2] * up_axis[2]
        )
        if up < min_up - 1e-12:
            return -1
        if up < min_up + 1e-12:
            return -2
    for s in range(ns):
        j = sphere_joint[s]
        x, y, z = sphere_local[s, 0], sphere_local[s, 1], sphere_local[s, 2]
        for r in range(3):
            centres[s, r] = poses[j, r, 0] * x + poses[j, r, 1] * y + poses[j, r, 2] * z + poses[j, r, 3]
    for g in range(ng):
        j = geom_joint[g]
        x, y, z = bound_local[g, 0], bound_local[g, 1], bound_local[g, 2]
        for r in range(3):
            bounds[g, r] = poses[j, r, 0] * x + poses[j, r, 1] * y + poses[j, r, 2] * z + poses[j, r, 3]
    if held_joint >= 0:
        _compose(poses[held_joint], held_local, held)
    posed = False
    found = 0
    for k in range(n_pairs):
        kind, a, b = pairs[k, 0], pairs[k, 1], pairs[k, 2]
        meets = False
        if kind != PAIR_ROBOT:
            # Bounding spheres first (the obstacle's, and a's or the held object's): most pairs are far apart.
            if kind == PAIR_OBSTACLE:
                cx, cy, cz, reach = bounds[a, 0], bounds[a, 1], bounds[a, 2], bound_radius[a] + ob_radius[b]
            else:
                cx, cy, cz, reach = held[0, 3], held[1, 3], held[2, 3], held_radius
                reach += bound_radius[a] if kind == PAIR_HELD else ob_radius[b]
            if kind == PAIR_HELD:
                dx, dy, dz = cx - bounds[a, 0], cy - bounds[a, 1], cz - bounds[a, 2]
            else:
                dx, dy, dz = cx - ob_pose[b, 0, 3], cy - ob_pose[b, 1, 3], cz - ob_pose[b, 2, 3]
            if dx * dx + dy * dy + dz * dz > reach * reach:
                continue
        if kind == PAIR_HELD_OBSTACLE:
            box = ob_size[b]
            if box[2] < 0.0:  # a cylinder: its bounding box
                box = scratch[21:24]
                box[0], box[1], box[2] = ob_size[b, 0], ob_size[b, 0], ob_size[b, 1]
            meets = not _boxes_apart(held, held_half, ob_pose[b], box, scratch)
        elif kind == PAIR_ROBOT:
            dx, dy, dz = bounds[a, 0] - bounds[b, 0], bounds[a, 1] - bounds[b, 1], bounds[a, 2] - bounds[b, 2]
            reach = bound_radius[a] + bound_radius[b]
            if dx * dx + dy * dy + dz * dz <= reach * reach:
                for sa in range(first[a], first[a] + count[a]):
                    for sb in range(first[b], first[b] + count[b]):
                        dx = centres[sa, 0] - centres[sb, 0]
                        dy = centres[sa, 1] - centres[sb, 1]
                        dz = centres[sa, 2] - centres[sb, 2]
                        reach = radius[sa] + radius[sb]
                        if dx * dx + dy * dy + dz * dz <= reach * reach:
                            meets = True
                            break
                    if meets:
                        break
                if meets and hull_count[a] > 0 and hull_count[b] > 0:
                    # Spheres meet: two hulls proven apart need no GJK (most such pairs: the wrist's links, 2-3 cm
                    # apart with the wrist folded). (dx, dy, dz): a point of a's hull minus one of b's.
                    if not posed:
                        _pose_geometries(poses, geom_joint, geom_placement, rotation, translation)
                        posed = True
                    margin = HULL_MARGIN_M + swept[a] + swept[b]
                    if hulls_apart(
                        rotation, translation, hull, hull_first, hull_count, margin, a, b, dx, dy, dz
                    ):
                        meets = False
        else:
            pose = held if kind == PAIR_HELD else ob_pose[b]
            size = held_half if kind == PAIR_HELD else ob_size[b]
            r = bound_radius[a]
            if _gap2_to(bounds[a, 0], bounds[a, 1], bounds[a, 2], pose, size) <= r * r:
                for s in range(first[a], first[a] + count[a]):
                    r = radius[s]
                    if _gap2_to(centres[s, 0], centres[s, 1], centres[s, 2], pose, size) <= r * r:
                        meets = True
                        break
        if meets:
            out[found] = k
            found += 1
    if found and not posed:
        # Each geometry's pose, for the narrow phase (GJK) of the candidates.
        _pose_geometries(poses, geom_joint, geom_placement, rotation, translation)
    return found


@njit(cache=True, nogil=True)
def first_candidates(states, start, arm_f, arm_i, world_f, world_i, work, out):  # pragma: no cover - compiled
    """`pair_candidates` row by row of the (n, dof) ``states`` from row ``start``, up to the first row whose
    answer is not 0 (a free state with no candidate pair): that row and its answer, the work arrays set for it;
    (n, 0) if every row is free. One call for a segment's states instead of one per state."""
    for r in range(start, states.shape[0]):
        found = pair_candidates(states[r], arm_f, arm_i, world_f, world_i, work, out)
        if found != 0:
            return r, found
    return states.shape[0], 0


@njit(cache=True, nogil=True)
def hand_candidates(ee_pose, part_centres, part_reach, ob_centres, ob_radii, ob_extents, reach, near, out):
    """The (part, obstacle) pairs of a hand at ``ee_pose`` (4x4, world) that may touch, part by part and each
    part's obstacles in order, into ``out`` (k, 2); returns k.

    An obstacle is near when its centre lies within ``reach`` plus its bounding radius of the hand's origin; a
    part may touch a near obstacle when its bounding sphere (centre in the end-effector frame, radius
    ``part_reach``) meets the obstacle's world-aligned bounding box (centre, half extents). ``near`` is workspace
    (one int per obstacle). A pair not returned is certainly apart.
    """
    ox, oy, oz = ee_pose[0, 3], ee_pose[1, 3], ee_pose[2, 3]
    n_near = 0
    for k in range(ob_centres.shape[0]):
        dx, dy, dz = ob_centres[k, 0] - ox, ob_centres[k, 1] - oy, ob_centres[k, 2] - oz
        if math.sqrt(dx * dx + dy * dy + dz * dz) < reach + ob_radii[k]:
            near[n_near] = k
            n_near += 1
    found = 0
    for p in range(part_centres.shape[0]):
        if n_near == 0:
            break
        lx, ly, lz = part_centres[p, 0], part_centres[p, 1], part_centres[p, 2]
        px = ee_pose[0, 0] * lx + ee_pose[0, 1] * ly + ee_pose[0, 2] * lz + ox
        py = ee_pose[1, 0] * lx + ee_pose[1, 1] * ly + ee_pose[1, 2] * lz + oy
        pz = ee_pose[2, 0] * lx + ee_pose[2, 1] * ly + ee_pose[2, 2] * lz + oz
        r2 = part_reach[p] * part_reach[p]
        for i in range(n_near):
            k = near[i]
            total = 0.0
            for over in (
                abs(px - ob_centres[k, 0]) - ob_extents[k, 0],
                abs(py - ob_centres[k, 1]) - ob_extents[k, 1],
                abs(pz - ob_centres[k, 2]) - ob_extents[k, 2],
            ):
                if over > 0.0:
                    total += over * over
            if total <= r2:
                out[found, 0] = p
                out[found, 1] = k
                found += 1
    return found


@njit(cache=True, nogil=True)
def sample_segment(
    first, delta, phases, count, duration, dt, offset, row, times, pos, vel, acc
):  # pragma: no cover
    """Rows ``row`` to ``row + count - 1`` of a sampled trajectory: the straight segment ``first + s delta`` at
    times k dt (k = 1..count, the last clipped to ``duration``), shifted by ``offset`` seconds, with s(t) a
    rest-to-rest profile of seven constant-jerk phases (``phases`` (5, 7): each phase's duration, jerk and its
    start's acceleration, velocity and position). The same floats as evaluating `timing._sample`'s expressions
    with numpy."""
    starts = np.empty(7)
    total = 0.0
    starts[0] = 0.0
    for k in range(1, 7):
        total = total + phases[0, k - 1]
        starts[k] = total
    for n in range(1, count + 1):
        ts = min(n * dt, duration)
        k = 6
        while k > 0 and starts[k] > ts:
            k -= 1
        d = ts - starts[k]
        j, a0, v0, p0 = phases[1, k], phases[2, k], phases[3, k], phases[4, k]
        sp = p0 + d * (v0 + d * (a0 / 2 + d * j / 6))
        sv = v0 + d * (a0 + d * j / 2)
        sa = a0 + d * j
        times[row] = offset + ts
        for c in range(first.shape[0]):
            pos[row, c] = first[c] + sp * delta[c]
            vel[row, c] = sv * delta[c]
            acc[row, c] = sa * delta[c]
        row += 1


@njit(cache=True, nogil=True)
def world_pairs(
    self_pairs, moving, in_hand, reach, first_origin, centres, radii, ignored, held, out
):  # pragma: no cover - compiled
    """A collision world's pairs (kind, a, b) into ``out``, in Pinocchio's order (its pair matrix's upper triangle
    row by row: robot geometries, then obstacles, then the held object); returns how many.

    Robot geometry r is paired with: the geometries of ``self_pairs`` (rows (r, j), j > r, sorted); every obstacle
    o it can reach (``moving[r]``, the obstacle's bounding sphere (centre ``centres[o]``, model frame, radius
    ``radii[o]``) within ``reach[r]`` of the first joint's origin) unless r is part of the hand and ``ignored[o]``;
    the held object (``held``) unless r moves with it or never moves. Each obstacle is paired with the held
    object.
    """
    n_robot, n_ob = moving.shape[0], centres.shape[0]
    distance = np.empty(n_ob)  # from the first joint's origin to each obstacle's centre
    for o in range(n_ob):
        dx, dy, dz = (
            centres[o, 0] - first_origin[0],
            centres[o, 1] - first_origin[1],
            centres[o, 2] - first_origin[2],
        )
        distance[o] = math.sqrt(dx * dx + dy * dy + dz * dz)
    k, s = 0, 0
    for r in range(n_robot):
        while s < self_pairs.shape[0] and self_pairs[s, 0] == r:
            out[k, 0], out[k, 1], out[k, 2] = PAIR_ROBOT, r, self_pairs[s, 1]
            k += 1
            s += 1
        if moving[r]:
            for o in range(n_ob):
                if distance[o] <= reach[r] + radii[o] and not (in_hand[r] and ignored[o]):
                    out[k, 0], out[k, 1], out[k, 2] = PAIR_OBSTACLE, r, o
                    k += 1
            if held and not in_hand[r]:
                out[k, 0], out[k, 1], out[k, 2] = PAIR_HELD, r, -1
                k += 1
    if held:
        for o in range(n_ob):
            out[k, 0], out[k, 1], out[k, 2] = PAIR_HELD_OBSTACLE, -1, o
            k += 1
    return k
