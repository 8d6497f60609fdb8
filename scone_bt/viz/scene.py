"""What a recording draws of the world: the fixed scene once, then the arm's and the products' poses every tick.

`world.Kitchen` has it; a real robot's backend provides it from its URDF, joint states and a scene description
(or not at all: its episodes are then not recorded).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Protocol

if TYPE_CHECKING:
    import numpy as np

    from scone_bt.config import KitchenConfig, ObjectSpec, RobotConfig
    from scone_bt.motion.executor import SceneBox

__all__ = ["ObjectPose", "SceneView"]


class ObjectPose(Protocol):
    """A product's pose: position (m) and quaternion (x, y, z, w), world frame."""

    @property
    def position(self) -> tuple[float, float, float]: ...

    @property
    def orientation(self) -> tuple[float, float, float, float]: ...


class SceneView(Protocol):
    """The world as a recording sees it."""

    @property
    def config(self) -> KitchenConfig:
        """The kitchen's configuration (scene boxes, the camera)."""
        ...

    @property
    def robot_config(self) -> RobotConfig:
        """The arm (its URDF draws it)."""
        ...

    @property
    def specs(self) -> Mapping[str, ObjectSpec]:
        """The products in the world by name (a live mapping: products added later appear in it)."""
        ...

    @property
    def static_boxes(self) -> Sequence[SceneBox]:
        """The fixed scene: shelves, table, pedestal."""
        ...

    @property
    def objects(self) -> Mapping[str, object]:
        """The products' names (the keys; the values are the backend's own handles)."""
        ...

    @property
    def sim_time(self) -> float:
        """Seconds since the episode started."""
        ...

    def object_state(self, name: str) -> ObjectPose:
        """The product's pose now."""
        ...

    def link_poses(self) -> dict[str, tuple[tuple[float, ...], tuple[float, ...]]]:
        """Every arm link's pose by link name."""
        ...

    def arm_joint_positions(self) -> np.ndarray:
        """The arm's joint angles now, radians."""
        ...
