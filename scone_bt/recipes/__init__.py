"""Recipes: loading them, and deciding which catalogue objects each step needs."""

from scone_bt.recipes.recipe import Recipe, load_recipe, recipe_corpus_path
from scone_bt.recipes.stocking import StockedRecipe, StockedStep, match_catalogue, stock_recipe

__all__ = [
    "Recipe",
    "StockedRecipe",
    "StockedStep",
    "load_recipe",
    "match_catalogue",
    "recipe_corpus_path",
    "stock_recipe",
]
