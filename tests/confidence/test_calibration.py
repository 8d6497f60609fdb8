"""Calibrated κ̂ ("<name>-cal"): Platt map from out-of-fold scores, stratified folds, registry, cold start."""

from __future__ import annotations

import numpy as np
import pytest

from scone_bt.confidence import CALIBRATED_ESTIMATORS, CalibratedEstimator, make_estimator
from scone_bt.confidence.calibration import fit_platt, stratified_folds
from scone_bt.confidence.grounded import is_grounded
from scone_bt.errors import SconeError, UnknownNameError


def _sigmoid(z: np.ndarray) -> np.ndarray:
    return 1.0 / (1.0 + np.exp(-z))


def test_fit_platt_recovers_a_known_map():
    rng = np.random.default_rng(0)
    s = rng.uniform(0.02, 0.98, 20000)
    y = rng.random(len(s)) < _sigmoid(0.5 * np.log(s / (1 - s)) + 0.4)
    a, b = fit_platt(s, y)
    assert a == pytest.approx(0.5, abs=0.05)
    assert b == pytest.approx(0.4, abs=0.05)


def test_stratified_folds_put_both_classes_in_every_fold_and_repeat():
    y = np.array([True] * 7 + [False] * 5)
    folds = stratified_folds(y, 3, seed=4)
    for f in range(3):
        assert y[folds == f].any() and not y[folds == f].all()
    assert np.array_equal(folds, stratified_folds(y, 3, seed=4))
    assert not np.array_equal(folds, stratified_folds(y, 3, seed=5))


def test_calibration_softens_an_overconfident_base_on_noise():
    # Labels independent of the inputs: 1-NN's 0/1 scores are pure over-confidence; the map must pull them in.
    rng = np.random.default_rng(1)
    X = rng.standard_normal((90, 8)).astype(np.float32)
    y = rng.random(90) < 0.6
    Xt = rng.standard_normal((400, 8)).astype(np.float32)
    yt = rng.random(400) < 0.6
    raw = make_estimator("knn", k=1).fit(X, y).predict(Xt)
    cal = CalibratedEstimator(lambda: make_estimator("knn", k=1), seed=0).fit(X, y)
    p = cal.predict(Xt)
    assert cal.a < 0.5  # out-of-fold 1-NN scores carry no information: the slope collapses
    assert np.all((p > 0.3) & (p < 0.9))
    assert np.mean((p - yt) ** 2) < np.mean((raw - yt) ** 2) - 0.1


def test_cold_start_and_one_class_keep_the_base_behaviour():
    est = make_estimator("knn-cal", seed=0)
    assert est.predict(np.ones((1, 4))) == pytest.approx([0.5])  # prior before any outcome
    est.fit(np.eye(4, dtype=np.float32), np.ones(4, dtype=bool))
    assert (est.a, est.b) == (1.0, 0.0)  # no folds with one class: identity map
    assert est.predict(np.ones((1, 4))) == pytest.approx([5 / 6])  # the base's Laplace rate


def test_registry_names_grounding_and_errors():
    assert {"lgbm-cal", "grounded-lgbm-cal", "grounded-gp-cal"} <= set(CALIBRATED_ESTIMATORS)
    g = make_estimator("grounded-lgbm-cal", seed=3)
    assert isinstance(g, CalibratedEstimator) and is_grounded(g) and g.name == "grounded-lgbm-cal"
    assert not is_grounded(make_estimator("lgbm-cal"))
    with pytest.raises(UnknownNameError):
        make_estimator("eps-knn-cal")
    with pytest.raises(SconeError, match="bad option"):
        make_estimator("knn-cal", bogus=1.0)
    with pytest.raises(SconeError, match="2 folds"):
        CalibratedEstimator(lambda: make_estimator("knn"), folds=1)


def test_seeded_fits_repeat_exactly():
    rng = np.random.default_rng(2)
    X = rng.standard_normal((60, 6)).astype(np.float32)
    y = X[:, 0] + 0.5 * rng.standard_normal(60) > 0
    p1 = make_estimator("gp-cal", seed=1).fit(X, y).predict(X[:10])
    p2 = make_estimator("gp-cal", seed=1).fit(X, y).predict(X[:10])
    assert np.array_equal(p1, p2)


@pytest.mark.parametrize("name", ["gp", "grounded-gp"])
def test_out_of_fold_gps_keep_the_kernel_the_full_model_optimised(name):
    rng = np.random.default_rng(3)
    X = rng.standard_normal((40, 16)).astype(
        np.float32
    )  # grounded: 4 embedding dims, then the 12 of the context
    y = X[:, 0] + 0.3 * rng.standard_normal(40) > 0
    cal = make_estimator(f"{name}-cal", seed=0).fit(X, y)
    full = cal.base.base if name.startswith("grounded-") else cal.base
    fold = make_estimator(name, seed=0)
    fold.share_hyperparameters(cal.base)
    fold.fit(X[:20], y[:20])  # half the rows: alone, it would optimise a kernel of its own
    inner = fold.base if name.startswith("grounded-") else fold
    assert str(inner._model.kernel_) == str(full._kernel)
    alone = make_estimator(name, seed=0).fit(X[:20], y[:20])
    assert str((alone.base if name.startswith("grounded-") else alone)._model.kernel_) != str(full._kernel)
