"""Metrics agree with scikit-learn and with known values; calibration bins add up."""

from __future__ import annotations

import numpy as np
import pytest
from sklearn.metrics import accuracy_score, brier_score_loss, roc_auc_score

from scone_bt.benchmarks.self_confidence.metrics import (
    accuracy,
    auroc,
    brier_score,
    expected_calibration_error,
    normalised_auc,
    reliability_bins,
)


def test_metrics_match_sklearn_on_random_predictions():
    rng = np.random.default_rng(0)
    p = rng.random(200)
    y = rng.random(200) < p  # roughly calibrated
    assert accuracy(p, y) == pytest.approx(accuracy_score(y, p >= 0.5))
    assert auroc(p, y) == pytest.approx(roc_auc_score(y, p))
    assert brier_score(p, y) == pytest.approx(brier_score_loss(y, p))


def test_known_values_and_degenerate_inputs():
    y = np.array([1, 1, 0, 0], dtype=bool)
    assert auroc(np.array([0.9, 0.8, 0.2, 0.1]), y) == 1.0
    assert auroc(np.array([0.1, 0.2, 0.8, 0.9]), y) == 0.0
    assert auroc(np.full(4, 0.5), y) == 0.5
    assert np.isnan(auroc(np.array([0.3, 0.4]), np.array([True, True])))
    assert brier_score(np.full(4, 0.5), y) == 0.25
    assert np.isnan(accuracy(np.zeros(0), np.zeros(0, dtype=bool)))
    assert expected_calibration_error(np.array([1.0, 1.0, 0.0, 0.0]), y) == 0.0
    assert expected_calibration_error(np.full(4, 0.8), y) == pytest.approx(0.3)  # |0.5 - 0.8|
    assert normalised_auc([10, 20, 30], [0.0, 0.5, 1.0]) == pytest.approx(0.5)
    assert normalised_auc([80], [0.7]) == pytest.approx(0.7)


def test_reliability_bins_cover_every_prediction_and_give_the_ece():
    rng = np.random.default_rng(1)
    p = rng.random(500)
    y = rng.random(500) < p**2  # over-confident
    bins = reliability_bins(p, y, 10)
    assert len(bins) == 10 and sum(b.count for b in bins) == 500
    assert bins[0].lower == 0.0 and bins[-1].upper == 1.0
    ece = sum(b.count * abs(b.observed_rate - b.mean_predicted) for b in bins if b.count) / 500
    assert expected_calibration_error(p, y, 10) == pytest.approx(ece)
    assert ece > 0.1  # the miscalibration is seen


def test_ece_noise_floor_is_the_ece_of_a_calibrated_predictor():
    from scone_bt.benchmarks.self_confidence.metrics import ece_noise_floor

    p = np.random.default_rng(3).random(220)
    mean, p95 = ece_noise_floor(p, 10, simulations=2000, seed=0)
    rng = np.random.default_rng(9)
    direct = [expected_calibration_error(p, rng.random(len(p)) < p, 10) for _ in range(2000)]
    assert mean == pytest.approx(np.mean(direct), abs=0.003)
    assert p95 > mean
    assert 0.055 < mean < 0.08  # 0.05 is below what sampling alone gives on 220 rows
    assert ece_noise_floor(np.random.default_rng(3).random(5000), 10)[0] < 0.02
    assert np.isnan(ece_noise_floor(np.zeros(0))[0])
