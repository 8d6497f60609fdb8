"""Recipe-aware selection: never-used items, finished steps, ambiguity, negation, and items needed later."""

from __future__ import annotations

import pytest

from scone_bt.errors import SconeError
from scone_bt.relevance.mentions import ambiguous_heads, mentioned_items, negated_items
from scone_bt.relevance.recipe_aware import (
    Need,
    RecipeContext,
    SelectionOptions,
    select_for_step,
)

PASTA = RecipeContext(
    items=("salt", "pasta", "olive oil", "garlic", "canned tomatoes", "cheese"),
    wordings={"pasta": ("spaghetti",), "canned tomatoes": ("crushed tomatoes",)},
    steps_ahead=("Warm the olive oil in a pan and fry the garlic.", "Serve topped with the cheese."),
)
SHELF = ("salt", "pasta", "olive oil", "garlic", "canned tomatoes", "cheese", "honey", "vinegar")


def _sim(**values: float) -> dict[str, float]:
    return {item: values.get(item.replace(" ", "_"), 0.1) for item in SHELF}


def test_named_items_are_needed_now_and_distractors_never() -> None:
    # honey is the most similar action but the recipe never uses it
    sel = select_for_step("Cook the spaghetti until al dente.", SHELF, PASTA, _sim(honey=0.9, pasta=0.4))
    assert sel.now == ("pasta",)
    assert "honey" not in sel.now + sel.later + sel.ambiguous
    assert sel.need("pasta") is Need.NOW
    assert sel.need("honey") is None


def test_items_of_later_steps_come_in_recipe_order() -> None:
    sel = select_for_step("Cook the spaghetti until al dente.", SHELF, PASTA, _sim())
    assert sel.later == ("olive oil", "garlic", "cheese", "salt", "canned tomatoes")
    assert sel.need("garlic") is Need.LATER


def test_unnamed_step_uses_the_similarity_fallback_or_nothing() -> None:
    ctx = RecipeContext(items=PASTA.items)
    opts = SelectionOptions(rho=0.4, margin=0.05)
    sel = select_for_step("Season the water generously.", SHELF, ctx, _sim(salt=0.6, garlic=0.3), opts)
    assert sel.now == ("salt",)
    none = select_for_step("Preheat the oven.", SHELF, ctx, _sim(salt=0.2), opts)
    assert none.now == () and none.ambiguous == ()


def test_two_equally_similar_candidates_are_ambiguous() -> None:
    ctx = RecipeContext(items=PASTA.items)
    opts = SelectionOptions(rho=0.4, margin=0.05)
    sel = select_for_step("Add the seasoning.", SHELF, ctx, _sim(salt=0.61, garlic=0.59), opts)
    assert sel.now == ()
    assert set(sel.ambiguous) == {"salt", "garlic"}


def test_a_shared_head_noun_alone_is_ambiguous() -> None:
    ctx = RecipeContext(items=("canola oil", "sesame oil", "ginger"))
    sel = select_for_step("Heat the oil in a wok.", ("canola oil", "sesame oil", "ginger"), ctx, {})
    assert sel.now == ()
    assert set(sel.ambiguous) == {"canola oil", "sesame oil"}
    assert "oil" in sel.reason


def test_negated_items_are_not_fetched() -> None:
    sel = select_for_step("Toss the spaghetti, without the cheese.", SHELF, PASTA, _sim())
    assert sel.now == ("pasta",)
    assert "cheese" not in sel.named


def test_step_is_done_when_what_it_names_is_on_the_table() -> None:
    on_table = RecipeContext(items=PASTA.items, wordings=PASTA.wordings, on_table=frozenset({"pasta"}))
    shelf = tuple(i for i in SHELF if i != "pasta")
    sel = select_for_step("Cook the spaghetti until al dente.", shelf, on_table, _sim())
    assert sel.done and sel.now == ()
    not_yet = select_for_step("Cook the spaghetti until al dente.", SHELF, PASTA, _sim())
    assert not not_yet.done


def test_mentions_fold_plurals_accents_and_heads() -> None:
    assert mentioned_items("Add two jalapeños and the berries", ["jalapeno", "berry"]) == [
        "jalapeno",
        "berry",
    ]
    assert mentioned_items("Add the liver", ["beef liver", "salt"]) == ["beef liver"]
    assert ambiguous_heads("add the oil", ["olive oil", "sesame oil"]) == [("olive oil", "sesame oil")]
    assert negated_items("serve without cheese but with salt", ["cheese", "salt"]) == {"cheese"}


@pytest.mark.parametrize("kw", [{"rho": 1.5}, {"margin": -0.1}])
def test_options_are_validated(kw) -> None:
    with pytest.raises(SconeError):
        SelectionOptions(**kw)


def test_a_step_whose_named_items_are_off_the_shelf_gets_no_similarity_fallback() -> None:
    # the step names spaghetti, which is not on the shelf: garlic (the most similar item) is for later, not now
    shelf = tuple(i for i in SHELF if i != "pasta")
    opts = SelectionOptions(rho=0.3, margin=0.05)
    sel = select_for_step("Cook the spaghetti until al dente.", shelf, PASTA, _sim(garlic=0.39), opts)
    assert sel.named == ("pasta",)
    assert sel.now == () and sel.ambiguous == ()
    assert sel.need("garlic") is Need.LATER
    assert not sel.done


def test_items_a_step_ahead_means_by_a_shared_head_noun_wait_for_that_step() -> None:
    items = ("ciabatta", "cheddar cheese", "swiss cheese")
    ctx = RecipeContext(items=items, steps_ahead=("Top the toast with the cheese.",))
    sel = select_for_step("Toast the ciabatta.", items, ctx, {})
    assert sel.now == ("ciabatta",) and sel.later == ()  # neither cheese is fetched ahead: it is asked there
    plain = RecipeContext(items=items, steps_ahead=("Top the toast with the cheddar cheese.",))
    assert select_for_step("Toast the ciabatta.", items, plain, {}).later == (
        "cheddar cheese",
        "swiss cheese",
    )
