"""Grounded κ̂: the action's embedding plus the context the robot acts in (where the object stands, what it saw).

The seed defines proficiency as an expectation over contexts, but the robot acts in one context: a bottle it
usually grasps fails between two jars, and a product whose marker it saw only partly fails more often. A grounded
estimator sees, next to ζ(action), six numbers of the execution's context (ExecutionContext): the shelf tier, the
clearance to the nearest neighbour, the number of neighbours, whether the target was detected, and its detected
width and height.

Features are prepared inside the estimator, from its own training rows only (nothing of a test row leaks): each
context value is standardised by the training mean and std; a missing value (NaN, e.g. no detected size when the
target was not detected) is imputed with the training mean (0 after standardising) and flagged in an indicator
column. The context block is scaled by `context_weight` / √6 so that it weighs about as much as a unit-norm
embedding in distance-based estimators (KNN, SVM, GP); trees are indifferent to the scale.

In the episode (docs/grounded.md): the gate builds an `ExecutionContext` for each candidate from that tick's
perception (scone_bt.perception.context), predicts with `grounded_features(embeddings, contexts)` when κ̂
`is_grounded`, and the outcome stage stores the attempt's context (Outcome.execution) and updates with
`grounded_features(embedding[None], [context])[0]`. The inner estimator is any registry estimator
("grounded-knn", "grounded-lgbm", "grounded-gp", ...).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence

import numpy as np

from scone_bt.confidence.base import ConfidenceEstimator
from scone_bt.errors import SconeError

# ExecutionContext is defined beside Outcome (the store persists it); re-exported here, where κ̂ reads it.
from scone_bt.experience.types import CONTEXT_FIELDS, FELT_FIELDS, ExecutionContext

__all__ = [
    "CONTEXT_FIELDS",
    "ExecutionContext",
    "GroundedEstimator",
    "grounded_features",
    "is_grounded",
    "kappa_rows",
]


def is_grounded(estimator: object) -> bool:
    """True for an estimator that reads [embedding | context] rows (GroundedEstimator, or a fake that says so)."""
    return bool(getattr(estimator, "grounded", False))


def grounded_features(embeddings: np.ndarray, contexts: Sequence[ExecutionContext | None]) -> np.ndarray:
    """(n, dim + len(CONTEXT_FIELDS)) rows for a grounded estimator: each embedding followed by its context vector
    (None: all NaN)."""
    E = np.atleast_2d(np.asarray(embeddings, dtype=np.float64))
    if len(contexts) != len(E):
        raise SconeError(f"{len(E)} embeddings but {len(contexts)} contexts")
    unknown = ExecutionContext()
    C = (
        np.stack([(unknown if c is None else c).vector() for c in contexts])
        if contexts
        else np.zeros((0, len(CONTEXT_FIELDS)))
    )
    return np.hstack([E, C])


def kappa_rows(
    estimator: object, embeddings: np.ndarray, contexts: Sequence[ExecutionContext | None]
) -> np.ndarray:
    """The rows ``estimator`` reads: (n, dim) ``embeddings`` as given, each followed by its context when κ̂ is
    grounded (`grounded_features`). The one place the gate, the judge after a probe and κ̂'s update build them."""
    return grounded_features(embeddings, contexts) if is_grounded(estimator) else embeddings


class GroundedEstimator(ConfidenceEstimator):
    """Wraps an estimator over [embedding | context]; the last `n_context` input columns are the context.

    With the full context (``n_context`` = len(CONTEXT_FIELDS)) it reads the perceived columns only: what a
    heft test felt (FELT_FIELDS) is read by the ``physical`` κ̂, which knows its scale (confidence.physical).

    Args:
        base: The estimator that learns from the prepared features (it also owns the cold start).
        n_context: Context columns at the end of every input row.
        context_weight: Norm budget of the standardised context block relative to a unit embedding.
    """

    handles_one_class = True  # the base handles its own cold start
    grounded = True  # callers pass grounded_features rows (see is_grounded)

    def __init__(
        self, base: ConfidenceEstimator, n_context: int = len(CONTEXT_FIELDS), context_weight: float = 1.0
    ) -> None:
        if n_context < 1:
            raise SconeError(f"n_context must be at least 1, got {n_context}")
        super().__init__(f"grounded-{base.name}", base.seed, base.prior)
        self.base = base
        self.n_context = n_context
        self.context_weight = context_weight
        self._read = (
            np.array([i for i, f in enumerate(CONTEXT_FIELDS) if f not in FELT_FIELDS])
            if n_context == len(CONTEXT_FIELDS)
            else np.arange(n_context)
        )
        self._mean = np.zeros(len(self._read))
        self._std = np.ones(len(self._read))

    def _split(self, X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        if X.shape[1] <= self.n_context:
            raise SconeError(
                f"{self.name}: rows need an embedding plus {self.n_context} context values, got {X.shape[1]} "
                "columns (build them with grounded_features)"
            )
        return X[:, : -self.n_context], X[:, -self.n_context :][:, self._read].astype(np.float64)

    def transform(self, X: np.ndarray) -> np.ndarray:
        """Prepared features: embedding, standardised and imputed context, missing-value indicators."""
        emb, ctx = self._split(np.atleast_2d(X))
        missing = np.isnan(ctx)
        z = np.where(missing, 0.0, (ctx - self._mean) / self._std)
        scale = self.context_weight / math.sqrt(len(self._read))
        return np.hstack([emb, scale * z, scale * missing]).astype(np.float32)

    def _fit_model(self, X: np.ndarray, y: np.ndarray) -> None:
        n = len(self._read)
        _, ctx = self._split(X) if len(X) else (None, np.zeros((0, n)))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # an all-NaN column: imputed with 0 below
            mean = np.nanmean(ctx, axis=0) if len(ctx) else np.zeros(n)
            std = np.nanstd(ctx, axis=0) if len(ctx) else np.ones(n)
        self._mean = np.where(np.isfinite(mean), mean, 0.0)
        self._std = np.where(np.isfinite(std) & (std > 1e-9), std, 1.0)
        if len(X):
            self.base.fit(self.transform(X), y)
        else:
            self.base.fit(np.zeros((0, 1), dtype=np.float32), y)

    def share_hyperparameters(self, fitted: ConfidenceEstimator) -> None:
        inner = getattr(fitted, "base", None)
        if inner is not None:
            self.base.share_hyperparameters(inner)

    def _predict_model(self, X: np.ndarray) -> np.ndarray:
        return self.base.predict(self.transform(X))

    def _predict_uncached(self, X: np.ndarray) -> np.ndarray:
        if self._n == 0:
            return np.full(len(X), self.prior)
        return self._predict_model(X)
