"""What a simulated kitchen's helpers read of it, as Protocols that the kitchen and its helpers both import.

The kitchens (`world.kitchen.Kitchen` on PyBullet, `world.mj_kitchen.MjKitchen` on MuJoCo) hand themselves to
their helpers (arm I/O, cameras, the render cache); the helpers name these narrow views rather than the kitchen's
own class, so that the types point one way: from the kitchen to its helpers.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Protocol

if TYPE_CHECKING:
    from scone_bt.config import RobotConfig

__all__ = ["BulletParts", "MjParts"]


class BulletParts(Protocol):
    """The PyBullet kitchen's bodies and client, as its arm I/O, cameras and render cache read them."""

    @property
    def bc(self) -> Any:
        """The kitchen's own PyBullet client (`pybullet_utils.bullet_client.BulletClient`)."""
        ...

    @property
    def robot_id(self) -> int: ...

    @property
    def joint_index(self) -> dict[str, int]:
        """Joint name → PyBullet joint index."""
        ...

    @property
    def robot_config(self) -> RobotConfig: ...

    @property
    def objects(self) -> dict[str, int]:
        """Product name → body id."""
        ...

    @property
    def static_body_ids(self) -> dict[str, int]:
        """Static box name → body id."""
        ...

    @property
    def floor_id(self) -> int: ...

    @property
    def uid(self) -> int:
        """Changes whenever the kitchen's bodies may have (a camera's last image is then stale)."""
        ...

    @property
    def static_key(self) -> tuple[object, ...]:
        """Identifies the static scene (a background rendered of it is reused across kitchens with one key)."""
        ...


class MjParts(Protocol):
    """The MuJoCo kitchen's model and data, as its cameras read them."""

    @property
    def mujoco(self) -> Any:
        """The `mujoco` module."""
        ...

    @property
    def model(self) -> Any: ...

    @property
    def data(self) -> Any: ...

    @property
    def model_version(self) -> int:
        """Counts model compiles (a renderer of an older model is rebuilt)."""
        ...

    @property
    def uid(self) -> int: ...

    @property
    def robot_bodies(self) -> frozenset[int]: ...

    @property
    def objects(self) -> dict[str, int]: ...
