"""Affordances: actions the robot could take now."""

from __future__ import annotations

import re
from dataclasses import dataclass

from scone_bt.perception.types import Detection

__all__ = ["Affordance", "action_text", "object_of_action"]

_ACTION = re.compile(r"^Put (.+) on table$")


def action_text(object_name: str) -> str:
    """The paper's action template."""
    return f"Put {object_name} on table"


def object_of_action(action: str) -> str:
    """The inverse of `action_text` ("Put salt on table" → "salt"); any other text is returned as it is."""
    m = _ACTION.match(action)
    return m.group(1) if m else action


@dataclass(frozen=True)
class Affordance:
    """An action the robot can attempt: its text and the detection it acts on."""

    object_name: str
    text: str
    detection: Detection
