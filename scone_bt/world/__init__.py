"""The simulated kitchen (PyBullet adapter): static scene, the arm, the catalogue's objects, and the clock.

`Kitchen` is imported on first use, so a submodule (`world.visuals`) loads without the whole kitchen.
"""

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from scone_bt.world.kitchen import Kitchen, ObjectState, StaticBox

__all__ = ["Kitchen", "ObjectState", "StaticBox"]


def __getattr__(name: str) -> Any:
    if name in __all__:
        from scone_bt.world import kitchen

        return getattr(kitchen, name)
    raise AttributeError(f"module 'scone_bt.world' has no attribute {name!r}")
