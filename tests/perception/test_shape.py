"""The perceived shape (scone_bt.perception.context.perceived_size) against the catalogue's true sizes on 200
detections of randomly stocked shelves, in PyBullet (DIRECT) and in MuJoCo: height and depth within 5 mm median,
the width unbiased for boxes and cylinders alike (a round lid's 1–99 % range is scaled: DISC_SPAN), and the lid's
fill tells a cylinder from a box."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import Any

import numpy as np
import pytest

from scone_bt.benchmarks.self_confidence.generate import _fits, drawable_products
from scone_bt.experience.types import ROUND_FILL_BELOW
from scone_bt.perception.context import DISC_SPAN, RECTANGLE_SPAN, execution_contexts
from scone_bt.perception.observe import Observer

pytestmark = pytest.mark.slow

_DETECTIONS = 200
_WIDTH_BIAS_M = 0.002
"""The largest median signed width error per shape (metres): before the round lid was scaled, cylinders measured
2.5 mm (PyBullet) and 3.8 mm (MuJoCo) narrower than they are."""


def _pybullet_stockings(kitchen_cfg, robot_cfg) -> Iterator[Callable[[list[Any], np.random.Generator], Any]]:
    from scone_bt.world import Kitchen

    with Kitchen(kitchen_cfg, robot_cfg) as kitchen:
        start = kitchen.bc.saveState()

        def stock(specs: list[Any], rng: np.random.Generator) -> Any:
            kitchen.clear_products(start)
            kitchen.spawn(specs, rng)
            return kitchen

        yield stock


def _mujoco_stockings(kitchen_cfg, robot_cfg) -> Iterator[Callable[[list[Any], np.random.Generator], Any]]:
    pytest.importorskip("mujoco")
    from scone_bt.world.mj_kitchen import MjKitchen

    kitchens: list[Any] = []

    def stock(specs: list[Any], rng: np.random.Generator) -> Any:
        while kitchens:  # MuJoCo recompiles its model for every stocking anyway: a new kitchen each time
            kitchens.pop().close()
        kitchens.append(MjKitchen(kitchen_cfg, robot_cfg))
        kitchens[-1].spawn(specs, rng)
        return kitchens[-1]

    yield stock
    while kitchens:
        kitchens.pop().close()


_ENGINES = {"pybullet": _pybullet_stockings, "mujoco": _mujoco_stockings}


def test_the_disc_and_rectangle_spans_are_the_one_to_99_percent_ranges() -> None:
    # The disc's share of points left of x·r across one axis; DISC_SPAN is where it reaches 99 %.
    def share(x: float) -> float:
        return 0.5 + (x * np.sqrt(1 - x * x) + np.arcsin(x)) / np.pi

    assert share(DISC_SPAN) == pytest.approx(0.99, abs=1e-5)
    rng = np.random.default_rng(0)
    r, a = np.sqrt(rng.random(400_000)), rng.random(400_000) * 2 * np.pi
    disc = r * np.cos(a)  # x of points spread evenly over a unit disc
    assert float(np.ptp(np.percentile(disc, [1, 99]))) / 2 == pytest.approx(DISC_SPAN, abs=2e-3)
    assert float(np.ptp(np.percentile(rng.random(400_000), [1, 99]))) == pytest.approx(
        RECTANGLE_SPAN, abs=2e-3
    )


@pytest.mark.parametrize("engine", sorted(_ENGINES))
def test_perceived_size_and_shape_match_the_catalogue_on_200_detections(
    engine, kitchen_cfg, robot_cfg
) -> None:
    pool = drawable_products(kitchen_cfg)
    errors: dict[str, list[float]] = {"height": [], "depth": [], "box width": [], "cylinder width": []}
    round_ok: list[bool] = []
    stockings = _ENGINES[engine](kitchen_cfg, robot_cfg)
    stock = next(stockings)
    draw = 0
    while len(round_ok) < _DETECTIONS:
        rng = np.random.default_rng([7, draw])
        draw += 1
        specs = [pool[j] for j in rng.permutation(len(pool))[:10]]
        if not _fits(kitchen_cfg.scene, specs):
            continue
        kitchen = stock(specs, rng)
        kitchen.advance(0.3)
        seen = Observer(kitchen_cfg).observe(kitchen, np.random.default_rng([7, draw, 1]))
        contexts = execution_contexts(
            seen.detections, seen.detections, seen.frames, kitchen_cfg.scene, kitchen_cfg.catalogue
        )
        for name, ctx in contexts.items():
            if ctx.detected_depth_m is None or ctx.detected_height_m is None:
                continue
            spec = kitchen_cfg.catalogue.get(name)
            errors[f"{spec.shape.value} width"].append(ctx.detected_width_m - min(spec.size[:2]))
            errors["height"].append(abs(ctx.detected_height_m - spec.height))
            errors["depth"].append(abs(ctx.detected_depth_m - max(spec.size[:2])))
            round_ok.append((ctx.detected_fill < ROUND_FILL_BELOW) == (spec.shape.value == "cylinder"))
    stockings.close()
    median = {k: float(np.median(v)) for k, v in errors.items()}
    assert median["height"] <= 0.005 and median["depth"] <= 0.005, median
    assert len(errors["box width"]) >= 50 and len(errors["cylinder width"]) >= 50, median
    assert abs(median["box width"]) <= _WIDTH_BIAS_M and abs(median["cylinder width"]) <= _WIDTH_BIAS_M, (
        median
    )
    assert np.mean(round_ok) >= 0.9, np.mean(round_ok)
