"""Affordance generation: each object detected on the shelf yields "Put X on table"."""

from scone_bt.affordances.generate import generate_affordances
from scone_bt.affordances.types import Affordance, action_text, object_of_action

__all__ = ["Affordance", "action_text", "generate_affordances", "object_of_action"]
