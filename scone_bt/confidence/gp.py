"""κ̂ as a Gaussian-process classifier over action embeddings (beyond the paper's six).

The closest prior work is the GP trust-transfer model of Soh, Pan, Chen and Hsu ("The Transfer of Human Trust in
Robot Capabilities across Tasks", RSS 2018): a GP over task embeddings whose kernel lets a success on one task
raise the belief in similar tasks. Here the same idea models the robot's own competence: a Laplace-approximated
binary GP (scikit-learn's GaussianProcessClassifier) with a constant × RBF kernel on unit-normalised embeddings,
so the squared distance is 2 − 2·cos and the length scale says how far in meaning one outcome generalises. The
kernel's amplitude and length scale are fitted by marginal likelihood (bounded so that a handful of outcomes cannot
collapse the length scale to zero) whenever the outcomes have grown by `reoptimise_growth` (at least one) since
the last such fit; the refits in between keep those hyper-parameters and only recompute the Laplace posterior.
Marginal-likelihood optimisation is most of a refit's cost and grows with the data (about 0.12 s at 200 outcomes
against 13 ms for the posterior alone), while one more outcome among hundreds hardly moves the optimum; among the
first few it does (a second failure of the same product must lower its belief at once), so a young κ̂ optimises on
every outcome. Every benchmark refit (10 or more new rows) optimises. A GP given another's kernel
(share_hyperparameters: the out-of-fold models of "gp-cal") keeps it and only recomputes the posterior.
"""

from __future__ import annotations

import math
import warnings
from typing import Any

import numpy as np

from scone_bt.confidence.base import ConfidenceEstimator
from scone_bt.errors import SconeError

__all__ = ["GPEstimator"]


def _unit(X: np.ndarray) -> np.ndarray:
    norms = np.linalg.norm(X, axis=1, keepdims=True)
    return X / np.where(norms > 0, norms, 1.0)


class GPEstimator(ConfidenceEstimator):
    """Binary GP classifier (Laplace approximation), constant × RBF kernel on unit-normalised embeddings.

    Args:
        name: Registry name.
        seed: Seeds the optimiser restarts.
        length_scale: Initial RBF length scale (unit-vector distance; √2 separates orthogonal embeddings).
        restarts: Extra optimiser restarts of the kernel hyper-parameters.
        prior: Prediction before any outcome.
        reoptimise_growth: Relative growth of the outcomes that triggers a new marginal-likelihood optimisation of
            the kernel (0: every refit; 0.1: every outcome up to 10, then every n/10).
    """

    def __init__(
        self,
        name: str = "gp",
        seed: int = 0,
        length_scale: float = 1.0,
        restarts: int = 0,
        prior: float = 0.5,
        reoptimise_growth: float = 0.1,
    ) -> None:
        super().__init__(name, seed, prior)
        if not 0.0 <= reoptimise_growth <= 10.0:
            raise SconeError(f"{name}: reoptimise_growth must be between 0 and 10, got {reoptimise_growth}")
        self.length_scale = length_scale
        self.restarts = restarts
        self.reoptimise_growth = reoptimise_growth
        self._model: Any = None
        self._kernel: Any = None  # the last optimised kernel
        self._n_optimised = 0  # outcomes it was optimised on
        self._kernel_fixed = False  # a kernel from another GP (share_hyperparameters) is never re-optimised

    def share_hyperparameters(self, fitted: ConfidenceEstimator) -> None:
        """Keep `fitted`'s optimised kernel for every later fit (only the Laplace posterior is recomputed)."""
        kernel = getattr(fitted, "_kernel", None)
        if kernel is not None:
            self._kernel, self._kernel_fixed = kernel, True

    def _fit_model(self, X: np.ndarray, y: np.ndarray) -> None:
        from sklearn.exceptions import ConvergenceWarning
        from sklearn.gaussian_process import GaussianProcessClassifier
        from sklearn.gaussian_process.kernels import RBF, ConstantKernel

        n = len(y)
        step = max(1, math.ceil(self.reoptimise_growth * self._n_optimised))
        keep = self._kernel_fixed or (
            self._kernel is not None and self._n_optimised <= n < self._n_optimised + step
        )
        if keep:
            model = GaussianProcessClassifier(self._kernel, optimizer=None, random_state=self.seed)
        else:
            kernel = ConstantKernel(1.0, (1e-2, 1e2)) * RBF(self.length_scale, (0.05, 20.0))
            model = GaussianProcessClassifier(
                kernel, n_restarts_optimizer=self.restarts, random_state=self.seed
            )
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ConvergenceWarning)  # bounds reached on tiny data: still a GP
            model.fit(_unit(X.astype(np.float64)), y.astype(int))
        if not keep:
            self._kernel, self._n_optimised = model.kernel_, n
        self._model = model

    def _predict_model(self, X: np.ndarray) -> np.ndarray:
        return self._model.predict_proba(_unit(X.astype(np.float64)))[:, 1]
