import numpy as np
import pytest

from scone_bt.confidence.logistic import fit_logistic


def _data(seed, n, d, separable=False):
    rng = np.random.default_rng(seed)
    X = rng.normal(size=(n, d))
    w = rng.normal(size=d)
    z = X @ w + 0.3
    y = (z > 0) if separable else (rng.random(n) < 1 / (1 + np.exp(-z)))
    return X, y.astype(int)


@pytest.mark.parametrize(
    ("seed", "n", "d", "separable"),
    [(0, 40, 24, False), (1, 300, 24, False), (2, 12, 24, True), (3, 5, 3, True)],
)
def test_same_model_as_scikit_learn(seed, n, d, separable):
    from sklearn.linear_model import LogisticRegression

    X, y = _data(seed, n, d, separable)
    ours = fit_logistic(X, y, C=1.0)
    # scikit-learn at a tight tolerance reaches the same unique minimum.
    theirs = LogisticRegression(C=1.0, tol=1e-12, max_iter=10_000).fit(X, y)
    assert np.abs(ours.coef - theirs.coef_[0]).max() < 1e-5
    assert abs(ours.intercept - theirs.intercept_[0]) < 1e-5
    Xq = np.random.default_rng(seed + 10).normal(size=(50, d))
    assert np.abs(ours.predict_proba(Xq) - theirs.predict_proba(Xq)[:, 1]).max() < 1e-6
    # And at its default tolerance (what the estimator used before) to about 1e-4.
    default = LogisticRegression(C=1.0, max_iter=300).fit(X, y)
    assert np.abs(ours.predict_proba(Xq) - default.predict_proba(Xq)[:, 1]).max() < 2e-3


def test_gradient_is_zero_at_the_fit():
    X, y = _data(4, 60, 8)
    m = fit_logistic(X, y, C=0.5)
    p = m.predict_proba(X)
    assert np.abs(0.5 * X.T @ (p - y) + m.coef).max() < 1e-8
    assert abs((p - y).sum()) < 1e-8  # the unpenalised intercept balances the residuals


def test_probabilities_do_not_overflow():
    X, y = _data(5, 30, 2, separable=True)
    m = fit_logistic(X * 1e3, y, C=1e6)
    p = m.predict_proba(np.array([[1e6, 1e6], [-1e6, -1e6]]))
    assert np.all(np.isfinite(p)) and np.all((p >= 0) & (p <= 1))


@pytest.mark.parametrize(
    ("X", "y", "C", "message"),
    [
        (np.zeros((3, 2)), [1, 1, 1], 1.0, "both classes"),
        (np.zeros((3, 2)), [0, 1], 1.0, "must match"),
        (np.zeros((2, 2)), [0, 1], 0.0, "C must be positive"),
    ],
)
def test_bad_input_is_one_clear_error(X, y, C, message):
    with pytest.raises(ValueError, match=message):
        fit_logistic(X, y, C=C)
