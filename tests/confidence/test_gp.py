"""GPEstimator: kernel hyper-parameters re-optimised as the outcomes grow by `reoptimise_growth`, kept in between."""

from __future__ import annotations

import numpy as np
import pytest

from scone_bt.confidence.base import _one_thread
from scone_bt.confidence.gp import GPEstimator
from scone_bt.errors import SconeError


def _data(n: int, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    X = rng.normal(size=(n, 8)).astype(np.float32)
    y = X[:, 0] + 0.3 * rng.normal(size=n) > 0
    return X, y


def test_updates_between_reoptimisations_keep_the_optimised_kernel() -> None:
    X, y = _data(40)
    gp = GPEstimator(reoptimise_growth=0.25).fit(X[:20], y[:20])
    kernel = gp._kernel
    for i in range(20, 24):  # 4 updates: still within 25 % (5 outcomes) of the last optimisation
        gp.update(X[i], bool(y[i]))
        assert gp._kernel is kernel and gp._model.kernel_ == kernel  # type: ignore[attr-defined]
    gp.update(X[24], bool(y[24]))  # the 5th: optimised afresh
    assert gp._kernel is not kernel and gp._n_optimised == 25


def test_kept_kernel_predicts_as_a_fit_with_that_kernel_fixed() -> None:
    from sklearn.gaussian_process import GaussianProcessClassifier

    X, y = _data(30)
    gp = GPEstimator(reoptimise_growth=0.4).fit(X[:25], y[:25])
    for i in range(25, 30):
        gp.update(X[i], bool(y[i]))
    norm = X / np.linalg.norm(X, axis=1, keepdims=True)
    ref = GaussianProcessClassifier(gp._kernel, optimizer=None).fit(norm.astype(np.float64), y.astype(int))
    np.testing.assert_allclose(
        gp.predict(X[:5]), ref.predict_proba(norm[:5].astype(np.float64))[:, 1], atol=1e-9
    )


def test_a_young_gp_optimises_on_every_update_and_batch_fits_always_do() -> None:
    X, y = _data(30)
    gp = GPEstimator().fit(X[:9], y[:9])  # default growth 0.1: below 10 outcomes every one re-optimises
    gp.update(X[9], bool(y[9]))
    assert gp._n_optimised == 10
    gp.update(X[10], bool(y[10]))
    assert gp._n_optimised == 11
    lazy = GPEstimator(reoptimise_growth=10.0).fit(X[:20], y[:20])
    lazy.fit(X[:10], y[:10])  # fewer rows than it was optimised on: a new data set, optimised again
    assert lazy._n_optimised == 10


def test_reoptimise_growth_out_of_range_is_a_one_line_error() -> None:
    with pytest.raises(SconeError, match="reoptimise_growth must be between 0 and 10"):
        GPEstimator(reoptimise_growth=-0.1)


def test_one_thread_also_pins_blas_pools_loaded_after_the_first_call() -> None:
    from threadpoolctl import threadpool_info

    with _one_thread():
        pass
    import scipy.linalg  # noqa: F401  (scipy's own OpenBLAS, possibly loaded only now)

    with _one_thread():
        assert all(pool["num_threads"] == 1 for pool in threadpool_info())
