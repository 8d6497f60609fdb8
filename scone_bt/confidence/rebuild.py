"""Rebuilding κ̂ from the experience store at start-up (stored action texts re-embedded with today's embedder).

A grounded κ̂ (is_grounded) gets each stored outcome's execution context after its embedding; outcomes stored
without one (before contexts were recorded, or by a robot that did not perceive them) give NaN context values,
which the grounded estimator imputes from the others and flags.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from scone_bt.confidence.base import ConfidenceEstimator
from scone_bt.confidence.grounded import grounded_features, is_grounded
from scone_bt.embedding.base import Embedder
from scone_bt.experience.base import OutcomeStore
from scone_bt.experience.types import Outcome

__all__ = ["fit_on_outcomes", "rebuild_estimator", "training_data"]


def training_data(
    outcomes: list[Outcome], embedder: Embedder, grounded: bool = False
) -> tuple[np.ndarray, np.ndarray]:
    """(X, y) for an estimator: the outcomes' action embeddings and success flags, in stored order.

    Args:
        outcomes: Stored outcomes.
        embedder: ζ that re-embeds their action texts.
        grounded: Append each outcome's execution context (grounded_features; NaN where none was stored).
    """
    if not outcomes:
        X = np.zeros((0, embedder.dim), dtype=np.float32)
        return (grounded_features(X, []) if grounded else X), np.zeros(0, dtype=bool)
    X = embedder.embed([o.action for o in outcomes])
    if grounded:
        X = grounded_features(X, [o.execution for o in outcomes])
    return X, np.array([o.success for o in outcomes], dtype=bool)


def rebuild_estimator(
    estimator: ConfidenceEstimator,
    store: OutcomeStore,
    embedder: Embedder,
    *,
    only_embedder: str | None = None,
    where: Callable[[Outcome], bool] | None = None,
    robot_id: str | None = None,
    arm: str | None = None,
    profile: str | None = None,
) -> int:
    """Fit `estimator` on the stored outcomes (all, or those of one embedder / robot / arm / profile / predicate).

    The robot, arm and profile filters are what `LearnFrom.filters` returns (--learn-from self|same-model|fleet).

    An outcome does not depend on the embedder that was active when it was observed, so by default every stored
    outcome is used and re-embedded with `embedder`; pass `only_embedder` for experiments that must not mix.

    Returns:
        The number of outcomes learnt from.
    """
    outcomes = store.outcomes(only_embedder, where, robot_id=robot_id, arm=arm, profile=profile)
    return fit_on_outcomes(estimator, outcomes, embedder)


def fit_on_outcomes(estimator: ConfidenceEstimator, outcomes: list[Outcome], embedder: Embedder) -> int:
    """Fit `estimator` on outcomes already read from a store (re-embedded with `embedder`); how many."""
    X, y = training_data(outcomes, embedder, grounded=is_grounded(estimator))
    if len(y) or estimator.n_observations:
        estimator.fit(X, y)
    return len(y)
