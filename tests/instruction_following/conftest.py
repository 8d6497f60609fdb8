"""Tiny hand-made recipes and states for the IF tests."""

from __future__ import annotations

import pytest

from scone_bt.instruction_following.states import IfState
from scone_bt.recipes.recipe import Recipe


@pytest.fixture
def hummus() -> Recipe:
    return Recipe(
        id="test:hummus",
        title="Hummus",
        ingredients=(
            "1 can chickpeas, drained",
            "2 Tbsp tahini",
            "1 lemon",
            "2 cloves of garlic",
            "salt",
            "water",
        ),
        steps=(
            "Blend the chickpeas with the tahini.",
            "Add the garlic and a little water.",
            "Rinse the blender.",
            "Season with salt and the juice of the lemon. Add more tahini if needed.",
        ),
        step_ingredients=(("chickpeas", "tahini"), ("garlic", "water"), (), ("salt", "lemon", "tahini")),
    )


@pytest.fixture
def pancakes() -> Recipe:
    return Recipe(
        id="test:pancakes",
        title="Pancakes",
        ingredients=("200 g flour", "2 eggs", "300 ml milk", "1 tbsp butter, melted"),
        steps=("Whisk flour, eggs and milk.", "Fry in butter."),
        step_ingredients=(("flour", "eggs", "milk"), ("butter",)),
    )


@pytest.fixture
def salad_state() -> IfState:
    return IfState(
        instruction="Dress the salad with olive oil and vinegar, but do not add salt.",
        available=(
            "Put olive oil on table",
            "Put vinegar on table",
            "Put salt on table",
            "Put sugar on table",
            "Put flour on table",
        ),
        relevant=frozenset({"Put olive oil on table", "Put vinegar on table"}),
        recipe_id="test:salad",
        step=0,
        locations={
            "Put olive oil on table": (0, 0),
            "Put vinegar on table": (2, 1),
            "Put salt on table": (1, 2),
            "Put sugar on table": (0, 3),
            "Put flour on table": (1, 4),
        },
    )
