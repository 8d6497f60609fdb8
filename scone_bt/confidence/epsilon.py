"""ε-greedy κ̂: exploration changes which actions the robot tries, never the belief that is scored.

Without it, an estimator whose early outcomes were failures predicts failure everywhere, the robot only ever
asks for help, and it never observes another outcome (the cold-start trap the paper counters with ε-greedy).

The rule (what the self-confidence benchmark tests):
- `belief(X)` is the wrapped estimator's probability, unchanged: trained on the same labels, ε-X and X have the
  same belief function. This is what AUC, AUROC, Brier and ECE score.
- `decide(X, τ)` is what the robot attempts: belief ≥ τ, or an exploration draw below ε. Exploring, the robot
  acts despite low confidence and so observes a label it would otherwise never get (it asked for help instead).
  The benefit of ε-greedy is therefore in *which labels the robot collects* online; with ε = 0 it never explores.
- `predict(X)` is what the behaviour tree's gate reads today: 1.0 on an exploration draw, else the belief, so that
  a gate comparing predict with its threshold acts exactly when `decide` says so.

ε after n outcomes is ε₀ · 2^(−n / half_life). The exploration draw for an action is a hash of (seed, n, the
action's embedding): fixed until the next outcome, so the gate does not flicker between ticks of the tree, and
reproducible for a given seed.
"""

from __future__ import annotations

import hashlib

import numpy as np

from scone_bt.confidence.base import ConfidenceEstimator
from scone_bt.errors import SconeError

__all__ = ["EpsilonGreedy"]


class EpsilonGreedy(ConfidenceEstimator):
    """Wraps another estimator; see the module docstring.

    Args:
        base: The estimator that learns (it receives every update).
        epsilon: ε₀, the exploration probability before any outcome, in [0, 1].
        half_life: Outcomes after which ε halves (> 0).
        seed: Seeds the exploration draws.
    """

    handles_one_class = True

    def __init__(
        self, base: ConfidenceEstimator, epsilon: float = 0.3, half_life: float = 20.0, seed: int = 0
    ) -> None:
        if not 0.0 <= epsilon <= 1.0:
            raise SconeError(f"epsilon must be in [0, 1], got {epsilon}")
        if half_life <= 0:
            raise SconeError(f"half_life must be positive, got {half_life}")
        super().__init__(f"eps-{base.name}", seed, base.prior)
        self.base = base
        self.epsilon0 = epsilon
        self.half_life = half_life

    @property
    def epsilon(self) -> float:
        """Current exploration probability."""
        return self.epsilon0 * 2.0 ** (-self.base.n_observations / self.half_life)

    @property
    def n_observations(self) -> int:
        return self.base.n_observations

    @property
    def n_successes(self) -> int:
        return self.base.n_successes

    @property
    def X(self) -> np.ndarray:
        return self.base.X

    @property
    def y(self) -> np.ndarray:
        return self.base.y

    def forget_predictions(self) -> None:
        self.base.forget_predictions()

    def update(self, x: np.ndarray, success: bool) -> None:
        self.base.update(x, success)

    def fit(self, X: np.ndarray, y: np.ndarray) -> EpsilonGreedy:
        self.base.fit(X, y)
        return self

    def explores(self, X: np.ndarray) -> np.ndarray:
        """Which rows of X get the optimistic prediction now (bool (n,))."""
        X = np.atleast_2d(np.asarray(X, dtype=np.float32))
        eps, n = self.epsilon, self.base.n_observations
        prefix = f"{self.seed}:{n}:".encode()
        draws = np.array(
            [
                int.from_bytes(hashlib.blake2b(prefix + row.tobytes(), digest_size=8).digest(), "little")
                / 2.0**64
                for row in np.ascontiguousarray(X)
            ]
        )
        return draws < eps

    def belief(self, X: np.ndarray) -> np.ndarray:
        """The wrapped estimator's success probability (exploration never touches it)."""
        return self.base.predict(X)

    def decide(self, X: np.ndarray, threshold: float = 0.5) -> np.ndarray:
        """Rows the robot attempts: confident (belief ≥ threshold) or exploring."""
        X = np.atleast_2d(np.asarray(X, dtype=np.float32))
        if len(X) == 0:
            return np.zeros(0, dtype=bool)
        return (self.belief(X) >= threshold) | self.explores(X)

    def predict(self, X: np.ndarray) -> np.ndarray:
        """The gate's reading: 1.0 where the robot explores, else the belief."""
        X = np.atleast_2d(np.asarray(X, dtype=np.float32))
        if len(X) == 0:
            return np.zeros(0)
        return np.where(self.explores(X), 1.0, self.base.predict(X))

    def _fit_model(self, X: np.ndarray, y: np.ndarray) -> None:  # learning is delegated to base
        raise NotImplementedError

    def _predict_model(self, X: np.ndarray) -> np.ndarray:
        raise NotImplementedError
