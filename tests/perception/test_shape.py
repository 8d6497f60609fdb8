"""The perceived shape (scone_bt.perception.context.perceived_size) against the catalogue's true sizes on 200
detections of randomly stocked shelves (PyBullet DIRECT): height and depth within 5 mm median, and the lid's fill
tells a cylinder from a box."""

from __future__ import annotations

import numpy as np
import pytest

from scone_bt.benchmarks.self_confidence.generate import _fits, drawable_products
from scone_bt.confidence.physical import _ROUND_BELOW
from scone_bt.perception.context import execution_contexts
from scone_bt.perception.observe import Observer

pytestmark = pytest.mark.slow

_DETECTIONS = 200


def test_perceived_height_depth_and_shape_match_the_catalogue_on_200_detections(
    kitchen_cfg, robot_cfg
) -> None:
    from scone_bt.world import Kitchen

    pool = drawable_products(kitchen_cfg)
    errors: dict[str, list[float]] = {"width": [], "height": [], "depth": []}
    round_ok: list[bool] = []
    with Kitchen(kitchen_cfg, robot_cfg) as kitchen:
        start = kitchen.bc.saveState()
        draw = 0
        while len(round_ok) < _DETECTIONS:
            rng = np.random.default_rng([7, draw])
            draw += 1
            specs = [pool[j] for j in rng.permutation(len(pool))[:10]]
            if not _fits(kitchen_cfg.scene, specs):
                continue
            kitchen.clear_products(start)
            kitchen.spawn(specs, rng)
            kitchen.advance(0.3)
            seen = Observer(kitchen_cfg).observe(kitchen, np.random.default_rng([7, draw, 1]))
            contexts = execution_contexts(
                seen.detections, seen.detections, seen.frames, kitchen_cfg.scene, kitchen_cfg.catalogue
            )
            for name, ctx in contexts.items():
                if ctx.detected_depth_m is None or ctx.detected_height_m is None:
                    continue
                spec = kitchen_cfg.catalogue.get(name)
                errors["width"].append(abs(ctx.detected_width_m - min(spec.size[:2])))
                errors["height"].append(abs(ctx.detected_height_m - spec.height))
                errors["depth"].append(abs(ctx.detected_depth_m - max(spec.size[:2])))
                round_ok.append((ctx.detected_fill < _ROUND_BELOW) == (spec.shape.value == "cylinder"))
    median = {k: float(np.median(v)) for k, v in errors.items()}
    assert median["height"] <= 0.005 and median["depth"] <= 0.005, median
    assert median["width"] <= 0.005, median
    assert np.mean(round_ok) >= 0.9, np.mean(round_ok)
