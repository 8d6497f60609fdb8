"""Data that leaves the relevance stage (ρ)."""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["RankedAction"]


@dataclass(frozen=True)
class RankedAction:
    """An action text with its cosine similarity to the current instruction, in [-1, 1].

    ``need`` is set by recipe-aware ranking: "now" (the step needs it) or "later" (a step ahead does); "" when
    the ranking knew only the step's text (the paper's setting, where the gate's ρ decides relevance).
    """

    text: str
    relevance: float
    need: str = ""
