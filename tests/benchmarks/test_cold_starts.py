"""Each stream rotated to a new start (replay_streams.rotated), and tools/cold_starts.py's first start is
`scone-bench gate`'s replay."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def cold(tool):
    return tool("cold_starts")


def test_a_rotated_stream_starts_at_its_row_and_keeps_every_row():
    from scone_bt.benchmarks.replay_streams import Streams, rotated

    n = 5
    streams = Streams(
        names=["s"],
        vectors=[np.arange(n * 2, dtype=float).reshape(n, 2)],
        context=[np.arange(n, dtype=float)[:, None]],
        success=[np.array([1, 0, 1, 1, 0], dtype=bool)],
        products=[tuple("abcde")],
        readings=[None],
        foreseen=[np.array(["", "missing", "", "", ""])],
    )
    r = rotated(streams, 2)
    assert r.products == [tuple("cdeab")]
    assert r.vectors[0][0].tolist() == [4.0, 5.0] and r.context[0][:, 0].tolist() == [2, 3, 4, 0, 1]
    assert r.success[0].tolist() == [True, True, False, True, False] and r.readings == [None]
    assert r.foreseen[0].tolist() == ["", "", "", "", "missing"]
    assert rotated(streams, 0).products == streams.products


def test_the_first_start_is_the_replay_of_scone_bench_gate(cold, monkeypatch, capsys):
    """--step 100 starts each 100-row stream once, at its first row: the committed replay (probe_slide.json,
    the shipped gate at α = 0.15 on the shipped arm's recording), stream by stream."""
    argv = ["cold_starts", "--datasets", str(ROOT / "tools/data/sc_slide"), "--step", "100"]
    monkeypatch.setattr(sys, "argv", argv)
    cold.main()
    (line,) = map(json.loads, capsys.readouterr().out.splitlines())
    committed = json.loads((ROOT / "docs/results/probe_slide.json").read_text())["default"]
    assert line["cold_starts"] == 11 and line["feel_allowance"] == 2.0
    assert line["help_rate_mean"] == pytest.approx(np.mean(committed["help_rate_per_stream"]), abs=1e-4)
    assert line["attempt_failure_rate"] == pytest.approx(committed["attempt_failure_rate"], abs=1e-4)
    assert line["asked_for_everything"] == len(line["which"]) == 0
