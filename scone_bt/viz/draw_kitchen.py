"""Draws the kitchen: its static boxes (shelving, table, pedestal, floor) and the products standing in it."""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import rerun as rr

from scone_bt.config.catalogue import Shape
from scone_bt.viz import paths as P
from scone_bt.viz.colours import SCENE_COLOURS, SHELF_COLOUR, rgba255
from scone_bt.viz.pose_batch import MovedFilter, PoseBatch
from scone_bt.viz.render import slug
from scone_bt.viz.sinks import Sinks
from scone_bt.viz.snapshot import Pose

if TYPE_CHECKING:
    from scone_bt.config import ObjectSpec
    from scone_bt.viz.scene import SceneView

__all__ = ["OBJECT_FRAME", "KitchenDrawer"]

OBJECT_FRAME = "object"
"""Products' transform frame ids are object/<name>."""


class KitchenDrawer:
    """The kitchen's static boxes once; each product's shape when first seen, and its pose when it moved."""

    def __init__(self, sinks: Sinks, poses: PoseBatch) -> None:
        self._sinks = sinks
        self._poses = poses
        self._specs: Mapping[str, ObjectSpec] = {}
        self._moved = MovedFilter()
        self._objects_drawn: set[str] = set()

    def log_static(self, kitchen: SceneView) -> None:
        """The world's axes, the static boxes and the floor (static: the same at every time)."""
        rec = self._sinks.rec
        rec.log(P.WORLD, rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
        for box in kitchen.static_boxes:
            colour = SCENE_COLOURS.get(box.name, SHELF_COLOUR)
            rec.log(
                f"{P.SCENE}/{slug(box.name)}",
                rr.Boxes3D(centers=[box.center], sizes=[box.size], colors=[colour], fill_mode="solid"),
                static=True,
            )
        scene = kitchen.config.scene
        rec.log(
            f"{P.SCENE}/floor",
            rr.Boxes3D(
                centers=[(0.3, 0.0, scene.floor_z - 0.005)],
                sizes=[(2.0, 2.0, 0.01)],
                colors=[SCENE_COLOURS["floor"]],
                fill_mode="solid",
            ),
            static=True,
        )

    def follow_specs(self, specs: Mapping[str, ObjectSpec]) -> None:
        """Draw products by these specs (a live reference: objects spawned later are drawn when first seen)."""
        self._specs = specs

    def log_objects(self, poses: Mapping[str, Pose]) -> None:
        """Each product's geometry the first time it is seen; its pose (into the tick's batch) when it moved."""
        for name in poses:
            if name not in self._objects_drawn:
                self._objects_drawn.add(name)
                self._log_object_geometry(name, f"{P.OBJECTS}/{slug(name)}", f"{OBJECT_FRAME}/{name}")
        for name in self._moved.moved(poses):
            self._poses.add(f"{OBJECT_FRAME}/{name}", poses[name])

    def _log_object_geometry(self, name: str, entity: str, frame: str) -> None:
        spec = self._specs.get(name)
        if spec is None:  # not from the catalogue: a marker-sized cube keeps it visible
            geometry: Any = rr.Boxes3D(
                sizes=[(0.05, 0.05, 0.05)], labels=[name], colors=[(200, 200, 200)], fill_mode="solid"
            )
        elif spec.shape == Shape.BOX:
            geometry = rr.Boxes3D(
                sizes=[spec.size], colors=[rgba255(spec.rgba)], labels=[name], fill_mode="solid"
            )
        else:
            geometry = rr.Cylinders3D(
                lengths=[spec.size[2]],
                radii=[spec.size[0] / 2],
                colors=[rgba255(spec.rgba)],
                labels=[name],
                fill_mode="solid",
            )
        self._sinks.rec.log(entity, rr.CoordinateFrame(frame), geometry, static=True)
