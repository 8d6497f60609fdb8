"""What stands on the shelf in an episode: the recipe's products and the distractors, side by side.

`--distractors N` puts N products the recipe never uses on the shelf beside the recipe's own. The recipe's
products past the slots the distractors leave stay off the shelf (the human brings them, like unstocked ones).
The most distractors an episode accepts is the most that *fit* (`max_distractors`): the shelving's lanes must
hold every product side by side, which counts widths, not only slots. Any N up to it is stocked:

1. the seeded draw of N products, if the stocking plan (`plan_stocking`, with the same generator) takes it, as it
   always has;
2. otherwise the drawn products that still fit (`fits_side_by_side`), in drawn order, then the narrowest others
   that fit;
3. otherwise the N narrowest, which fit whenever N is at most the maximum.
"""

from __future__ import annotations

import copy
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from scone_bt.config import Catalogue, SceneSpec
from scone_bt.errors import ConfigError
from scone_bt.recipes.recipe import Recipe
from scone_bt.stocking.lanes import lane_width
from scone_bt.stocking.needs import ProductIndex, StockedRecipe, stock_recipe
from scone_bt.stocking.pack import fits_side_by_side, wider_than_every_tier
from scone_bt.stocking.place import plan_stocking

__all__ = ["ShelfStock", "max_distractors", "stock_shelf"]


@dataclass(frozen=True)
class ShelfStock:
    """The recipe as stocked beside the distractors, and the distractors (catalogue names, in drawn order)."""

    recipe: StockedRecipe
    distractors: tuple[str, ...]


def _narrowest_first(names: Sequence[str], catalogue: Catalogue, scene: SceneSpec) -> list[str]:
    """``names`` by the widest lane each takes on any shelf unit, narrowest first (ties keep their order)."""
    return sorted(names, key=lambda n: max(lane_width(catalogue.get(n), u) for u in scene.shelves))


def _max_and_narrowest(
    order: Sequence[str],
    others: Sequence[str],
    catalogue: Catalogue,
    scene: SceneSpec,
    upto: int | None = None,
) -> tuple[int, list[str]]:
    """The maximum (-1: not even the recipe's products fit), looked for up to ``upto`` (None: all the way), and
    ``others`` narrowest first."""
    slots = len(scene.slots())
    narrow = _narrowest_first(others, catalogue, scene)
    best = -1
    limit = min(len(others), slots) if upto is None else min(len(others), slots, upto)
    for n in range(limit + 1):
        needed = order[: max(slots - n, 0)]  # the recipe's products that keep a slot beside n distractors
        if not fits_side_by_side(scene, [catalogue.get(x) for x in (*needed, *narrow[:n])]):
            break  # every smaller N fits: the maximum is the last N before the first that does not
        best = n
    return best, narrow


def max_distractors(recipe: Recipe, catalogue: Catalogue, scene: SceneSpec) -> int:
    """The most distractors this recipe and shelving accept: every N up to it is stocked side by side.

    0 when the recipe's own products do not fit side by side (the stocking plan may still find room for them).
    """
    order = stock_recipe(recipe, catalogue).needed
    others = [n for n in catalogue.names() if n not in order]
    return max(_max_and_narrowest(order, others, catalogue, scene)[0], 0)


def _stocks(scene: SceneSpec, names: Sequence[str], catalogue: Catalogue, rng: np.random.Generator) -> bool:
    """Whether `plan_stocking` takes these products with this generator (a copy: ``rng`` does not move)."""
    try:
        plan_stocking(scene, [catalogue.get(n) for n in names], copy.deepcopy(rng))
    except ConfigError:
        return False
    return True


def stock_shelf(
    recipe: Recipe,
    catalogue: Catalogue,
    scene: SceneSpec,
    distractors: int,
    rng: np.random.Generator,
    option: str = "--distractors",
) -> ShelfStock:
    """The recipe stocked beside ``distractors`` products it never uses, drawn from ``rng`` (module docstring).

    ``option`` is what the user wrote the count as (the command line's flag, a scenario's ``world.distractors``),
    named by the error.

    Raises:
        ConfigError: More distractors than fit side by side (the message gives the maximum).
    """
    index = ProductIndex(catalogue)
    order = stock_recipe(recipe, catalogue, index=index).needed
    # A product of the recipe left off the shelf is the human's to bring: never a distractor.
    others = [n for n in catalogue.names() if n not in order]
    best, narrow = _max_and_narrowest(order, others, catalogue, scene)
    slots = len(scene.slots())
    if best < 0 and distractors > 0:  # the recipe's own products do not fit: not a matter of distractors
        too_wide = wider_than_every_tier(scene, [catalogue.get(n) for n in order])
        if too_wide is not None:
            raise ConfigError(too_wide)
    if distractors > max(best, 0):
        raise ConfigError(
            f"{option} {distractors}: {max(best, 0)} available for this recipe and shelf "
            f"({len(others)} other products, {slots} slots; more do not fit the shelving side by side)"
        )
    stocked = stock_recipe(recipe, catalogue, capacity=max(slots - distractors, 0), index=index)
    if distractors == 0:
        return ShelfStock(stocked, ())
    drawn = [str(n) for n in rng.choice(others, size=distractors, replace=False)]
    if _stocks(scene, [*stocked.needed, *drawn], catalogue, rng):
        return ShelfStock(stocked, tuple(drawn))
    # The draw crowds the shelving: keep the drawn products that still fit, then the narrowest others.
    specs = {n: catalogue.get(n) for n in (*stocked.needed, *drawn, *narrow[:distractors])}

    def fits(names: Sequence[str]) -> bool:
        return fits_side_by_side(scene, [specs[x] for x in (*stocked.needed, *names)])

    chosen: list[str] = []
    for n in drawn:
        if fits([*chosen, n]):
            chosen.append(n)
    for n in (n for n in narrow[:distractors] if n not in chosen):
        if len(chosen) == distractors or not fits([*chosen, n]):
            break  # the narrowest left does not fit: no wider one will
        chosen.append(n)
    if len(chosen) < distractors:
        chosen = narrow[:distractors]  # fits: distractors ≤ the maximum, found with these
    return ShelfStock(stocked, tuple(chosen))
