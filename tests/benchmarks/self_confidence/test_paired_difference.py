"""Paired per-dataset differences between pairs, and the target checks that quote them."""

from __future__ import annotations

import numpy as np
import pytest

from scone_bt.benchmarks.self_confidence.report import paired_difference, target_checks


def _entry(emb: str, est: str, per_dataset: list[float]) -> dict:
    mean = sum(per_dataset) / len(per_dataset)
    auc = {"mean": mean, "std": 0.0, "per_dataset": per_dataset}
    return {"embedder": emb, "estimator": est, "auc": auc, "ece": 0.1, "n_test": 20}


def test_a_consistent_difference_has_an_interval_away_from_zero():
    a = _entry("mpnet", "knn", [0.80, 0.75, 0.90, 0.70, 0.85, 0.78])
    b = _entry("onehot", "knn", [0.60, 0.55, 0.70, 0.52, 0.66, 0.58])
    p = paired_difference(a, b)
    assert p is not None and p["datasets"] == 6 and p["wins"] == 6 and p["ties"] == 0
    assert p["mean"] == pytest.approx(0.195)
    assert 0.0 < p["ci_low"] <= p["mean"] <= p["ci_high"] < 0.3
    assert paired_difference(a, b) == p  # seeded


def test_a_difference_of_mixed_sign_spans_zero_and_a_swap_flips_it():
    a = _entry("mpnet", "lgbm", [0.70, 0.60, 0.80, 0.50, 0.65])
    b = _entry("glove", "lgbm", [0.60, 0.70, 0.70, 0.60, 0.66])
    p, q = paired_difference(a, b), paired_difference(b, a)
    assert p["ci_low"] < 0 < p["ci_high"] and p["wins"] == 2
    assert q["mean"] == pytest.approx(-p["mean"]) and q["wins"] == 3


def test_older_reports_without_per_dataset_values_give_none():
    old = {"auc": {"mean": 0.7, "std": 0.1}}
    assert paired_difference(old, _entry("x", "y", [0.5])) is None
    assert paired_difference(None, None) is None
    assert paired_difference(_entry("a", "k", [0.5, 0.6]), _entry("b", "k", [0.5])) is None


def test_the_gap_and_order_targets_quote_the_paired_interval():
    rows = [
        _entry("onehot", "knn", [0.60, 0.62, 0.58]),
        _entry("glove", "knn", [0.66, 0.65, 0.67]),
        _entry("mpnet", "knn", [0.75, 0.72, 0.78]),
        _entry("onehot", "lgbm", [0.60, 0.62, 0.58]),
        _entry("glove", "lgbm", [0.66, 0.65, 0.67]),
        _entry("mpnet", "lgbm", [0.62, 0.64, 0.60]),
    ]
    report = {"embedders": ["onehot", "glove", "mpnet"], "protocols": {"algorithm1": rows}}
    checks = {c["target"]: c for c in target_checks(report)}
    gap = checks["Algorithm 1: best semantic ≥ one-hot + 0.08 with the same estimator"]
    assert gap["met"] and "paired gap +0.150" in gap["measured"] and "higher on 3" in gap["measured"]
    order = checks["Algorithm 1 order semantic > GloVe > one-hot (lgbm)"]
    assert not order["met"] and "semantic − GloVe -0.040" in order["measured"]
    assert "GloVe − one-hot +0.060" in order["measured"]


def test_shuffles_of_one_dataset_count_once():
    # per_dataset holds each dataset's mean over its shuffles; pairing follows dataset_index, not list position
    a = {"auc": {"mean": 0.7, "per_dataset": [0.7, 0.8, 0.6], "dataset_index": [0, 1, 2]}}
    b = {"auc": {"mean": 0.6, "per_dataset": [0.5, 0.7, 0.6], "dataset_index": [2, 0, 1]}}
    p = paired_difference(a, b)
    assert p["datasets"] == 3 and p["mean"] == pytest.approx((0.0 + 0.2 + 0.1) / 3)
    other = {"auc": {"mean": 0.6, "per_dataset": [0.5, 0.7], "dataset_index": [0, 1]}}
    assert paired_difference(a, other) is None


def _hand_resampled(d: list[float], resamples: int = 10_000, seed: int = 0) -> tuple[float, float]:
    """The interval the report computed before scipy: datasets drawn with replacement, 2.5 / 97.5 percentiles."""
    x = np.array(d)
    rng = np.random.default_rng(seed)
    means = x[rng.integers(0, len(x), size=(resamples, len(x)))].mean(axis=1)
    lo, hi = np.percentile(means, [2.5, 97.5])
    return float(lo), float(hi)


@pytest.mark.parametrize("n", [2, 5, 17, 40])
def test_scipy_bootstrap_draws_the_same_resamples_as_before(n):
    # scipy.stats.bootstrap with the same seeded Generator draws the same datasets: the printed intervals stay.
    rng = np.random.default_rng(n)
    a, b = rng.random(n).tolist(), rng.random(n).tolist()
    p = paired_difference(_entry("a", "k", a), _entry("b", "k", b))
    lo, hi = _hand_resampled([x - y for x, y in zip(a, b, strict=True)])
    assert p["ci_low"] == pytest.approx(lo, abs=1e-12) and p["ci_high"] == pytest.approx(hi, abs=1e-12)
    if n >= 17:  # with few datasets every seed gives the same percentiles
        assert paired_difference(_entry("a", "k", a), _entry("b", "k", b), seed=1) != p  # the seed is used


def test_one_dataset_is_its_own_interval_and_nan_datasets_are_left_out():
    p = paired_difference(_entry("a", "k", [0.7, float("nan")]), _entry("b", "k", [0.5, 0.4]))
    assert p["datasets"] == 1 and p["ci_low"] == p["ci_high"] == pytest.approx(0.2)
