"""Typed views of the declarative inputs: robots/*.yaml, perception/kitchen.yaml, trees/*.yaml."""

from scone_bt.config.kitchen import (
    CameraSpec,
    Catalogue,
    KitchenConfig,
    ObjectSpec,
    SceneSpec,
    load_kitchen,
)
from scone_bt.config.robot import GripperSpec, LimitsSpec, PlannerSpec, RobotConfig, load_robot
from scone_bt.config.yaml_io import read_yaml

__all__ = [
    "CameraSpec",
    "Catalogue",
    "GripperSpec",
    "KitchenConfig",
    "LimitsSpec",
    "ObjectSpec",
    "PlannerSpec",
    "RobotConfig",
    "SceneSpec",
    "load_kitchen",
    "load_robot",
    "read_yaml",
]
