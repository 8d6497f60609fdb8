"""load_eval_datasets hands a grounded κ̂ the context the robot had when it decided (test_one_context.py: as
recorded); a file without context columns leaves it missing."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np

from scone_bt.benchmarks.self_confidence.dataset import load_datasets
from scone_bt.benchmarks.self_confidence.evaldata import decision_time_context


def test_files_without_context_stay_missing(sc_data: Callable[..., Path]) -> None:
    (data,) = load_datasets(sc_data(n_datasets=1, rows=20, context=False))
    assert np.isnan(decision_time_context(data)).all()
