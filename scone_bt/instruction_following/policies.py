"""Embedding-similarity policies: rank the remaining actions by cosine similarity to the instruction.

Three stopping rules: never (pick everything, the base rate), a learnt threshold ρ on the similarity (stop
when the best remaining action scores below it), and an oracle that stops after as many picks as there are
relevant actions (it reads the labels, so it only measures ranking quality).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Literal, overload

import numpy as np

from scone_bt.embedding.base import Embedder
from scone_bt.instruction_following.states import IfState

__all__ = [
    "SimilarityPolicy",
    "Objective",
    "state_scores",
    "fit_threshold",
    "threshold_picks_score",
    "relative_scores",
]

Objective = Literal["accuracy", "f1"]


def state_scores(embedder: Embedder, states: Sequence[IfState]) -> list[np.ndarray]:
    """Cosine similarity of each state's available actions to its instruction (one array per state)."""
    texts = sorted({s.instruction for s in states} | {a for s in states for a in s.available})
    vecs = embedder.embed(texts)
    index = {t: i for i, t in enumerate(texts)}
    out = []
    for s in states:
        inst = vecs[index[s.instruction]]
        acts = vecs[[index[a] for a in s.available]]
        out.append(acts @ inst)
    return out


def relative_scores(scores: Sequence[np.ndarray]) -> list[np.ndarray]:
    """Each state's similarities minus its best one (≤ 0), for a threshold relative to the top action."""
    return [
        np.asarray(s, dtype=float) - float(np.max(s)) if len(s) else np.asarray(s, dtype=float)
        for s in scores
    ]


@overload
def threshold_picks_score(
    scores: Sequence[np.ndarray], states: Sequence[IfState], threshold: float
) -> tuple[float, float]: ...


@overload
def threshold_picks_score(
    scores: Sequence[np.ndarray], states: Sequence[IfState], threshold: np.ndarray
) -> tuple[np.ndarray, np.ndarray]: ...


def threshold_picks_score(
    scores: Sequence[np.ndarray], states: Sequence[IfState], threshold: float | np.ndarray
) -> tuple[float, float] | tuple[np.ndarray, np.ndarray]:
    """Mean IF accuracy and recall of "pick while the best remaining scores ≥ threshold"; with an array of
    thresholds, arrays of both (one entry per threshold)."""
    flat = np.concatenate([np.asarray(sc, dtype=float) for sc in scores])
    owner = np.repeat(np.arange(len(states)), [len(sc) for sc in scores])
    rel = np.concatenate([[a in s.relevant for a in s.available] for s in states]).astype(bool)
    n_rel = np.bincount(owner, weights=rel, minlength=len(states))
    thresholds = np.atleast_1d(np.asarray(threshold, dtype=float))
    accs, recs = [], []
    for t in thresholds:
        chosen = flat >= t
        n = np.bincount(owner, weights=chosen, minlength=len(states))
        hits = np.bincount(owner, weights=chosen & rel, minlength=len(states))
        acc = np.where(n > 0, hits / np.maximum(n, 1), (n_rel == 0).astype(float))
        rec = np.where(n_rel > 0, hits / np.maximum(n_rel, 1), 1.0)
        accs.append(acc.mean())
        recs.append(rec.mean())
    if np.ndim(threshold) == 0:
        return float(accs[0]), float(recs[0])
    return np.array(accs), np.array(recs)


def fit_threshold(
    scores: Sequence[np.ndarray], states: Sequence[IfState], objective: Objective = "accuracy"
) -> float:
    """The stopping threshold ρ that maximises the IF objective on labelled (training) states.

    Args:
        scores: ``state_scores`` of the states.
        states: Labelled states (the train split).
        objective: "accuracy" (the paper's metric) or "f1" (harmonic mean of accuracy and recall).

    Returns:
        ρ, a cosine similarity; ties go to the lower threshold (more recall).
    """
    if objective not in ("accuracy", "f1"):
        raise ValueError(f"unknown objective {objective!r}; valid: accuracy, f1")
    pooled = np.concatenate([np.asarray(s, dtype=float) for s in scores])
    candidates = np.unique(np.quantile(pooled, np.linspace(0.0, 1.0, 201)))
    acc, rec = threshold_picks_score(scores, states, candidates)
    value = (
        acc
        if objective == "accuracy"
        else np.where(acc + rec > 0, 2 * acc * rec / np.maximum(acc + rec, 1e-12), 0.0)
    )
    # argmax takes the first (lowest) of equally good thresholds.
    return float(candidates[int(np.argmax(np.round(value, 12)))])


@dataclass
class SimilarityPolicy:
    """Greedy by cosine similarity, with an optional stopping rule.

    Attributes:
        embedder: The joint embedder ζ.
        name: Row label in the results table.
        threshold: ρ; stop when the best remaining action's similarity is below it (None: never).
        relative: Compare ρ with the similarity minus the state's best similarity, so the first pick is free.
        oracle_count: Stop after len(relevant) picks (reads the labels: an analysis upper bound on stopping).
        score_fn: Replaces the cosine similarity (used by tests and by calibrated variants).
    """

    embedder: Embedder | None
    name: str
    threshold: float | None = None
    relative: bool = False
    oracle_count: bool = False
    score_fn: Callable[[IfState], dict[str, float]] | None = None
    _cache: dict[tuple[str, tuple[str, ...]], dict[str, float]] = field(default_factory=dict, repr=False)

    def scores(self, state: IfState) -> dict[str, float]:
        """Action text → similarity to the instruction (cached per state)."""
        key = (state.instruction, state.available)
        if key not in self._cache:
            if self.score_fn is not None:
                self._cache[key] = self.score_fn(state)
            else:
                assert self.embedder is not None
                (sc,) = state_scores(self.embedder, [state])
                self._cache[key] = dict(zip(state.available, map(float, sc), strict=True))
        return self._cache[key]

    def choose(self, state: IfState, remaining: Sequence[str], picked: Sequence[str]) -> str | None:
        """The most similar remaining action, unless the stopping rule says stop."""
        if self.oracle_count and len(picked) >= len(state.relevant):
            return None
        scores = self.scores(state)
        best = max(remaining, key=lambda a: scores[a])
        offset = max(scores.values()) if self.relative else 0.0
        if self.threshold is not None and scores[best] - offset < self.threshold:
            return None
        return best
