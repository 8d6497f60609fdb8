"""κ̂ by name: the paper's six classifiers, our conformal one, and an ε-greedy variant of each."""

from __future__ import annotations

from collections.abc import Callable

from scone_bt.confidence.base import ConfidenceEstimator
from scone_bt.confidence.conformal import ConformalKNNEstimator
from scone_bt.confidence.epsilon import EpsilonGreedy
from scone_bt.confidence.models import (
    KNNEstimator,
    LGBMEstimator,
    MLPEstimator,
    RandomForestEstimator,
    SVMEstimator,
    XGBEstimator,
)
from scone_bt.errors import SconeError, UnknownNameError

__all__ = ["BASE_ESTIMATORS", "ESTIMATORS", "make_estimator"]

_FACTORIES: dict[str, Callable[..., ConfidenceEstimator]] = {
    "knn": KNNEstimator,
    "lgbm": LGBMEstimator,
    "rf": RandomForestEstimator,
    "svm": SVMEstimator,
    "mlp": MLPEstimator,
    "xgb": XGBEstimator,
    "conformal": ConformalKNNEstimator,
}
BASE_ESTIMATORS: tuple[str, ...] = tuple(_FACTORIES)
ESTIMATORS: tuple[str, ...] = (*BASE_ESTIMATORS, *(f"eps-{n}" for n in BASE_ESTIMATORS))
_EPS_KEYS = ("epsilon", "half_life")


def make_estimator(name: str, seed: int = 0, **options: float) -> ConfidenceEstimator:
    """A fresh estimator by name (see ESTIMATORS), e.g. make_estimator("eps-knn", seed=3, epsilon=0.2).

    Args:
        name: One of ESTIMATORS.
        seed: Seeds model fitting and ε-greedy draws.
        **options: Constructor options: k (knn, conformal), n_estimators (rf, lgbm, xgb), C (svm), hidden
            (mlp), prior (all but conformal), epsilon and half_life (eps-* only).

    Raises:
        UnknownNameError: not one of ESTIMATORS.
        SconeError: an option the estimator does not take.
    """
    if name not in ESTIMATORS:
        raise UnknownNameError("estimator", name, ESTIMATORS)
    eps_opts = {k: options.pop(k) for k in _EPS_KEYS if k in options}
    base_name = name.removeprefix("eps-")
    if eps_opts and base_name == name:
        raise SconeError(f"{', '.join(eps_opts)} only apply to ε-greedy estimators, e.g. eps-{name}")
    try:
        base = _FACTORIES[base_name](name=base_name, seed=seed, **options)
    except TypeError as exc:
        raise SconeError(f"bad option for estimator {base_name!r}: {exc}") from None
    if base_name == name:
        return base
    return EpsilonGreedy(base, seed=seed, **eps_opts)
