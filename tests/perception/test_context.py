"""Execution contexts from one tick's perception (PyBullet DIRECT): tier, clearance and neighbours from the
detections, width and height from the depth frames, all close to the simulator's truth."""

from __future__ import annotations

import numpy as np
import pytest

from scone_bt.config.footprint import footprint
from scone_bt.perception.context import ALONE_CLEARANCE_M, execution_contexts, shelf_place, surface_below
from scone_bt.perception.observe import Observer

pytestmark = pytest.mark.slow


def test_contexts_from_detections_and_depth_match_the_simulation(staged_kitchen, kitchen_cfg) -> None:
    placed = {"salt": (0, 0), "sugar": (0, 1), "honey": (2, 3)}
    kitchen = staged_kitchen(placed)
    seen = Observer(kitchen_cfg).observe(kitchen, np.random.default_rng(0))
    by_name = {d.name: d for d in seen.detections}
    assert set(placed) <= set(by_name)
    scene, catalogue = kitchen_cfg.scene, kitchen_cfg.catalogue
    contexts = execution_contexts(list(by_name.values()), seen.detections, seen.frames, scene, catalogue)
    for name, (tier, _) in placed.items():
        ctx, spec = contexts[name], catalogue.get(name)
        assert ctx.shelf_tier == tier and ctx.detected is True
        # The depth image measures the lid and the height above the step to within a centimetre.
        assert ctx.detected_width_m == pytest.approx(min(spec.size[:2]), abs=0.01), name
        assert ctx.detected_height_m == pytest.approx(spec.height, abs=0.01), name
    # salt and sugar share a tier one slot apart: the gap between their sides, as the simulation has it.
    unit = scene.shelves[0]
    v = {n: unit.to_unit(*kitchen.object_state(n).position[:2])[1] for n in ("salt", "sugar")}
    half = {n: footprint(catalogue.get(n), 0.0)[1] / 2 for n in v}
    true_gap = abs(v["salt"] - v["sugar"]) - half["salt"] - half["sugar"]
    assert contexts["salt"].clearance_m == pytest.approx(max(0.0, true_gap), abs=0.01)
    assert contexts["salt"].neighbours == contexts["sugar"].neighbours == 1
    # honey stands alone on the top tier.
    assert contexts["honey"].clearance_m == ALONE_CLEARANCE_M and contexts["honey"].neighbours == 0


def test_a_size_that_cannot_be_measured_is_unknown(staged_kitchen, kitchen_cfg) -> None:
    kitchen = staged_kitchen({"salt": (0, 0)})
    seen = Observer(kitchen_cfg).observe(kitchen, np.random.default_rng(0))
    (salt,) = [d for d in seen.detections if d.name == "salt"]
    (ctx,) = execution_contexts(
        [salt], seen.detections, {}, kitchen_cfg.scene, kitchen_cfg.catalogue
    ).values()
    assert ctx.detected_width_m is None and ctx.detected_height_m is None and ctx.shelf_tier == 0


def test_shelf_place_names_the_step_under_a_point(kitchen_cfg) -> None:
    scene = kitchen_cfg.scene
    unit = scene.shelves[0]
    for i, tier in enumerate(unit.tiers):
        x, y = unit.to_world(tier.center, sum(unit.span) / 2)
        assert shelf_place(scene, (x, y, tier.top_z + 0.05)) == (unit.name, i)
        assert surface_below(scene, x, y, tier.top_z + 0.05) == tier.top_z
    assert shelf_place(scene, (*scene.place_spots[0], scene.table_top_z + 0.05)) is None


def test_the_extractor_measures_a_product_again_only_when_it_moved(staged_kitchen, kitchen_cfg) -> None:
    from dataclasses import replace

    from scone_bt.perception.context import ContextExtractor

    kitchen = staged_kitchen({"salt": (0, 0), "sugar": (0, 1)})
    seen = Observer(kitchen_cfg).observe(kitchen, np.random.default_rng(0))
    extract = ContextExtractor(kitchen_cfg.scene, kitchen_cfg.catalogue)
    first = extract(seen.detections, seen.detections, seen.frames)
    assert extract.measured == 2 and extract(seen.detections, seen.detections, seen.frames) == first
    assert extract.measured == 2  # nothing moved: the sizes are the ones measured
    salt = next(d for d in seen.detections if d.name == "salt")
    moved = replace(salt, position=(salt.position[0], salt.position[1] + 0.02, salt.position[2]))
    extract([moved], seen.detections, seen.frames)
    assert extract.measured == 3
    extract([salt], seen.detections, {})  # no frames: unmeasurable, and not remembered as such
    extract([salt], seen.detections, {})
    assert extract.measured == 5
