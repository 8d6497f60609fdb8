"""load_eval_datasets hands a grounded κ̂ the context the robot has when it decides (no detected-flag leak)."""

from __future__ import annotations

import csv
from collections.abc import Callable
from pathlib import Path

import numpy as np

from scone_bt.benchmarks.self_confidence.dataset import load_datasets
from scone_bt.benchmarks.self_confidence.evaldata import decision_time_context, load_eval_datasets
from scone_bt.confidence.grounded import CONTEXT_FIELDS

D, W, H = (CONTEXT_FIELDS.index(c) for c in ("detected", "detected_width_m", "detected_height_m"))


def test_undetected_rows_look_detected_with_the_products_own_size(sc_data: Callable[..., Path]) -> None:
    folder = sc_data(n_datasets=1, rows=60)
    rows = list(csv.DictReader(next(folder.glob("*.csv")).open()))
    undetected = np.array([r["detected"] == "0" for r in rows])
    assert undetected.any() and (~undetected).any()
    (data,) = load_eval_datasets(folder)
    assert np.all(data.context[:, D] == 1.0)  # the flag carries nothing
    assert not np.isnan(data.context[:, [W, H]]).any()  # no missing-size pattern either
    np.testing.assert_allclose(
        data.context[undetected, W], [float(r["width_m"]) for r in rows if r["detected"] == "0"]
    )
    detected_w = [float(r["detected_width_m"]) for r in rows if r["detected"] == "1"]
    np.testing.assert_allclose(data.context[~undetected, W], detected_w)  # measured sizes are kept


def test_files_without_context_stay_missing(sc_data: Callable[..., Path]) -> None:
    (data,) = load_datasets(sc_data(n_datasets=1, rows=20, context=False))
    assert np.isnan(decision_time_context(data)).all()
