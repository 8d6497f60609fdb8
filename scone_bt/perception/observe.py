"""One look at the kitchen through every camera: shelf detections for affordances, table detections for placing.

The robot knows what stands on the table only from its table camera: a covered or missing table camera means an
empty table as far as the robot can tell (the planner then meets whatever it did not see).
"""

from __future__ import annotations

import time
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np

from scone_bt.config import Catalogue, KitchenConfig, SceneSpec
from scone_bt.perception.camera import Camera
from scone_bt.perception.detector import Detector, DetectorOptions
from scone_bt.perception.exposure import look
from scone_bt.perception.images import ImageSource
from scone_bt.perception.tracker import Tracker
from scone_bt.perception.types import Detection, Frame

__all__ = ["Observation", "Observer", "merge_detections", "on_table", "free_place_spots"]

FREE_SPOT_CLEARANCE_M = 0.07
"""A table spot is free when no detected object's centre is nearer than this (the rule the kitchen uses)."""


@dataclass(frozen=True, eq=False)
class Observation:
    """What the robot saw at one tick.

    Attributes:
        frame: The first shelf camera's frame (for display).
        frames: Every camera's frame, by camera name.
        detections: Every object seen by any camera, tracked, sorted by name.
        table_detections: The subset standing on the table as the table camera sees it.
    """

    frame: Frame
    frames: dict[str, Frame]
    detections: tuple[Detection, ...]
    table_detections: tuple[Detection, ...]


def merge_detections(per_camera: Iterable[Sequence[Detection]]) -> list[Detection]:
    """One detection per object over several cameras: the most confident one; sorted by name."""
    best: dict[str, Detection] = {}
    for detections in per_camera:
        for det in detections:
            if det.name not in best or det.confidence > best[det.name].confidence:
                best[det.name] = det
    return [best[name] for name in sorted(best)]


def on_table(det: Detection, scene: SceneSpec, catalogue: Catalogue, tolerance_m: float = 0.03) -> bool:
    """True if a detected top face lies over the table with the object's catalogue height above the top."""
    height = catalogue.get(det.name).height
    resting = abs(det.position[2] - scene.table_top_z - height) <= tolerance_m
    return scene.on_table(det.position) and resting


def free_place_spots(
    table_detections: Sequence[Detection], scene: SceneSpec, clearance_m: float = FREE_SPOT_CLEARANCE_M
) -> tuple[tuple[float, float, float], ...]:
    """The kitchen's place spots (x, y, table top z), in order, that no detected object is near."""
    top = scene.table_top_z
    taken = [(d.position[0], d.position[1]) for d in table_detections]
    return tuple(
        (x, y, top)
        for x, y in scene.place_spots
        if all(np.hypot(x - ox, y - oy) > clearance_m for ox, oy in taken)
    )


class Observer:
    """The robot's cameras, one detector and one tracker; `observe` renders, detects and tracks.

    Args:
        kitchen: The kitchen file (cameras, scene and catalogue).
        options: Detector thresholds.
        table_camera: Watch the table (default: if the kitchen file has a table camera).
    """

    def __init__(
        self, kitchen: KitchenConfig, options: DetectorOptions | None = None, table_camera: bool = True
    ) -> None:
        self.config = kitchen
        self.shelf_cameras = [Camera(spec) for spec in kitchen.shelf_cameras]
        table = kitchen.table_camera if table_camera else None
        self.table_camera = Camera(table) if table is not None else None
        self.detector = Detector(kitchen.catalogue, options)
        self.tracker = Tracker()
        self.wall_s = self.cpu_s = 0.0  # spent in observe(), for the episode's time breakdown
        self._last: dict[str, tuple[np.ndarray, np.ndarray, list[Detection]]] = {}

    def _detect(self, camera: str, frame: Frame) -> list[Detection]:
        """The detector's answer, reused when the camera handed back the very same (noise-free) images."""
        last = self._last.get(camera)
        if last is not None and last[0] is frame.rgb and last[1] is frame.depth:
            return list(last[2])
        detections = self.detector.detect(frame)
        # The arrays are kept with the answer, so their identity cannot be reused by new ones.
        self._last[camera] = (frame.rgb, frame.depth, detections)
        return detections

    @property
    def cameras(self) -> list[Camera]:
        return [*self.shelf_cameras, *([self.table_camera] if self.table_camera is not None else [])]

    def observe(self, source: ImageSource, rng: np.random.Generator, exposures: int = 1) -> Observation:
        """Capture every camera from ``source`` (the simulated kitchen re-renders only if the world changed),
        detect, track. ``exposures`` > 1: each camera's frames of the still scene averaged into one, a longer look
        (perception.exposure)."""
        started, started_cpu = time.perf_counter(), time.thread_time()
        frames = {cam.spec.name: look(cam, source, rng, exposures) for cam in self.cameras}
        shelf = [self._detect(cam.spec.name, frames[cam.spec.name]) for cam in self.shelf_cameras]
        scene, catalogue = self.config.scene, self.config.catalogue
        table: list[Detection] = []
        if self.table_camera is not None:
            name = self.table_camera.spec.name
            table = [d for d in self._detect(name, frames[name]) if on_table(d, scene, catalogue)]
        # A shelf camera may glimpse the table's edge too; what stands on the table is the table camera's word.
        shelf_only = [[d for d in dets if not scene.on_table(d.position)] for dets in shelf]
        merged = merge_detections([*shelf_only, table])
        sim_time = frames[self.shelf_cameras[0].spec.name].sim_time
        tracked = tuple(self.tracker.update(merged, sim_time))
        table_names = {d.name for d in table}
        self.wall_s += time.perf_counter() - started
        self.cpu_s += time.thread_time() - started_cpu
        return Observation(
            frame=frames[self.shelf_cameras[0].spec.name],
            frames=frames,
            detections=tracked,
            table_detections=tuple(d for d in tracked if d.name in table_names),
        )
