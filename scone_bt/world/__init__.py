"""The simulated kitchen (PyBullet adapter): static scene, the arm, the catalogue's objects, and the clock."""

from scone_bt.world.kitchen import Kitchen, ObjectState, StaticBox

__all__ = ["Kitchen", "ObjectState", "StaticBox"]
