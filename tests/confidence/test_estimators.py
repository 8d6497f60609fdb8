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


@pytest.mark.parametrize("bad", ["catboost", "grounded-nosuch", "nosuch-cal"])
def test_an_unknown_estimator_lists_exactly_the_names_that_are_accepted(bad: str) -> None:
    from scone_bt.confidence.registry import estimator_names

    with pytest.raises(UnknownNameError) as info:
        make_estimator(bad)
    assert tuple(info.value.valid) == estimator_names()
    assert {"xgboost", "knn-cal", "grounded-knn", "physical", "eps-knn"} <= set(estimator_names())
    for name in estimator_names():
        make_estimator(name)  # every listed name builds


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


def test_random_forest_trees_are_those_of_the_stock_forest():
    from sklearn.ensemble import RandomForestClassifier

    rng = np.random.default_rng(4)
    X = rng.standard_normal((60, 300)).astype(np.float32)  # wide and noisy: every tree differs from the next
    y = rng.random(60) < 0.6
    Xt = rng.standard_normal((25, 300)).astype(np.float32)
    stock = RandomForestClassifier(n_estimators=50, random_state=3, n_jobs=1).fit(X, y)
    est = make_estimator("rf", seed=3).fit(X, y)
    np.testing.assert_allclose(est.predict(Xt), stock.predict_proba(Xt)[:, 1], atol=1e-12)
    assert len({float(p) for p in est.predict(Xt)}) > 5


def test_epsilon_belief_is_the_base_probability_and_decide_adds_exploration():
    X, y = _profile(120, seed=9)
    eps = make_estimator("eps-lgbm", seed=3, epsilon=0.6, half_life=1e6).fit(X[:80], y[:80])
    plain = make_estimator("lgbm", seed=3).fit(X[:80], y[:80])
    np.testing.assert_allclose(eps.belief(X[80:]), plain.predict(X[80:]))
    explore = eps.explores(X[80:])
    assert explore.any() and not explore.all()
    np.testing.assert_array_equal(eps.decide(X[80:], 0.5), (plain.predict(X[80:]) >= 0.5) | explore)
    np.testing.assert_array_equal(eps.predict(X[80:]) == 1.0, explore | (plain.predict(X[80:]) == 1.0))
    np.testing.assert_array_equal(plain.decide(X[80:], 0.5), plain.belief(X[80:]) >= 0.5)


def test_gp_generalises_by_embedding_distance():
    rng = np.random.default_rng(0)
    good, bad = rng.standard_normal(16), rng.standard_normal(16)
    X = np.vstack([good + 0.1 * rng.standard_normal((10, 16)), bad + 0.1 * rng.standard_normal((10, 16))])
    y = np.array([True] * 10 + [False] * 10)
    gp = make_estimator("gp", seed=0).fit(X, y)
    p = gp.predict(np.vstack([good, bad]))
    assert p[0] > 0.7 and p[1] < 0.3
    assert make_estimator("gp").predict(X[:2]) == pytest.approx([0.5, 0.5])  # cold start: the prior


def test_grounded_estimator_prepares_context_from_its_training_rows_only():
    from scone_bt.confidence import CONTEXT_FIELDS, ExecutionContext, grounded_features
    from scone_bt.experience.types import FELT_FIELDS

    ctx = ExecutionContext(shelf_tier=1, clearance_m=0.02, detected=False)
    v = ctx.vector()
    assert len(v) == len(CONTEXT_FIELDS) == 12 and v[0] == 1.0 and v[3] == 0.0 and np.isnan(v[4])
    emb = np.eye(4)[[0, 0, 1, 1, 2, 2, 3, 3]]
    clearance = [0.01, 0.06, 0.01, 0.06, 0.01, 0.06, 0.01, 0.06]
    contexts = [ExecutionContext(clearance_m=c, detected=True, detected_width_m=None) for c in clearance]
    F = grounded_features(emb, contexts)
    assert F.shape == (8, 4 + len(CONTEXT_FIELDS))
    y = np.array(clearance) > 0.03  # the object says nothing; the clearance decides
    est = make_estimator("grounded-knn", seed=0, k=1).fit(F, y)
    assert est.name == "grounded-knn"
    Z = est.transform(F)
    # the perceived columns only: what a probe felt is the physical κ̂'s (FELT_FIELDS)
    assert Z.shape == (8, 4 + 2 * (len(CONTEXT_FIELDS) - len(FELT_FIELDS)))
    assert np.isfinite(Z).all()  # imputed
    assert est.predict(F).tolist() == y.astype(float).tolist()
    plain = make_estimator("knn", seed=0, k=1).fit(emb, y)
    assert (plain.predict(emb) == y).mean() < 1.0  # without context it cannot tell them apart
    with pytest.raises(SconeError, match="6 contexts|contexts"):
        grounded_features(emb, contexts[:3])
    with pytest.raises(SconeError, match="grounded_features"):
        make_estimator("grounded-knn").fit(np.ones((3, 4)), np.array([True, False, True]))
    with pytest.raises(UnknownNameError, match="grounded-knn"):
        make_estimator("grounded-conformal")
