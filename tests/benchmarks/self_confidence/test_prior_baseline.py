"""The prior baseline: the training prefix's Laplace-smoothed success rate for every action."""

from __future__ import annotations

import numpy as np

from scone_bt.benchmarks.self_confidence.evaluate import _Prior
from scone_bt.confidence.base import ConfidenceEstimator


def test_prior_is_the_smoothed_rate_of_what_it_was_fitted_on():
    prior = _Prior()
    assert isinstance(prior, ConfidenceEstimator)
    X = np.zeros((4, 1))
    assert prior.fit(X, np.array([True, True, False, True])) is prior
    np.testing.assert_array_equal(prior.belief(np.zeros((3, 1))), np.full(3, 4.0 / 6.0))
    np.testing.assert_array_equal(prior.decide(np.zeros((2, 1)), 0.7), [False, False])


def test_prior_with_no_data_or_one_class():
    assert _Prior().fit(np.zeros((0, 1)), np.zeros(0, dtype=bool)).belief(np.zeros((1, 1)))[0] == 0.5
    assert _Prior().fit(np.zeros((2, 1)), np.ones(2, dtype=bool)).belief(np.zeros((1, 1)))[0] == 0.75
