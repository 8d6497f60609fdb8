"""κ̂ by name: the paper's six classifiers, a GP, our conformal one, an ε-greedy variant of each, and grounded ones.

CALIBRATED_ESTIMATORS ("<name>-cal", for a plain or grounded name) pass the estimator's scores through a Platt
map learnt from its out-of-fold scores on the training rows (calibration.py).

ESTIMATORS read action embeddings only (the paper's κ̂, every benchmark over actions). GROUNDED_ESTIMATORS read
an embedding followed by the execution context: "grounded-<base>" (grounded.py) and "physical" (physical.py, the
shipped tree's κ̂, which reads the context relative to the arm's gripper). make_estimator builds any of them.
"xgboost" is accepted for "xgb".
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from scone_bt.confidence.base import ConfidenceEstimator
from scone_bt.confidence.calibration import CalibratedEstimator
from scone_bt.confidence.conformal import ConformalKNNEstimator
from scone_bt.confidence.epsilon import EpsilonGreedy
from scone_bt.confidence.gp import GPEstimator
from scone_bt.confidence.grounded import GroundedEstimator
from scone_bt.confidence.models import (
    KNNEstimator,
    LGBMEstimator,
    MLPEstimator,
    RandomForestEstimator,
    SVMEstimator,
    XGBEstimator,
)
from scone_bt.errors import SconeError, UnknownNameError

__all__ = [
    "BASE_ESTIMATORS",
    "CALIBRATED_ESTIMATORS",
    "ESTIMATORS",
    "GROUNDED_ESTIMATORS",
    "estimator_names",
    "make_estimator",
]

_FACTORIES: dict[str, Callable[..., ConfidenceEstimator]] = {
    "knn": KNNEstimator,
    "lgbm": LGBMEstimator,
    "rf": RandomForestEstimator,
    "svm": SVMEstimator,
    "mlp": MLPEstimator,
    "xgb": XGBEstimator,
    "gp": GPEstimator,
    "conformal": ConformalKNNEstimator,
}
BASE_ESTIMATORS: tuple[str, ...] = tuple(_FACTORIES)
ESTIMATORS: tuple[str, ...] = (*BASE_ESTIMATORS, *(f"eps-{n}" for n in BASE_ESTIMATORS))
GROUNDED_ESTIMATORS: tuple[str, ...] = (
    *(f"grounded-{n}" for n in BASE_ESTIMATORS if n != "conformal"),
    "physical",  # hardware-relative context and the embedding's principal components (physical.py)
)
CALIBRATED_ESTIMATORS: tuple[str, ...] = tuple(
    f"{n}-cal" for n in (*BASE_ESTIMATORS, *GROUNDED_ESTIMATORS) if n not in ("conformal", "physical")
)
_ALIASES = {"xgboost": "xgb"}
_EPS_KEYS = ("epsilon", "half_life")


def estimator_names() -> tuple[str, ...]:
    """Every name `make_estimator` accepts, sorted (the one list an error message or a file check shows)."""
    return tuple(sorted({*ESTIMATORS, *GROUNDED_ESTIMATORS, *CALIBRATED_ESTIMATORS, *_ALIASES}))


_GROUNDED_KEYS = ("n_context", "context_weight")


def make_estimator(name: str, seed: int = 0, **options: float) -> ConfidenceEstimator:
    """A fresh estimator by name (see ESTIMATORS), e.g. make_estimator("eps-knn", seed=3, epsilon=0.2).

    Args:
        name: One of ESTIMATORS, GROUNDED_ESTIMATORS or CALIBRATED_ESTIMATORS (or "xgboost").
        seed: Seeds model fitting and ε-greedy draws.
        **options: Constructor options: k (knn, conformal), n_estimators (rf, lgbm, xgb), colsample (lgbm), C
            (svm), hidden (mlp), length_scale and restarts (gp), prior (all but conformal), epsilon and half_life
            (eps-* only), n_context and context_weight (grounded-* only), gripper_opening_m and C (physical).

    Raises:
        UnknownNameError: not one of those names.
        SconeError: an option the estimator does not take.
    """
    name = _ALIASES.get(name, name)
    if name.endswith("-cal"):
        if name not in CALIBRATED_ESTIMATORS:
            raise UnknownNameError("estimator", name, estimator_names())
        inner = name.removesuffix("-cal")
        return CalibratedEstimator(lambda: make_estimator(inner, seed, **options), seed=seed)
    if name == "physical":
        from scone_bt.confidence.physical import PhysicalEstimator

        try:
            return PhysicalEstimator(name=name, seed=seed, **options)
        except TypeError as exc:
            raise SconeError(f"bad option for estimator 'physical': {exc}") from None
    if name.startswith("grounded-"):
        if name not in GROUNDED_ESTIMATORS:
            raise UnknownNameError("estimator", name, estimator_names())
        grounded_opts: dict[str, Any] = {k: options.pop(k) for k in _GROUNDED_KEYS if k in options}
        base = make_estimator(name.removeprefix("grounded-"), seed, **options)
        return GroundedEstimator(base, **grounded_opts)
    if name not in ESTIMATORS:
        raise UnknownNameError("estimator", name, estimator_names())
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
