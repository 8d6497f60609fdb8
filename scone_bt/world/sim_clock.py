"""A simulated kitchen's clock, whatever engine runs it: the controllers run before every step, and how long the
physics keeps stepping after a change (the PyBullet `world.Kitchen` and the MuJoCo `world.mj_kitchen.MjKitchen`).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

__all__ = ["REST_ANGULAR_RAD_S", "REST_JOINT_RAD_S", "REST_LINEAR_M_S", "WAKE_S", "SimClock"]

REST_LINEAR_M_S = 1e-3
"""A body slower than this (m/s, every axis) counts as at rest."""
REST_ANGULAR_RAD_S = 1e-2
"""... and turning slower than this (rad/s, every axis)."""
REST_JOINT_RAD_S = 1e-3
"""A robot joint slower than this (rad/s) counts as at rest."""
WAKE_S = 0.5
"""Simulated seconds the physics keeps stepping after the world was changed from outside."""


class SimClock:
    """The controllers and the wake-up time of a kitchen whose ``sim_time`` (s) its engine advances.

    ``state_version`` is bumped whenever the world may look different (cameras re-render only then).
    """

    sim_time: float
    state_version: int
    _controllers: list[Callable[[Any], None]]
    _awake_until: float

    def add_controller(self, controller: Callable[[Any], None]) -> None:
        """Call ``controller(kitchen)`` before every step from now on."""
        self._controllers.append(controller)
        self._keep_stepping()

    def remove_controller(self, controller: Callable[[Any], None]) -> None:
        if controller in self._controllers:
            self._controllers.remove(controller)
            self._keep_stepping()

    def wake(self, seconds: float = WAKE_S) -> None:
        """Step the physics for at least ``seconds`` from now, even if all is at rest."""
        self._keep_stepping(seconds)

    def _keep_stepping(self, seconds: float = WAKE_S) -> None:
        self._awake_until = max(self._awake_until, self.sim_time + seconds)
        self.state_version += 1
