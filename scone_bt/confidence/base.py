"""κ̂, the self-confidence interface: action embedding in, success probability out, learnt online.

Cold start (shared by every classifier-backed estimator): with no outcome yet κ̂ predicts `prior` (0.5); while
all outcomes so far share one class it predicts the Laplace-smoothed success rate (s + 1) / (n + 2) for every
action, because a classifier cannot be fitted on one class. Once both classes are present the model is refitted
after every outcome. (The conformal estimator handles these cases itself; see conformal.py.)

Predictions are memoised per embedding row until the next update, so the tree asking again every tick for the
same 21 actions costs one hash lookup per action.
"""

from __future__ import annotations

import hashlib
import sys
from abc import ABC, abstractmethod
from typing import Any

import numpy as np

from scone_bt.errors import SconeError

__all__ = ["ConfidenceEstimator", "row_key"]

_MEMO_LIMIT = 4096
_CONTROLLER: tuple[int, Any] | None = None


def _one_thread() -> Any:
    """Context that pins BLAS/OpenMP pools to one thread.

    Tiny fits and predictions gain nothing from threads, and on a loaded machine OpenBLAS's spinning threads cost
    a lot: an MLP refit on 60 outcomes took 4 s with two threads and 0.15 s with one, on a busy 2-core machine.
    The libraries are scanned again after new modules were imported: scipy brings its own OpenBLAS, loaded only
    when a model first imports scipy.linalg (a 200 × 200 Cholesky took 70 ms in its unpinned pool, 1 ms pinned).
    """
    global _CONTROLLER
    modules = len(sys.modules)
    if _CONTROLLER is None or _CONTROLLER[0] != modules:
        from threadpoolctl import ThreadpoolController

        _CONTROLLER = (len(sys.modules), ThreadpoolController())  # a scan takes ms: only when imports changed
    return _CONTROLLER[1].limit(limits=1)


def row_key(row: np.ndarray) -> bytes:
    """Identity of one float32 embedding row (for memoisation)."""
    return hashlib.blake2b(np.ascontiguousarray(row, dtype=np.float32).tobytes(), digest_size=16).digest()


