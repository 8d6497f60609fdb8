"""Ingredient lines → catalogue products, and products → the steps that need them."""

from __future__ import annotations

import pytest

from scone_bt.recipes.normalise import normalise_ingredient
from scone_bt.recipes.recipe import recipe_from_record
from scone_bt.stocking import stock_recipe
from scone_bt.stocking.needs import MatchRule, ProductIndex


@pytest.fixture(scope="module")
def index(kitchen_cfg):
    return ProductIndex(kitchen_cfg.catalogue)


@pytest.mark.parametrize(
    ("line", "product", "rule"),
    [
        ("2 large eggs", "eggs", MatchRule.EXACT),
        ("1 15-oz can garbanzo beans", "chickpeas", MatchRule.EXACT),
        ("1 tsp cumin", "cumin", MatchRule.EXACT),
        ("1 tsp paprika", "paprika", MatchRule.EXACT),
        ("1 tsp ground cinnamon", "cinnamon", MatchRule.EXACT),
        ("juice of 1 lime", "lime", MatchRule.PART),
        ("2 tbsp maple syrup", "maple syrup", MatchRule.EXACT),
        ("1 15-oz can diced tomatoes", "diced tomatoes", MatchRule.IN_LINE),
        ("1 cup milk or almond milk", "milk", MatchRule.EXACT),
        ("1 cup extra sharp cheddar", "cheddar cheese", MatchRule.IN_LINE),
        ("1 cup mild cheddar", "cheddar cheese", MatchRule.GRADE),
        ("3 egg yolks", "eggs", MatchRule.PART),
        ("zest of lemon", "lemon", MatchRule.PART),
        ("2 cups broccli florets", "broccoli", MatchRule.SPELLING),
        # Grades, parts and kinds the catalogue's growth asked for.
        ("Juice from 1 lime", "lime", MatchRule.PART),
        ("400g pork meat", "pork", MatchRule.PART),
        ("1 cup ham pieces", "ham", MatchRule.PART),
        ("1 vanilla bean pod", "vanilla bean", MatchRule.PART),
        ("250g fat free yoghurt", "yogurt", MatchRule.GRADE),
        ("250 g chilled unsalted Normandy butter", "unsalted butter", MatchRule.GRADE),
        ("1 Italian eggplant", "eggplant", MatchRule.GRADE),
        ("1/2 tsp red-pepper flakes.", "red pepper flakes", MatchRule.EXACT),
        ("2 33cl bottles of brown beer", "beer", MatchRule.KIND),
        ("1/3 cup Chiave d'Oro Cheese", "cheese", MatchRule.KIND),
        ("10 raw, unsalted almonds", "almonds", MatchRule.GRADE),
    ],
)
def test_lookup_rules(index, line, product, rule):
    match = index.lookup(normalise_ingredient(line), line)
    assert match is not None and (match.product, match.rule) == (product, rule)


@pytest.mark.parametrize(
    "line", ["1 tbsp grapeseed oil", "1 cup rye flour", "2 tomatillos", "1 tsp lemon extract"]
)
def test_unlike_products_are_not_spelling_matches(index, line):
    match = index.lookup(normalise_ingredient(line), line)
    assert match is None or match.rule is not MatchRule.SPELLING, match


@pytest.mark.parametrize("line", ["1 cup ginger beer", "2 cups root beer", "1 prickly pear"])
def test_names_ending_in_a_kind_head_are_not_that_kind(index, line):
    assert index.lookup(normalise_ingredient(line), line) is None


def _recipe(ingredients, steps):
    return recipe_from_record({"id": "test", "ingredients": ingredients, "steps": steps}, "test")


def test_water_and_tools_are_not_fetchable_not_unstocked(kitchen_cfg):
    recipe = _recipe(
        ["2 cups flour", "1 cup warm water", "candy thermometer", "1 tsp unobtainium"],
        ["Mix the flour with the water.", "Check the temperature."],
    )
    stocked = stock_recipe(recipe, kitchen_cfg.catalogue)
    assert stocked.needed == ("flour",)
    assert stocked.not_fetchable == ("1 cup warm water", "candy thermometer")
    assert stocked.unstocked == ("1 tsp unobtainium",)


def test_steps_name_products_by_the_recipes_own_words(kitchen_cfg):
    recipe = _recipe(
        ["1 cup sharp cheddar cheese", "2 tbsp extra virgin olive oil", "1 tsp vanilla"],
        ["Warm the oil.", "Melt the cheese into it.", "Serve."],
    )
    stocked = stock_recipe(recipe, kitchen_cfg.catalogue)
    # "vanilla" is named by no step: it is gathered before the first step's products.
    assert [s.objects for s in stocked.steps] == [
        ("vanilla extract", "extra virgin olive oil"),
        ("cheddar cheese",),
        (),
    ]


def test_capacity_leaves_the_last_products_off_the_shelf(kitchen_cfg):
    recipe = _recipe(["salt", "sugar", "flour", "milk"], ["Add salt and sugar.", "Add flour.", "Add milk."])
    stocked = stock_recipe(recipe, kitchen_cfg.catalogue, capacity=2)
    assert stocked.needed == ("salt", "sugar") and stocked.off_shelf == ("flour", "milk")
    assert [s.objects for s in stocked.steps] == [("salt", "sugar"), (), ()]


def test_every_corpus_recipe_stocks_within_the_shelf(kitchen_cfg):
    """What scone-run does before the robot acts, for all 1,227 recipes: no recipe is refused."""
    from scone_bt.recipes.recipe import read_corpus, recipe_corpus_path

    if recipe_corpus_path() is None:
        pytest.skip("../shared recipe corpus not present")
    index = ProductIndex(kitchen_cfg.catalogue)
    capacity = len(kitchen_cfg.scene.shelf_slots()) - 6  # scone-run's default distractors
    for recipe in read_corpus():
        stocked = stock_recipe(recipe, kitchen_cfg.catalogue, capacity=capacity, index=index)
        assert len(stocked.needed) <= capacity
        assert sorted(n for s in stocked.steps for n in s.objects) == sorted(stocked.needed)
        assert len(stocked.unstocked) + len(stocked.not_fetchable) <= len(recipe.ingredients)
