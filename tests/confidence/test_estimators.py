"""κ̂: every estimator learns a separable toy profile online; cold start, one class, ε-greedy, conformal."""

from __future__ import annotations

import numpy as np
import pytest

from scone_bt.confidence import (
    BASE_ESTIMATORS,
    ESTIMATORS,
    EpsilonGreedy,
    make_estimator,
    rebuild_estimator,
)
from scone_bt.embedding import OneHotEmbedder
from scone_bt.errors import SconeError, UnknownNameError
from scone_bt.experience import ExperienceStore, Outcome

DIM = 32


def _profile(n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """A robot that succeeds on one family of actions (near centre A) and fails on another (near centre B)."""
    rng = np.random.default_rng(seed)
    centres = np.random.default_rng(100).standard_normal((2, DIM))
    y = np.arange(n) % 2 == 0
    X = centres[np.where(y, 0, 1)] + 0.5 * rng.standard_normal((n, DIM))
    return (X / np.linalg.norm(X, axis=1, keepdims=True)).astype(np.float32), y


@pytest.mark.parametrize("name", BASE_ESTIMATORS)
def test_learns_a_separable_profile_online(name):
    est = make_estimator(name, seed=0)
    X, y = _profile(40, seed=1)
    for x, label in zip(X, y, strict=True):
        est.update(x, bool(label))
    assert est.n_observations == 40
    Xt, yt = _profile(30, seed=2)
    p = est.predict(Xt)
    assert p.shape == (30,) and np.all((p >= 0) & (p <= 1))
    if name == "conformal":  # confidence = 1 - p-value of failure: successes certified, failures not
        assert p[yt].min() >= 0.9 and p[~yt].mean() < 0.6
    else:
        assert np.mean((p > 0.5) == yt) >= 0.9
        assert p[yt].mean() - p[~yt].mean() > 0.5


@pytest.mark.parametrize("name", [n for n in BASE_ESTIMATORS if n != "conformal"])
def test_cold_start_and_one_class(name):
    est = make_estimator(name, seed=0)
    X, _ = _profile(4, seed=3)
    assert est.predict(X) == pytest.approx([0.5] * 4)  # the prior
    est.update(X[0], False)
    est.update(X[1], False)
    assert est.predict(X) == pytest.approx([1 / 4] * 4)  # Laplace (0 + 1) / (2 + 2)
    est.update(X[2], True)  # both classes now: a real model
    assert est.n_observations == 3 and est.n_successes == 1
    assert np.all(np.isfinite(est.predict(X)))


def test_fit_replaces_data_and_prediction_memo_is_invalidated():
    est = make_estimator("knn", seed=0, k=1)
    X, y = _profile(10, seed=4)
    est.fit(X, y)
    first = est.predict(X[:2])
    assert first == pytest.approx([1.0, 0.0])
    est.fit(X, ~y)
    assert est.predict(X[:2]) == pytest.approx([0.0, 1.0])
    with pytest.raises(SconeError, match="embedding has 5 values"):
        est.update(np.ones(5), True)


def test_epsilon_greedy_explores_then_decays_and_is_stable_between_updates():
    est = make_estimator("eps-knn", seed=7, epsilon=0.5, half_life=10)
    assert isinstance(est, EpsilonGreedy) and est.name == "eps-knn"
    X, y = _profile(400, seed=5)
    failures = X[~y][:200]
    for x in failures[:20]:
        est.update(x, False)  # every early outcome failed: plain knn now predicts failure everywhere
    assert est.epsilon == pytest.approx(0.5 * 2 ** (-20 / 10))
    p = est.predict(failures)
    explored = p == 1.0
    assert est.base.predict(failures) == pytest.approx([1 / 22] * 200)  # one class: Laplace rate
    assert 0.03 < explored.mean() < 0.30  # ≈ ε = 0.125
    np.testing.assert_array_equal(est.predict(failures), p)  # same draw until the next outcome
    for x in failures[20:120]:
        est.update(x, False)
    assert est.epsilon < 0.001
    assert (est.predict(failures) == 1.0).mean() < 0.02
    assert est.n_observations == 120


def test_epsilon_draws_are_seeded():
    X, _ = _profile(200, seed=6)
    a = make_estimator("eps-rf", seed=1).predict(X)
    b = make_estimator("eps-rf", seed=1).predict(X)
    c = make_estimator("eps-rf", seed=2).predict(X)
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, c)
    assert set(np.unique(a)) == {0.5, 1.0}


def test_conformal_error_rate_holds_on_overlapping_data():
    rng = np.random.default_rng(0)
    centres = rng.standard_normal((2, 8))
    alpha, errors = 0.2, []
    for trial in range(20):
        y = rng.random(240) < 0.6
        X = centres[np.where(y, 0, 1)] + 2.0 * rng.standard_normal((240, 8))
        est = make_estimator("conformal", seed=trial).fit(X[:40], y[:40])
        act = est.predict(X[40:]) >= 1 - alpha
        errors.append(np.mean(act & ~y[40:]))
    assert np.mean(errors) <= alpha  # acted-and-failed on at most alpha of decisions


def test_conformal_cold_start_certifies_nothing():
    est = make_estimator("conformal")
    X, y = _profile(4, seed=8)
    assert est.predict(X) == pytest.approx([0.0] * 4)
    est.update(X[0], True)
    assert est.predict(X).max() <= 0.5  # one outcome: smallest p-value is 1/2


def test_registry_names_and_errors():
    assert set(ESTIMATORS) == {*BASE_ESTIMATORS, *(f"eps-{n}" for n in BASE_ESTIMATORS)}
    assert {"knn", "lgbm", "rf", "svm", "mlp", "xgb"} <= set(BASE_ESTIMATORS)
    with pytest.raises(UnknownNameError, match="eps-knn"):
        make_estimator("catboost")
    with pytest.raises(SconeError, match="eps-knn"):
        make_estimator("knn", epsilon=0.2)
    with pytest.raises(SconeError, match="bad option"):
        make_estimator("rf", k=3)


def test_rebuild_from_the_experience_store(tmp_path):
    emb = OneHotEmbedder()
    with ExperienceStore(tmp_path / "e.sqlite") as store:
        for i in range(6):
            store.append(Outcome(float(i), f"Put o{i % 2} on table", f"o{i % 2}", "onehot", i % 2 == 0))
        store.append(Outcome(9.0, "Put o1 on table", "o1", "glove", True))
        est = make_estimator("knn", k=1)
        assert rebuild_estimator(est, store, emb, only_embedder="onehot") == 6
        p = est.predict(emb.embed(["Put o0 on table", "Put o1 on table"]))
        assert p == pytest.approx([1.0, 0.0])
        assert rebuild_estimator(est, store, emb) == 7


def test_random_forest_fast_path_matches_predict_proba():
    X, y = _profile(40, seed=9)
    est = make_estimator("rf", seed=0).fit(X, y)
    Xt, _ = _profile(21, seed=10)
    np.testing.assert_allclose(est.predict(Xt), est._model.predict_proba(Xt)[:, 1], atol=1e-12)
