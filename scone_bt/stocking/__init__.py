"""Stocking the kitchen, in one place: which products a recipe needs, which stand on the shelf, and where.

- `needs`: a recipe's ingredient lines → catalogue products, each assigned to the first step that uses it
  (`stock_recipe`).
- `shelf`: the recipe's products and the distractors that stand beside them (`stock_shelf`, `max_distractors`).
- `place`: where each product stands, heaviest lowest, facing the robot (`plan_stocking`).
- `validate`: a scenario's names (products, slots, cameras, pinned products) against the stocked kitchen
  (`kitchen_names`, `KitchenNames`).
- `lanes`, `pack`: the geometry both answer with: the lane a product takes along a tier, and whether a set fits
  side by side.
"""

from scone_bt.stocking.lanes import FINGER_ROOM_M, LANE_MIN_M, fits_shelf, lane_width
from scone_bt.stocking.needs import StockedRecipe, StockedStep, match_catalogue, stock_recipe
from scone_bt.stocking.pack import fits_side_by_side, pack_side_by_side, wider_than_every_tier
from scone_bt.stocking.place import Placement, plan_stocking
from scone_bt.stocking.shelf import ShelfStock, max_distractors, stock_shelf
from scone_bt.stocking.validate import (
    SLOT_PATTERN,
    KitchenNames,
    kitchen_names,
    parse_slot,
    slots_beside,
    stocked_names,
)

__all__ = [
    "FINGER_ROOM_M",
    "KitchenNames",
    "LANE_MIN_M",
    "SLOT_PATTERN",
    "Placement",
    "ShelfStock",
    "StockedRecipe",
    "StockedStep",
    "fits_shelf",
    "fits_side_by_side",
    "kitchen_names",
    "lane_width",
    "match_catalogue",
    "max_distractors",
    "pack_side_by_side",
    "parse_slot",
    "plan_stocking",
    "slots_beside",
    "stock_recipe",
    "stock_shelf",
    "stocked_names",
    "wider_than_every_tier",
]
