"""Data that leaves the relevance stage (ρ)."""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["RankedAction"]


@dataclass(frozen=True)
class RankedAction:
    """An action text with its cosine similarity to the current instruction, in [-1, 1]."""

    text: str
    relevance: float
