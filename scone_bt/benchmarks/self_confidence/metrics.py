"""Scores of probabilistic success predictions: accuracy, AUROC and Brier (scikit-learn), calibration, curve area.

scikit-learn has no expected calibration error; `reliability_bins` and `expected_calibration_error` compute it
from equal-width bins (the reliability diagram's bars).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

__all__ = [
    "ECE_FLOOR_SIMULATIONS",
    "ReliabilityBin",
    "accuracy",
    "auroc",
    "brier_score",
    "ece_noise_floor",
    "expected_calibration_error",
    "normalised_auc",
    "reliability_bins",
]


def accuracy(p: np.ndarray, y: np.ndarray, threshold: float = 0.5) -> float:
    """Fraction of outcomes predicted right when success is predicted for p ≥ threshold; NaN for no rows."""
    from sklearn.metrics import accuracy_score

    y = np.asarray(y, dtype=bool)
    if len(y) == 0:
        return float("nan")
    return float(accuracy_score(y, np.asarray(p, dtype=float) >= threshold))


def auroc(p: np.ndarray, y: np.ndarray) -> float:
    """Area under the ROC curve (ties count half); NaN when only one class occurs."""
    from sklearn.metrics import roc_auc_score

    y = np.asarray(y, dtype=bool)
    if y.all() or not y.any():
        return float("nan")
    return float(roc_auc_score(y, np.asarray(p, dtype=float)))


def brier_score(p: np.ndarray, y: np.ndarray) -> float:
    """Mean squared error of the success probability (0 is perfect, 0.25 is a constant 0.5); NaN for no rows."""
    from sklearn.metrics import brier_score_loss

    y = np.asarray(y, dtype=bool)
    if len(y) == 0:
        return float("nan")
    return float(brier_score_loss(y, np.clip(np.asarray(p, dtype=float), 0.0, 1.0), pos_label=True))


@dataclass(frozen=True)
class ReliabilityBin:
    """One bar of a reliability diagram.

    Attributes:
        lower: Lower edge of the predicted-probability bin.
        upper: Upper edge (the last bin includes 1.0).
        count: Predictions in the bin.
        mean_predicted: Mean predicted success probability in the bin (NaN if empty).
        observed_rate: Observed success rate in the bin (NaN if empty).
    """

    lower: float
    upper: float
    count: int
    mean_predicted: float
    observed_rate: float


def reliability_bins(p: np.ndarray, y: np.ndarray, bins: int = 10) -> list[ReliabilityBin]:
    """Equal-width bins of the predicted probability with their mean prediction and observed success rate."""
    p = np.clip(np.asarray(p, dtype=float), 0.0, 1.0)
    y = np.asarray(y, dtype=float)
    which = np.minimum((p * bins).astype(int), bins - 1)
    out = []
    for b in range(bins):
        mask = which == b
        n = int(mask.sum())
        out.append(
            ReliabilityBin(
                b / bins,
                (b + 1) / bins,
                n,
                float(p[mask].mean()) if n else float("nan"),
                float(y[mask].mean()) if n else float("nan"),
            )
        )
    return out


def expected_calibration_error(p: np.ndarray, y: np.ndarray, bins: int = 10) -> float:
    """Σ_b (n_b / n) |observed rate_b − mean prediction_b| over `bins` equal-width bins; NaN for no rows."""
    if len(np.asarray(y)) == 0:
        return float("nan")
    table = reliability_bins(p, y, bins)
    total = sum(b.count * abs(b.observed_rate - b.mean_predicted) for b in table if b.count)
    return float(total / sum(b.count for b in table))


def normalised_auc(steps: Sequence[float], values: Sequence[float] | np.ndarray) -> float:
    """Trapezoidal area under a curve over its x range, divided by that range (a curve of 1 gives 1)."""
    x = np.asarray(steps, dtype=float)
    v = np.asarray(values, dtype=float)
    if len(x) == 1:
        return float(v[0])
    return float(np.trapezoid(v, x) / (x[-1] - x[0]))


ECE_FLOOR_SIMULATIONS = 1000
"""Simulated outcome sets behind each ECE noise floor (its Monte-Carlo error is about 0.0005)."""


def ece_noise_floor(
    p: np.ndarray, bins: int = 10, simulations: int = ECE_FLOOR_SIMULATIONS, seed: int = 0
) -> tuple[float, float]:
    """(mean, 95th percentile) of the ECE of a perfectly calibrated predictor making these predictions.

    Outcomes are drawn as y ~ Bernoulli(p), so the predictor is calibrated by construction and every bit of its
    ECE is sampling noise: what a measured ECE on len(p) rows must be compared with. NaN for no rows.
    """
    p = np.clip(np.asarray(p, dtype=float), 0.0, 1.0)
    if len(p) == 0:
        return float("nan"), float("nan")
    which = np.minimum((p * bins).astype(int), bins - 1)
    onehot = np.zeros((bins, len(p)))
    onehot[which, np.arange(len(p))] = 1.0
    predicted = onehot @ p  # per bin: Σ p (independent of the draw)
    y = np.random.default_rng([seed, 11]).random((simulations, len(p))) < p
    observed = y.astype(float) @ onehot.T  # (simulations, bins): Σ y per bin
    ece = np.abs(observed - predicted).sum(axis=1) / len(p)  # Σ_b n_b/n |ȳ_b − p̄_b| = Σ_b |Σy − Σp| / n
    return float(ece.mean()), float(np.quantile(ece, 0.95))
