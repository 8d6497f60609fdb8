"""The human's free table spot (`Kitchen.free_place_spot`) uses the robot's footprint test on ground truth."""

from __future__ import annotations

import numpy as np
import pytest

from scone_bt.motion.placement import Footprint, TableRegion, clear_spots, footprint_gaps

pytestmark = pytest.mark.slow


def test_the_human_packs_cartons_by_their_rectangles(kitchen_cfg, robot_cfg):
    from scone_bt.world import Kitchen

    cartons = sorted(
        (o for o in kitchen_cfg.catalogue.objects if o.shape == "box" and 0.08 <= max(o.size[:2]) <= 0.12),
        key=lambda o: o.name,
    )[:16]
    with Kitchen(kitchen_cfg, robot_cfg) as k:
        k.spawn(cartons, np.random.default_rng(0))
        placed = [c.name for c in cartons if k.human_place_on_table(c.name)]
        k.advance(0.2)
        # Sixteen 8-12 cm cartons fit on the 56 x 50 cm table by their rectangles (by bounding circles, 12).
        assert len(placed) == len(cartons)
        table = TableRegion.from_scene(kitchen_cfg.scene)
        feet = []
        for name in placed:
            st = k.object_state(name)
            yaw = k.bc.getEulerFromQuaternion(st.orientation)[2]
            feet.append(Footprint.of(k.specs[name], st.position[0], st.position[1], yaw))
            assert k.is_on_table(name)
        for i, f in enumerate(feet):
            others = feet[:i] + feet[i + 1 :]
            gaps = footprint_gaps(np.array([[f.x, f.y]]), np.array([f.yaw]), f, others)
            assert gaps.min() > 0.005  # 1 cm when put down; the physics may nudge them a little
            assert clear_spots(table, others, f, np.array([[f.x, f.y]]), f.yaw, 0.0, -0.005).free[0]
        # The next spot the human would pick is one the shared test calls free.
        spec = cartons[0]
        spot = k.free_place_spot(spec)
        if spot is not None:
            assert clear_spots(table, feet, Footprint.of(spec), np.array([spot[:2]]), 0.0, 0.01).free[0]
