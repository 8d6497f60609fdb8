"""Affordances: actions the robot could take now."""

from __future__ import annotations

from dataclasses import dataclass

from scone_bt.perception.types import Detection

__all__ = ["Affordance", "action_text"]


def action_text(object_name: str) -> str:
    """The paper's action template."""
    return f"Put {object_name} on table"


@dataclass(frozen=True)
class Affordance:
    """An action the robot can attempt: its text and the detection it acts on."""

    object_name: str
    text: str
    detection: Detection
