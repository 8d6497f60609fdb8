"""The paper's Algorithm 1: how fast and how well an embedder × estimator pair learns self-confidence.

For every shuffle s and dataset d: permute d's rows (seeded by s and d, identical for every pair), keep the last
`n_test` rows as the test set, and for n_train = 10, 20, …, 80 fit a fresh estimator on the first n_train rows and
score its predictions on the test set. Accuracy per step is averaged over datasets (the learning curve); its
normalised area is the paper's number. AUROC, Brier score and ECE are computed at the largest n_train on the test
predictions of all datasets pooled (20 rows per dataset are too few for a per-dataset AUROC). Every number is
reported as mean ± std over shuffles.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np

from scone_bt.benchmarks.self_confidence.dataset import Dataset
from scone_bt.benchmarks.self_confidence.metrics import (
    accuracy,
    auroc,
    brier_score,
    expected_calibration_error,
    normalised_auc,
)
from scone_bt.errors import ConfigError

__all__ = [
    "EvalOptions",
    "PairResult",
    "Estimator",
    "EstimatorFactory",
    "embed_datasets",
    "evaluate_pair",
    "GridInputs",
    "evaluate_grid_pair",
    "prior_baseline",
    "shuffled_order",
]


class Estimator(Protocol):
    """What the evaluation needs of κ̂ (scone_bt.confidence estimators satisfy it)."""

    def fit(self, X: np.ndarray, y: np.ndarray) -> Any: ...

    def predict(self, X: np.ndarray) -> np.ndarray: ...


EstimatorFactory = Callable[[int], Estimator]
"""Builds a fresh, untrained estimator from a seed."""


@dataclass(frozen=True)
class EvalOptions:
    """Settings of Algorithm 1.

    Attributes:
        n_test: Rows at the end of each shuffled dataset used for testing.
        steps: Training-set sizes n_train, increasing.
        shuffles: Number of seeded row permutations (≥ 1; the paper's protocol asks ≥ 5).
        seed: Base seed of the permutations and the estimators.
        ece_bins: Equal-width bins of the calibration error.
        threshold: Success is predicted when κ̂ ≥ threshold.
    """

    n_test: int = 20
    steps: tuple[int, ...] = (10, 20, 30, 40, 50, 60, 70, 80)
    shuffles: int = 5
    seed: int = 0
    ece_bins: int = 10
    threshold: float = 0.5

    def __post_init__(self) -> None:
        if self.n_test < 1 or self.shuffles < 1 or not self.steps:
            raise ConfigError("n_test and shuffles must be ≥ 1 and steps non-empty")
        if list(self.steps) != sorted(set(self.steps)) or self.steps[0] < 1:
            raise ConfigError(f"steps must be distinct, increasing and ≥ 1, got {list(self.steps)}")

    @property
    def min_rows(self) -> int:
        return self.steps[-1] + self.n_test


@dataclass(frozen=True)
class PairResult:
    """Algorithm 1's numbers for one embedder × estimator pair (means and stds over shuffles).

    Attributes:
        embedder: Embedder name.
        estimator: Estimator name.
        steps: n_train values.
        curve_mean: Accuracy per step, averaged over datasets, then over shuffles.
        curve_std: Std over shuffles of the dataset-averaged accuracy per step.
        auc: Normalised area under the learning curve per shuffle.
        auroc: Pooled AUROC at the largest n_train per shuffle.
        brier: Pooled Brier score at the largest n_train per shuffle.
        ece: Pooled expected calibration error at the largest n_train per shuffle.
        final_accuracy: Dataset-averaged accuracy at the largest n_train per shuffle.
        wall_s: Wall time of this pair's evaluation, seconds.
    """

    embedder: str
    estimator: str
    steps: tuple[int, ...]
    curve_mean: tuple[float, ...]
    curve_std: tuple[float, ...]
    auc: tuple[float, ...]
    auroc: tuple[float, ...]
    brier: tuple[float, ...]
    ece: tuple[float, ...]
    final_accuracy: tuple[float, ...]
    wall_s: float = field(default=0.0, compare=False)

    @staticmethod
    def _ms(values: Sequence[float]) -> dict[str, float]:
        v = np.asarray(values, dtype=float)
        return {
            "mean": float(np.nanmean(v)),
            "std": float(np.nanstd(v)),
            "per_shuffle": [float(x) for x in v],
        }

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready numbers."""
        return {
            "embedder": self.embedder,
            "estimator": self.estimator,
            "n_train": list(self.steps),
            "accuracy_curve": {"mean": list(self.curve_mean), "std": list(self.curve_std)},
            "auc": self._ms(self.auc),
            "final_accuracy": self._ms(self.final_accuracy),
            "auroc": self._ms(self.auroc),
            "brier": self._ms(self.brier),
            "ece": self._ms(self.ece),
            "wall_s": round(self.wall_s, 3),
        }


def shuffled_order(n: int, shuffle: int, dataset_index: int, seed: int = 0) -> np.ndarray:
    """The row permutation of one dataset in one shuffle (shared by every embedder and estimator)."""
    return np.random.default_rng([seed, shuffle, dataset_index]).permutation(n)


def embed_datasets(datasets: Sequence[Dataset], embed: Callable[[list[str]], np.ndarray]) -> list[np.ndarray]:
    """(n, d) float matrices, one per dataset; each distinct action text is embedded once."""
    texts = sorted({a for d in datasets for a in d.actions})
    vectors = np.asarray(embed(texts), dtype=np.float64)
    if vectors.shape[0] != len(texts):
        raise ConfigError(f"the embedder returned {vectors.shape[0]} vectors for {len(texts)} texts")
    row = {t: i for i, t in enumerate(texts)}
    return [vectors[[row[a] for a in d.actions]] for d in datasets]


def _check(datasets: Sequence[Dataset], options: EvalOptions) -> None:
    if not datasets:
        raise ConfigError("no datasets to evaluate")
    short = [d for d in datasets if len(d) < options.min_rows]
    if short:
        raise ConfigError(
            f"dataset {short[0].name} has {len(short[0])} rows; n_train up to {options.steps[-1]} "
            f"plus {options.n_test} test rows needs {options.min_rows}"
        )


def evaluate_pair(
    embedder: str,
    estimator: str,
    datasets: Sequence[Dataset],
    features: Sequence[np.ndarray],
    make: EstimatorFactory,
    options: EvalOptions = EvalOptions(),
) -> PairResult:
    """Run Algorithm 1 for one pair.

    Args:
        embedder: Name recorded in the result.
        estimator: Name recorded in the result.
        datasets: The datasets (their outcomes and order).
        features: Embedded actions per dataset, rows aligned with the dataset's rows.
        make: Fresh estimator from a seed; called once per dataset, shuffle and step.
        options: Protocol settings.
    """
    _check(datasets, options)
    t0 = time.perf_counter()
    steps = options.steps
    curves = np.zeros((options.shuffles, len(steps)))
    aucs, aurocs, briers, eces, finals = [], [], [], [], []
    for s in range(options.shuffles):
        acc = np.zeros((len(datasets), len(steps)))
        pooled_p, pooled_y = [], []
        for di, (data, X) in enumerate(zip(datasets, features, strict=True)):
            order = shuffled_order(len(data), s, di, options.seed)
            Xs, ys = X[order], data.success[order]
            X_test, y_test = Xs[-options.n_test :], ys[-options.n_test :]
            for k, n in enumerate(steps):
                est = make(options.seed * 1000 + s)
                est.fit(Xs[:n], ys[:n])
                p = np.clip(np.asarray(est.predict(X_test), dtype=float).reshape(-1), 0.0, 1.0)
                acc[di, k] = accuracy(p, y_test, options.threshold)
            pooled_p.append(p)
            pooled_y.append(y_test)
        curve = acc.mean(axis=0)
        curves[s] = curve
        aucs.append(normalised_auc(steps, curve))
        finals.append(float(curve[-1]))
        p_all, y_all = np.concatenate(pooled_p), np.concatenate(pooled_y)
        aurocs.append(auroc(p_all, y_all))
        briers.append(brier_score(p_all, y_all))
        eces.append(expected_calibration_error(p_all, y_all, options.ece_bins))
    return PairResult(
        embedder=embedder,
        estimator=estimator,
        steps=tuple(steps),
        curve_mean=tuple(float(v) for v in curves.mean(axis=0)),
        curve_std=tuple(float(v) for v in curves.std(axis=0)),
        auc=tuple(aucs),
        auroc=tuple(aurocs),
        brier=tuple(briers),
        ece=tuple(eces),
        final_accuracy=tuple(finals),
        wall_s=time.perf_counter() - t0,
    )


class _Prior:
    """Predicts the training prefix's success rate for every action (what κ̂ must beat)."""

    def fit(self, X: np.ndarray, y: np.ndarray) -> _Prior:
        self.rate = float(np.mean(y)) if len(y) else 0.5
        return self

    def predict(self, X: np.ndarray) -> np.ndarray:
        return np.full(len(X), self.rate)


def prior_baseline(datasets: Sequence[Dataset], options: EvalOptions = EvalOptions()) -> PairResult:
    """Algorithm 1 for a predictor that ignores the action (the majority outcome seen so far)."""
    zeros = [np.zeros((len(d), 1)) for d in datasets]
    return evaluate_pair("none", "prior", datasets, zeros, lambda seed: _Prior(), options)


@dataclass(frozen=True)
class GridInputs:
    """What every pair of the embedder × estimator grid reads (shipped once per worker by scone_bt.distributed).

    Attributes:
        datasets: The datasets.
        features: Embedded actions per dataset, per embedder name.
        options: Protocol settings.
    """

    datasets: tuple[Dataset, ...]
    features: dict[str, list[np.ndarray]]
    options: EvalOptions


def evaluate_grid_pair(pair: tuple[str, str], inputs: GridInputs) -> PairResult:
    """Algorithm 1 for one (embedder, estimator) pair of the grid, with scone_bt.confidence's estimator."""
    from scone_bt.confidence import make_estimator

    emb, est = pair
    return evaluate_pair(
        emb,
        est,
        inputs.datasets,
        inputs.features[emb],
        lambda seed: make_estimator(est, seed=seed),
        inputs.options,
    )
