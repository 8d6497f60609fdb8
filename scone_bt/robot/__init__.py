"""The robot the behaviours talk to: perceive the shelf and the table, run a pick-and-place, report progress.

`Robot` is the interface (docs/robot_interface.md says how a real robot implements it); a `Backend` is a robot with
the world it works in (`World`: the test rig), built by the factory `registry.BACKENDS` names. `SimRobot` is the
PyBullet backend's robot behind ``scone-run --robot sim`` (imported on first use: it loads PyBullet).
"""

from typing import Any

from scone_bt.robot.backend import Backend, BackendFactory, BackendRequest, BackendStats
from scone_bt.robot.interface import MotionHandle, PickRequest, Robot
from scone_bt.robot.registry import BACKENDS, DEFAULT_BACKEND, backend_factory
from scone_bt.robot.rig import HumanWorld, World

__all__ = [
    "BACKENDS",
    "DEFAULT_BACKEND",
    "Backend",
    "BackendFactory",
    "BackendRequest",
    "BackendStats",
    "HumanWorld",
    "MotionHandle",
    "PickRequest",
    "Robot",
    "SimRobot",
    "World",
    "backend_factory",
]


def __getattr__(name: str) -> Any:
    if name == "SimRobot":
        from scone_bt.robot.sim import SimRobot

        return SimRobot
    raise AttributeError(f"module 'scone_bt.robot' has no attribute {name!r}")
