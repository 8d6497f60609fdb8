"""--distractors: the maximum the robot quotes is stocked, one more is a one-line error."""

from __future__ import annotations

import numpy as np
import pytest

from scone_bt.errors import ConfigError
from scone_bt.recipes import load_recipe
from scone_bt.stocking import max_distractors, stock_recipe, stock_shelf


def test_the_quoted_maximum_stands_on_the_shelf_and_one_more_is_refused(kitchen_cfg, kitchen) -> None:
    catalogue, scene = kitchen_cfg.catalogue, kitchen_cfg.scene
    recipe = load_recipe("example:tomato-pasta")
    most = max_distractors(recipe, catalogue, scene)
    assert 6 < most <= len(scene.slots()) - len(stock_recipe(recipe, catalogue).needed)
    with pytest.raises(ConfigError) as refused:
        stock_shelf(recipe, catalogue, scene, most + 1, np.random.default_rng(0))
    message = str(refused.value)
    assert "\n" not in message and f"--distractors {most + 1}: {most} available" in message
    rng = np.random.default_rng(0)
    shelf = stock_shelf(recipe, catalogue, scene, most, rng)
    assert len(shelf.distractors) == most and not set(shelf.distractors) & set(shelf.recipe.needed)
    names = [*shelf.recipe.needed, *shelf.distractors]
    kitchen.spawn([catalogue.get(n) for n in names], rng)  # as the episode stocks it: settled by physics
    assert [n for n in names if not kitchen.is_on_shelf(n)] == []


def test_counts_near_the_maximum_are_stocked_whatever_the_seed(kitchen_cfg) -> None:
    from scone_bt.stocking import plan_stocking

    catalogue, scene = kitchen_cfg.catalogue, kitchen_cfg.scene
    recipe = load_recipe("example:pancakes")
    most = max_distractors(recipe, catalogue, scene)
    for seed in (1, 2, 3):
        for n in (most - 2, most - 1, most):  # seeded draws this crowded never fit as drawn
            rng = np.random.default_rng(seed)
            shelf = stock_shelf(recipe, catalogue, scene, n, rng)
            assert len(shelf.distractors) == n
            plan_stocking(scene, [catalogue.get(x) for x in (*shelf.recipe.needed, *shelf.distractors)], rng)


def test_a_draw_that_fits_is_the_seeded_draw_it_always_was(kitchen_cfg) -> None:
    catalogue, scene = kitchen_cfg.catalogue, kitchen_cfg.scene
    recipe = load_recipe("example:tomato-pasta")
    needed = stock_recipe(recipe, catalogue).needed
    others = [n for n in catalogue.names() if n not in needed]
    expected = [str(n) for n in np.random.default_rng(0).choice(others, size=6, replace=False)]
    assert list(stock_shelf(recipe, catalogue, scene, 6, np.random.default_rng(0)).distractors) == expected


def test_a_recipe_product_wider_than_every_tier_is_named_not_blamed_on_distractors(kitchen_cfg) -> None:
    from dataclasses import replace

    from scone_bt.config import Catalogue
    from scone_bt.stocking import plan_stocking

    recipe = load_recipe("example:tomato-pasta")
    wide = stock_recipe(recipe, kitchen_cfg.catalogue).needed[0]
    catalogue = Catalogue(
        tuple(
            replace(o, size=(0.9, 0.1, 0.2)) if o.name == wide else o for o in kitchen_cfg.catalogue.objects
        )
    )
    needed = [catalogue.get(n) for n in stock_recipe(recipe, catalogue).needed]
    for refuse in (
        lambda: stock_shelf(recipe, catalogue, kitchen_cfg.scene, 6, np.random.default_rng(0)),
        lambda: plan_stocking(kitchen_cfg.scene, needed, np.random.default_rng(0)),  # --distractors 0
    ):
        with pytest.raises(ConfigError) as refused:
            refuse()
        message = str(refused.value)
        assert "\n" not in message and "--distractors" not in message
        assert (
            message.startswith(f"product {wide!r} of family ")
            and "(0.9 x 0.1 x 0.2 m) needs a 0.93 m lane" in message
        )
        assert "longer than every shelf tier (the longest is 0.50 m)" in message
