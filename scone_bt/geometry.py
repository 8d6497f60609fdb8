"""Small geometry shared by the stages: angle wrapping."""

from __future__ import annotations

import math
from typing import TypeVar

import numpy as np

__all__ = ["wrap_angle"]

Angle = TypeVar("Angle", float, np.ndarray)


def wrap_angle(angle: Angle, period: float = 2 * math.pi) -> Angle:
    """`angle` (radians, a number or an array) wrapped into [-period/2, period/2).

    The default period is a full turn ([-pi, pi)); `period=np.pi` wraps modulo a half turn ([-pi/2, pi/2)), for a
    shape that looks the same turned by pi (a rectangle, a parallel gripper).
    """
    half = period / 2
    return (angle + half) % period - half
