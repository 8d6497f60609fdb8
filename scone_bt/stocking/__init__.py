"""Stocking the kitchen, in one place: which products a recipe needs, which stand on the shelf, and where.

- `needs`: a recipe's ingredient lines → catalogue products, each assigned to the first step that uses it
  (`stock_recipe`).
- `shelf`: the recipe's products and the distractors that stand beside them (`stock_shelf`, `max_distractors`).
- `place`: where each product stands, heaviest lowest, facing the robot (`plan_stocking`).
- `lanes`, `pack`: the geometry both answer with: the lane a product takes along a tier, and whether a set fits
  side by side.
"""

from scone_bt.stocking.lanes import FINGER_ROOM_M, LANE_MIN_M, fits_shelf, lane_width
from scone_bt.stocking.needs import StockedRecipe, StockedStep, match_catalogue, stock_recipe
from scone_bt.stocking.pack import fits_side_by_side, pack_side_by_side, wider_than_every_tier
from scone_bt.stocking.place import Placement, plan_stocking
from scone_bt.stocking.shelf import ShelfStock, max_distractors, stock_shelf

__all__ = [
    "FINGER_ROOM_M",
    "LANE_MIN_M",
    "Placement",
    "ShelfStock",
    "StockedRecipe",
    "StockedStep",
    "fits_shelf",
    "fits_side_by_side",
    "lane_width",
    "match_catalogue",
    "max_distractors",
    "pack_side_by_side",
    "plan_stocking",
    "stock_recipe",
    "stock_shelf",
    "wider_than_every_tier",
]
