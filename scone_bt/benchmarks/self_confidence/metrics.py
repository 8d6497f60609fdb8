"""Scores of probabilistic success predictions: accuracy, AUROC, Brier score, calibration error, curve area."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

__all__ = ["accuracy", "auroc", "brier_score", "expected_calibration_error", "normalised_auc"]


def accuracy(p: np.ndarray, y: np.ndarray, threshold: float = 0.5) -> float:
    """Fraction of outcomes predicted right when success is predicted for p ≥ threshold."""
    return float(np.mean((np.asarray(p) >= threshold) == np.asarray(y, dtype=bool)))


def auroc(p: np.ndarray, y: np.ndarray) -> float:
    """Area under the ROC curve (probability a success scores above a failure, ties count half); NaN if one class."""
    p = np.asarray(p, dtype=float)
    y = np.asarray(y, dtype=bool)
    pos, neg = p[y], p[~y]
    if len(pos) == 0 or len(neg) == 0:
        return float("nan")
    greater = (pos[:, None] > neg[None, :]).sum()
    ties = (pos[:, None] == neg[None, :]).sum()
    return float((greater + 0.5 * ties) / (len(pos) * len(neg)))


def brier_score(p: np.ndarray, y: np.ndarray) -> float:
    """Mean squared error of the success probability (0 is perfect, 0.25 is a constant 0.5)."""
    return float(np.mean((np.asarray(p, dtype=float) - np.asarray(y, dtype=float)) ** 2))


def expected_calibration_error(p: np.ndarray, y: np.ndarray, bins: int = 10) -> float:
    """Σ_b (n_b / n) |mean(y_b) − mean(p_b)| over `bins` equal-width probability bins."""
    p = np.clip(np.asarray(p, dtype=float), 0.0, 1.0)
    y = np.asarray(y, dtype=float)
    which = np.minimum((p * bins).astype(int), bins - 1)
    total = 0.0
    for b in range(bins):
        mask = which == b
        if mask.any():
            total += mask.sum() * abs(y[mask].mean() - p[mask].mean())
    return float(total / len(p))


def normalised_auc(steps: Sequence[float], values: Sequence[float]) -> float:
    """Trapezoidal area under a curve over its x range, divided by that range (a curve of 1 gives 1)."""
    x = np.asarray(steps, dtype=float)
    v = np.asarray(values, dtype=float)
    if len(x) == 1:
        return float(v[0])
    return float(np.trapezoid(v, x) / (x[-1] - x[0]))
