"""Small geometry shared by the stages: angle wrapping and unit quaternions (x, y, z, w), in numpy alone (the
recorder would otherwise load scipy for three rotations, a sixth of a second)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TypeVar

import numpy as np

__all__ = ["wrap_angle", "quat_multiply", "quat_inverse", "quat_rotate"]

Angle = TypeVar("Angle", float, np.ndarray)


def wrap_angle(angle: Angle, period: float = 2 * math.pi) -> Angle:
    """`angle` (radians, a number or an array) wrapped into [-period/2, period/2).

    The default period is a full turn ([-pi, pi)); `period=np.pi` wraps modulo a half turn ([-pi/2, pi/2)), for a
    shape that looks the same turned by pi (a rectangle, a parallel gripper).
    """
    half = period / 2
    return (angle + half) % period - half


def quat_multiply(a: np.ndarray | Sequence[float], b: np.ndarray | Sequence[float]) -> np.ndarray:
    """The rotation ``a`` after ``b`` (Hamilton product a · b), quaternions (x, y, z, w)."""
    ax, ay, az, aw = (float(v) for v in a)
    bx, by, bz, bw = (float(v) for v in b)
    return np.array(
        [
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
            aw * bw - ax * bx - ay * by - az * bz,
        ]
    )


def quat_inverse(q: np.ndarray | Sequence[float]) -> np.ndarray:
    """The inverse rotation of a unit quaternion (x, y, z, w): its conjugate."""
    x, y, z, w = (float(v) for v in q)
    return np.array([-x, -y, -z, w])


def quat_rotate(q: np.ndarray | Sequence[float], v: np.ndarray | Sequence[float]) -> np.ndarray:
    """Vector ``v`` (3,) turned by the unit quaternion ``q`` (x, y, z, w)."""
    u = np.array([float(c) for c in q[:3]])
    w = float(q[3])
    v = np.asarray(v, dtype=float)
    t = 2.0 * np.cross(u, v)
    return v + w * t + np.cross(u, t)
