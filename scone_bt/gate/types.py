"""The gate's decision."""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum

__all__ = ["DecisionKind", "Decision"]


class DecisionKind(StrEnum):
    ACT = "act"  # confident enough: attempt the action
    ASK = "ask"  # not confident: ask the human for help with this action
    IDLE = "idle"  # no relevant action for the current instruction


@dataclass(frozen=True)
class Decision:
    """What the robot will do this cycle.

    Attributes:
        kind: act, ask or idle.
        action: The chosen action text (None when idle).
        relevance: Its cosine similarity to the instruction.
        confidence: κ̂'s success probability for it, in [0, 1].
        reason: One short sentence a user can read in the log.
    """

    kind: DecisionKind
    action: str | None
    relevance: float
    confidence: float
    reason: str
