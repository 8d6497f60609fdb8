"""A longer look: several frames of a still scene averaged into one, before the robot says it cannot see a product.

A cheap RGB-D camera's pixel noise is independent from frame to frame, so the mean of n frames of a scene that
does not move has 1/√n of the noise. The fiducial markers on small lids are what noise destroys first (the
``p04_noisy_camera`` profile: image noise std 45 on the 0–255 scale): before this, a target missed in one frame was
asked for at once. The robot looks again with `LOOK_AGAIN_EXPOSURES` frames once per product it needs and sees
nowhere (behaviours.gate_steps.look_again_first, the tree's Perceive; the dataset generator alike), and asks only if
the longer look misses it too. Chosen on the development stream of ``p04_noisy_camera`` (tools/data/sc_probe): of
the 15 targets one frame missed there, the mean of 4, 8 and 16 frames found 9, 12 and 13; 8 it is. A 60 Hz
camera takes them in about 0.13 s; the robot waits one control tick (0.1 s) for the look, and the simulation does
not charge the difference.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from scone_bt.errors import ConfigError
from scone_bt.perception.types import Frame

if TYPE_CHECKING:
    from scone_bt.perception.camera import Camera
    from scone_bt.perception.images import ImageSource

__all__ = ["LOOK_AGAIN_EXPOSURES", "averaged", "look"]

LOOK_AGAIN_EXPOSURES = 8
"""Frames per camera averaged when the robot looks again for a product it sees nowhere (noise / √8)."""


def averaged(frames: Sequence[Frame]) -> Frame:
    """One frame from several of the same camera: the mean colour (rounded to uint8) and the mean depth, with the
    first frame's intrinsics, pose and time.

    Raises:
        ConfigError: no frame, or frames of different sizes or cameras.
    """
    if not frames:
        raise ConfigError("averaged: no frame to average (exposures must be ≥ 1)")
    first = frames[0]
    if len(frames) == 1:
        return first
    for f in frames[1:]:
        same_pose = np.array_equal(f.world_from_camera, first.world_from_camera)
        if f.rgb.shape != first.rgb.shape or f.depth.shape != first.depth.shape or not same_pose:
            raise ConfigError("averaged: frames of different cameras or sizes cannot be averaged")
    rgb = np.mean([f.rgb.astype(np.float32) for f in frames], axis=0)
    depth = np.mean([f.depth for f in frames], axis=0).astype(np.float32)
    return Frame(
        rgb=np.clip(np.rint(rgb), 0, 255).astype(np.uint8),
        depth=depth,
        intrinsics=first.intrinsics.copy(),
        world_from_camera=first.world_from_camera.copy(),
        sim_time=float(first.sim_time),
    )


def look(camera: Camera, source: ImageSource, rng: np.random.Generator, exposures: int = 1) -> Frame:
    """One frame of ``camera`` from ``source``, or the mean of ``exposures`` frames of the still scene, each with its
    noise drawn afresh from ``rng`` (the robot's looks and the dataset generator's alike)."""
    if exposures <= 1:
        return camera.capture(source, rng)
    return averaged([camera.capture(source, rng) for _ in range(exposures)])
