"""Reports are strict JSON: a value that is not a finite number is written as null."""

from __future__ import annotations

import json

import numpy as np
import pytest

from scone_bt.strict_json import clean_json, dumps


def test_non_finite_floats_become_null_and_numpy_scalars_plain():
    report = {"r_hat": float("nan"), "x": [np.float64(np.inf), -np.inf], "n": np.int64(3), "t": (1.5, np.nan)}
    assert clean_json(report) == {"r_hat": None, "x": [None, None], "n": 3, "t": [1.5, None]}
    text = dumps(report)
    assert "NaN" not in text and "Infinity" not in text
    assert json.loads(text, parse_constant=pytest.fail) == {
        "r_hat": None,
        "x": [None, None],
        "n": 3,
        "t": [1.5, None],
    }


def test_benchmark_reports_are_strict(capsys, tmp_path):
    from scone_bt.reporting import emit_report

    emit_report({"ece": float("nan")}, tmp_path / "r.json")
    assert json.loads(capsys.readouterr().out) == {"ece": None}
    assert (tmp_path / "r.json").read_text() == '{\n  "ece": null\n}\n'
