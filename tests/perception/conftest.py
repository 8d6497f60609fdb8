"""Helpers for perception tests: put catalogue objects on chosen shelf slots."""

from __future__ import annotations

import numpy as np
import pytest


def place(kitchen, placements: dict[str, tuple[int, int]], yaw: float = 0.0) -> None:
    """Move spawned objects to (tier, slot) of the first shelf unit, upright, then settle.

    tier indexes the unit's tiers; slot indexes the positions of its longest (lowest) row, which the upper tiers
    share even where they list no slot (the camera still sees them there).
    """
    unit = kitchen.config.scene.shelves[0]
    row = max((t.slots for t in unit.tiers), key=len)
    for name, (tier, slot) in placements.items():
        step = unit.tiers[tier]
        x, y = unit.to_world(step.center, row[slot])
        top = step.top_z
        height = kitchen.specs[name].height
        orientation = kitchen.bc.getQuaternionFromEuler((0.0, 0.0, yaw))
        kitchen.bc.resetBasePositionAndOrientation(
            kitchen.objects[name], (x, y, top + height / 2 + 1e-3), orientation
        )
        kitchen.bc.resetBaseVelocity(kitchen.objects[name], (0, 0, 0), (0, 0, 0))
    kitchen.wake()
    kitchen.advance(0.3)


@pytest.fixture
def staged_kitchen(kitchen_cfg, robot_cfg):
    """Factory: a fresh kitchen with the named objects on the given (tier, slot) places."""
    from scone_bt.world import Kitchen

    opened = []

    def make(placements: dict[str, tuple[int, int]], yaw: float = 0.0):
        kitchen = Kitchen(kitchen_cfg, robot_cfg)
        opened.append(kitchen)
        kitchen.spawn([kitchen_cfg.catalogue.get(n) for n in placements], np.random.default_rng(0))
        place(kitchen, placements, yaw)
        return kitchen

    yield make
    for kitchen in opened:
        kitchen.close()