class ConfidenceEstimator(ABC):
    """Success-probability estimator over action embeddings, updated after every observed outcome.

    Attributes:
        name: Registry name ("knn", "eps-rf", ...).
        seed: Seeds every random choice of the estimator.
        prior: Prediction before any outcome, in [0, 1].
    """

    #: True if `_fit_model`/`_predict_model` cope with zero or one-class data themselves.
    handles_one_class = False

    def __init__(self, name: str, seed: int = 0, prior: float = 0.5) -> None:
        if not 0.0 <= prior <= 1.0:
            raise SconeError(f"prior must be a probability in [0, 1], got {prior}")
        self.name = name
        self.seed = seed
        self.prior = prior
        self._X = np.zeros((0, 0), dtype=np.float32)
        self._y = np.zeros(0, dtype=bool)
        self._n = 0
        self._fitted = False
        self._memo: dict[bytes, float] = {}

    # ----- data ---------------------------------------------------------------------------------------------
    @property
    def n_observations(self) -> int:
        """Outcomes learnt from so far."""
        return self._n

    @property
    def n_successes(self) -> int:
        """Successful outcomes among them."""
        return int(self._y[: self._n].sum())

    @property
    def X(self) -> np.ndarray:
        """Observed embeddings (n, dim), a read-only view."""
        view = self._X[: self._n]
        view.flags.writeable = False
        return view

    @property
    def y(self) -> np.ndarray:
        """Observed outcomes (n,), True for success."""
        return self._y[: self._n].copy()

    def _check_dim(self, dim: int) -> None:
        if self._n and dim != self._X.shape[1]:
            raise SconeError(
                f"{self.name}: embedding has {dim} values but earlier ones had {self._X.shape[1]}; "
                "use one embedder per estimator"
            )

    def update(self, x: np.ndarray, success: bool) -> None:
        """Learn from one outcome (x: the action's embedding, shape (dim,))."""
        x = np.asarray(x, dtype=np.float32).reshape(-1)
        self._check_dim(x.size)
        if self._n == 0:
            self._X = np.zeros((16, x.size), dtype=np.float32)
            self._y = np.zeros(16, dtype=bool)
        elif self._n == len(self._X):  # grow by doubling: amortised O(1) appends
            self._X = np.concatenate([self._X, np.zeros_like(self._X)])
            self._y = np.concatenate([self._y, np.zeros_like(self._y)])
        self._X[self._n] = x
        self._y[self._n] = bool(success)
        self._n += 1
        self._refit()

    def fit(self, X: np.ndarray, y: np.ndarray) -> ConfidenceEstimator:
        """Replace everything learnt by these outcomes (X: (n, dim), y: (n,) bools); returns self."""
        X = np.asarray(X, dtype=np.float32)
        y = np.asarray(y, dtype=bool).reshape(-1)
        if X.ndim != 2 or len(X) != len(y):
            raise SconeError(f"fit needs X of shape (n, dim) and n labels; got {X.shape} and {y.shape}")
        self._X, self._y, self._n = X.copy(), y.copy(), len(y)
        self._refit()
        return self

    def _refit(self) -> None:
        self._memo.clear()
        X, y = self._X[: self._n], self._y[: self._n]
        if self.handles_one_class or (y.any() and not y.all()):
            with _one_thread():
                self._fit_model(X, y)
            self._fitted = True
        else:
            self._fitted = False

    def share_hyperparameters(self, fitted: ConfidenceEstimator) -> None:
        """Take the hyper-parameters that `fitted`, an estimator of the same kind, tuned on its data (default: none).

        Used by calibration.py: the out-of-fold models of a calibrated estimator reuse what its final model tuned.
        """
        return None

    # ----- prediction ---------------------------------------------------------------------------------------
    def forget_predictions(self) -> None:
        """Drop memoised predictions (they are also dropped on every update); for benchmarks."""
        self._memo.clear()

    def predict(self, X: np.ndarray) -> np.ndarray:
        """Success probability of each row of X (n, dim), float64 in [0, 1]."""
        X = np.atleast_2d(np.asarray(X, dtype=np.float32))
        if len(X) == 0:
            return np.zeros(0)
        self._check_dim(X.shape[1])
        keys = [row_key(r) for r in X]
        out = np.empty(len(X))
        todo = []
        for i, k in enumerate(keys):
            v = self._memo.get(k)
            if v is None:
                todo.append(i)
            else:
                out[i] = v
        if todo:
            with _one_thread():
                fresh = np.clip(self._predict_uncached(X[todo]), 0.0, 1.0)
            out[todo] = fresh
            if len(self._memo) > _MEMO_LIMIT:
                self._memo.clear()
            for i, v in zip(todo, fresh, strict=True):
                self._memo[keys[i]] = float(v)
        return out

    def belief(self, X: np.ndarray) -> np.ndarray:
        """κ̂'s success probability for each row of X: what evaluation scores (equal to predict here)."""
        return self.predict(X)

    def decide(self, X: np.ndarray, threshold: float = 0.5) -> np.ndarray:
        """Which rows the robot would attempt (bool (n,)): belief ≥ threshold (ε-greedy also explores)."""
        return self.belief(X) >= threshold

    def _predict_uncached(self, X: np.ndarray) -> np.ndarray:
        if self._fitted:
            return self._predict_model(X)
        if self._n == 0:
            return np.full(len(X), self.prior)
        return np.full(len(X), (self.n_successes + 1) / (self._n + 2))

    @abstractmethod
    def _fit_model(self, X: np.ndarray, y: np.ndarray) -> None:
        """Fit on all outcomes so far (both classes present unless handles_one_class)."""

    @abstractmethod
    def _predict_model(self, X: np.ndarray) -> np.ndarray:
        """Success probabilities for rows of X from the fitted model."""

    def __repr__(self) -> str:
        return f"{type(self).__name__}(name={self.name!r}, n_observations={self._n})"
