"""The robot the behaviours talk to: perceive the shelf and the table, run a pick-and-place, report progress.

`Robot` is the interface (docs/robot_interface.md says how a real robot implements it); `SimRobot` is the PyBullet
backend behind ``scone-run --robot sim`` (imported on first use: it loads PyBullet).
"""

from typing import Any

from scone_bt.robot.interface import BACKENDS, MotionHandle, PickRequest, Robot

__all__ = ["BACKENDS", "MotionHandle", "PickRequest", "Robot", "SimRobot"]


def __getattr__(name: str) -> Any:
    if name == "SimRobot":
        from scone_bt.robot.sim import SimRobot

        return SimRobot
    raise AttributeError(f"module 'scone_bt.robot' has no attribute {name!r}")
