"""Our calibrated κ̂ (beyond the paper): KNN nonconformity with full conformal prediction.

For an action embedding x, the estimator computes the conformal p-value of the hypothesis "this action would
fail", p_fail(x), and reports confidence = 1 − p_fail(x). Conformal validity (outcomes exchangeable) gives:

    P(p_fail(x) ≤ α and the action fails) ≤ α

so a gate that acts only when confidence ≥ 1 − α (GateOptions(target_error_rate=α)) walks into an unannounced
failure on at most a fraction α of its decisions; every other would-fail action is turned into "ask for help".

Nonconformity of (x, y) is the classic KNN ratio: mean cosine distance to the k nearest past outcomes with label
y over the mean distance to the k nearest with the other label (2.0, the largest cosine distance, when that class
is empty). p-values are exact full conformal: every past outcome's score is recomputed with (x, fail) added.

Cold start: with n outcomes the smallest p-value is 1/(n+1), so no action can be certified at level α before
n ≥ 1/α − 1 outcomes (with no outcomes confidence is 0). Pair it with ε-greedy ("eps-conformal") or ask-first
data collection; this is the honest price of a stated error rate.
"""

from __future__ import annotations

import numpy as np

from scone_bt.confidence.base import ConfidenceEstimator

__all__ = ["ConformalKNNEstimator"]

_D_MAX = 2.0  # cosine distance between opposite unit vectors
_EPS = 1e-9


def _unit(X: np.ndarray) -> np.ndarray:
    norms = np.linalg.norm(X, axis=1, keepdims=True)
    return X / np.where(norms > 0, norms, 1.0)


def _mean_k(sorted_d: np.ndarray, k: int) -> np.ndarray:
    """Mean of the k smallest finite distances along the last axis (sorted ascending, inf-padded)."""
    head = sorted_d[..., :k]
    finite = np.isfinite(head)
    count = finite.sum(axis=-1)
    total = np.where(finite, head, 0.0).sum(axis=-1)
    return np.where(count > 0, total / np.maximum(count, 1), _D_MAX)


class ConformalKNNEstimator(ConfidenceEstimator):
    """Full conformal KNN; `predict` returns 1 − p-value of failure (see module docstring).

    Args:
        name: Registry name.
        seed: Unused (the method is deterministic); kept for a uniform constructor.
        k: Neighbours in the nonconformity score.
    """

    handles_one_class = True

    def __init__(self, name: str = "conformal", seed: int = 0, k: int = 3, prior: float = 0.0) -> None:
        super().__init__(name, seed, prior)
        self.k = k
        self._U = np.zeros((0, 0))
        self._labels = np.zeros(0, dtype=bool)
        self._same = np.zeros((0, k))
        self._other = np.zeros((0, k))

    def _fit_model(self, X: np.ndarray, y: np.ndarray) -> None:
        self._U = _unit(X.astype(np.float64))
        self._labels = y.copy()
        n, k = len(y), self.k
        if n == 0:
            return
        dist = np.clip(1.0 - self._U @ self._U.T, 0.0, _D_MAX)
        np.fill_diagonal(dist, np.inf)  # leave each point out of its own neighbourhood
        same_mask = y[:, None] == y[None, :]
        # k smallest distances to each class, ascending, inf-padded when a class has fewer than k members
        self._same = np.sort(np.where(same_mask, dist, np.inf), axis=1)[:, :k]
        self._other = np.sort(np.where(~same_mask, dist, np.inf), axis=1)[:, :k]
        if self._same.shape[1] < k:
            pad = np.full((n, k - self._same.shape[1]), np.inf)
            self._same = np.hstack([self._same, pad])
            self._other = np.hstack([self._other, pad])

    def failure_pvalues(self, X: np.ndarray) -> np.ndarray:
        """Conformal p-value of "this action fails" for each row of X (n, dim)."""
        X = np.atleast_2d(np.asarray(X, dtype=np.float64))
        n, k = len(self._labels), self.k
        if n == 0:
            return np.ones(len(X))
        delta = np.clip(1.0 - _unit(X) @ self._U.T, 0.0, _D_MAX)  # (m, n)
        fail = ~self._labels
        m = len(X)
        past_same = np.broadcast_to(self._same, (m, n, k))
        past_other = np.broadcast_to(self._other, (m, n, k))

        def add_new(past: np.ndarray) -> np.ndarray:
            return np.sort(np.concatenate([past, delta[..., None]], axis=-1), axis=-1)[..., :k]

        # the new point (x, fail) joins the same-label set of past failures, the other-label set of past successes
        is_fail = fail[None, :, None]
        same = np.where(is_fail, add_new(past_same), past_same)
        other = np.where(is_fail, past_other, add_new(past_other))
        train_scores = (_mean_k(same, k) + _EPS) / (_mean_k(other, k) + _EPS)  # (m, n)
        to_fail = np.sort(np.where(fail[None, :], delta, np.inf), axis=1)[:, :k]
        to_success = np.sort(np.where(~fail[None, :], delta, np.inf), axis=1)[:, :k]
        test_score = (_mean_k(to_fail, k) + _EPS) / (_mean_k(to_success, k) + _EPS)  # (m,)
        at_least = (train_scores >= test_score[:, None] - 1e-12).sum(axis=1)
        return (at_least + 1) / (n + 1)

    def _predict_model(self, X: np.ndarray) -> np.ndarray:
        return 1.0 - self.failure_pvalues(X)

    def _predict_uncached(self, X: np.ndarray) -> np.ndarray:
        return self._predict_model(X)
