"""The ungrounded ceiling (true product attributes) and the calibrated pair in the report's target checks."""

from __future__ import annotations

import numpy as np
import pytest

from scone_bt.benchmarks.self_confidence.evaldata import EvalDataset
from scone_bt.benchmarks.self_confidence.evaluate import ORACLE_EMBEDDER, oracle_features
from scone_bt.benchmarks.self_confidence.report import target_checks
from scone_bt.config import load_kitchen
from scone_bt.errors import ConfigError


def _data(objects: list[str]) -> EvalDataset:
    n = len(objects)
    return EvalDataset(
        "d",
        tuple(f"Put {o} on table" for o in objects),
        tuple(objects),
        ("x",) * n,
        np.ones(n, dtype=bool),
        np.full((n, 6), np.nan),
    )


def test_oracle_rows_are_the_products_true_attributes():
    specs = load_kitchen("kitchen").catalogue.objects
    a, b = specs[0].name, next(o.name for o in specs if o.family != specs[0].family)
    (X,) = oracle_features([_data([a, b, a])])
    assert np.array_equal(X[0], X[2]) and not np.array_equal(X[0], X[1])
    assert X.shape[1] > 4 and np.isfinite(X).all()
    with pytest.raises(ConfigError, match="not in the kitchen catalogue"):
        oracle_features([_data([a, "no such product"])])


def _row(emb: str, est: str, auc: float, ece: float) -> dict:
    return {
        "embedder": emb,
        "estimator": est,
        "auc": {"mean": auc, "std": 0.0},
        "ece": ece,
        "n_test": 220,
        "ece_noise_floor": {"mean": 0.055, "p95": 0.08},
    }


def test_targets_check_the_calibrated_best_pair_and_ignore_the_oracle():
    report = {
        "embedders": ["onehot", ORACLE_EMBEDDER],
        "protocols": {
            "algorithm1": [
                _row("onehot", "grounded-lgbm", 0.87, 0.097),
                _row("onehot", "grounded-lgbm-cal", 0.86, 0.045),
                _row(ORACLE_EMBEDDER, "grounded-lgbm", 0.95, 0.01),
                _row(ORACLE_EMBEDDER, "knn", 0.74, 0.2),
            ]
        },
    }
    checks = {c["target"]: c for c in target_checks(report)}
    ece = checks["ECE ≤ 0.05 at n_train = 80 for the best pair (Algorithm 1)"]
    assert ece["measured"].startswith("onehot + grounded-lgbm ECE 0.097") and not ece["met"]
    assert "noise floor" in ece["measured"]
    cal = checks["ECE ≤ 0.05 at n_train = 80, the best pair calibrated (Algorithm 1)"]
    assert cal["met"] and "grounded-lgbm-cal ECE 0.045" in cal["measured"]
