"""Which catalogue objects a recipe's steps need, i.e. what the robot can fetch for each step."""

from __future__ import annotations

import re
from dataclasses import dataclass

from scone_bt.config import Catalogue
from scone_bt.errors import RecipeError
from scone_bt.recipes.recipe import Recipe

__all__ = ["StockedStep", "StockedRecipe", "match_catalogue", "stock_recipe"]


@dataclass(frozen=True)
class StockedStep:
    """One instruction and the catalogue objects that must be on the table before it can be done."""

    instruction: str
    objects: tuple[str, ...]


@dataclass(frozen=True)
class StockedRecipe:
    """A recipe mapped onto a kitchen.

    Attributes:
        recipe: The source recipe.
        steps: One StockedStep per recipe step (objects may be empty: the human does that step alone).
        needed: Every catalogue object the recipe needs, in first-use order.
        unstocked: Ingredient strings no catalogue object matches (the human brings those).
    """

    recipe: Recipe
    steps: tuple[StockedStep, ...]
    needed: tuple[str, ...]
    unstocked: tuple[str, ...]


def _patterns(catalogue: Catalogue) -> list[tuple[re.Pattern[str], str]]:
    pairs = [(alias.lower(), obj.name) for obj in catalogue.objects for alias in (obj.name, *obj.aliases)]
    # Longest alias first so "olive oil" wins over "oil" and "canned tomatoes" over "tomatoes".
    pairs.sort(key=lambda p: -len(p[0]))
    return [(re.compile(rf"\b{re.escape(alias)}\b"), name) for alias, name in pairs]


def match_catalogue(text: str, catalogue: Catalogue) -> list[str]:
    """Catalogue objects named in a text, in order of first mention, each once."""
    lowered = text.lower()
    hits: list[tuple[int, str]] = []
    taken = [False] * len(lowered)
    for pattern, name in _patterns(catalogue):
        for m in pattern.finditer(lowered):
            if any(taken[m.start() : m.end()]):
                continue
            for i in range(m.start(), m.end()):
                taken[i] = True
            hits.append((m.start(), name))
    seen: list[str] = []
    for _, name in sorted(hits):
        if name not in seen:
            seen.append(name)
    return seen


def stock_recipe(recipe: Recipe, catalogue: Catalogue) -> StockedRecipe:
    """Map ingredients to catalogue objects and assign each object to the first step that uses it."""
    ingredient_objects: list[str] = []
    unstocked: list[str] = []
    for ingredient in recipe.ingredients:
        names = match_catalogue(ingredient, catalogue)
        if not names:
            unstocked.append(ingredient)
        for n in names:
            if n not in ingredient_objects:
                ingredient_objects.append(n)
    used: set[str] = set()
    steps = []
    for i, instruction in enumerate(recipe.steps):
        text = instruction
        if recipe.step_ingredients is not None and recipe.step_ingredients[i]:
            text = " ; ".join(recipe.step_ingredients[i]) + " ; " + instruction
        mentioned = [n for n in match_catalogue(text, catalogue) if n in ingredient_objects and n not in used]
        used.update(mentioned)
        steps.append(StockedStep(instruction, tuple(mentioned)))
    if not used:
        raise RecipeError(
            f"recipe {recipe.id!r} needs nothing this kitchen stocks; stocked items: {', '.join(catalogue.names())}"
        )
    needed = tuple(n for s in steps for n in s.objects)
    return StockedRecipe(recipe, tuple(steps), needed, tuple(unstocked))
