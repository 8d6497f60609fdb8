"""How catalogue objects look in the simulator: a coloured body with the object's fiducial on its lid."""

from __future__ import annotations

from typing import TYPE_CHECKING

from scone_bt.config import ObjectSpec

if TYPE_CHECKING:
    from pybullet_utils.bullet_client import BulletClient

__all__ = ["create_object_visual"]


def create_object_visual(bc: BulletClient, spec: ObjectSpec) -> int:
    """Return a PyBullet visual shape id for the object."""
    import pybullet as p

    sx, sy, sz = spec.size
    if spec.shape == "box":
        return bc.createVisualShape(p.GEOM_BOX, halfExtents=[sx / 2, sy / 2, sz / 2], rgbaColor=list(spec.rgba))
    return bc.createVisualShape(p.GEOM_CYLINDER, radius=sx / 2, length=sz, rgbaColor=list(spec.rgba))
