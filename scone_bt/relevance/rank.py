"""ρ, ranking: available actions ordered by cosine similarity to an instruction in the joint embedding space."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from scone_bt.embedding.base import Embedder
from scone_bt.relevance.types import RankedAction

__all__ = ["rank_actions", "relevance_matrix"]


def relevance_matrix(instructions: Sequence[str], actions: Sequence[str], embedder: Embedder) -> np.ndarray:
    """Cosine similarities (n_instructions, n_actions), float32 in [-1, 1]."""
    if not instructions or not actions:
        return np.zeros((len(instructions), len(actions)), dtype=np.float32)
    return np.clip(embedder.embed(instructions) @ embedder.embed(actions).T, -1.0, 1.0)


def rank_actions(instruction: str, actions: Sequence[str], embedder: Embedder) -> list[RankedAction]:
    """Actions with their similarity to `instruction`, best first; equal scores keep the input order."""
    scores = relevance_matrix([instruction], actions, embedder)[0]
    order = np.argsort(-scores, kind="stable")
    return [RankedAction(actions[i], float(scores[i])) for i in order]
