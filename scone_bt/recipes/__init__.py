"""Recipes: loading them (which catalogue products each step needs is `scone_bt.stocking.needs`)."""

from scone_bt.recipes.recipe import Recipe, load_recipe, recipe_corpus_path

__all__ = ["Recipe", "load_recipe", "recipe_corpus_path"]
