"""Affordance generation: each object detected on the shelf yields "Put X on table"."""

from scone_bt.affordances.generate import generate_affordances, on_shelf
from scone_bt.affordances.types import Affordance, action_text

__all__ = ["Affordance", "action_text", "generate_affordances", "on_shelf"]
