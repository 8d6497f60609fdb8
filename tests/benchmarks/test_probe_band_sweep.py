"""tools/probe_band_sweep.py: a configuration that names only some of the probe's settings keeps the probe on."""

from __future__ import annotations

import pytest


@pytest.fixture(scope="module")
def sweep(tool):
    return tool("probe_band_sweep")


def test_only_an_explicit_null_below_turns_the_probe_off(sweep):
    from scone_bt.gate.probe import ProbeOptions

    probe, allowance, power = sweep.configuration({"sure_traction": 0.05})
    assert probe == ProbeOptions(sure_traction=0.05) and allowance == 1.0 and power == 4.0
    assert sweep.configuration({"below": None, "allowance": None}) == (None, None, 4.0)
    probe, _, power = sweep.configuration({"below": 0.5, "power": 2})
    assert probe == ProbeOptions(below=0.5) and power == 2.0


def test_oracle_replays_the_true_attributes_view(sweep, monkeypatch, capsys, whole_held_fast_record):
    """--oracle reproduces the committed oracle line (docs/results/probe_oracle.jsonl at α = 0.15: κ̂ given the true
    mass, size and glass, no embedder involved), and only the oracle's lines say so."""
    import json
    import sys
    from pathlib import Path

    import scone_bt.benchmarks.gate as bench_gate
    from scone_bt.gate.budget import BudgetOptions

    def replay_args_1_3(*a, **k):  # the committed line was measured at the start of its day, 1 − 3α
        args = real_replay_args(*a, **k)
        args.budget = BudgetOptions(start_margin=3.0)
        return args

    real_replay_args = bench_gate.replay_args
    monkeypatch.setattr(bench_gate, "replay_args", replay_args_1_3)
    lines = {}
    for flags in ([], ["--oracle"]):
        # the band of the committed line's day (τ + 0.3; the tree's default since is τ + 0.45)
        argv = ["probe_band_sweep", "--configs", '[{"above": 0.3}]', "--alphas", "0.15", *flags]
        monkeypatch.setattr(sys, "argv", argv)
        sweep.main()
        lines[bool(flags)] = json.loads(capsys.readouterr().out)
    assert lines[True]["oracle"] is True and "oracle" not in lines[False]
    committed = Path(__file__).resolve().parents[2] / "docs" / "results" / "probe_oracle.jsonl"
    recorded = next(
        line for line in map(json.loads, committed.read_text().splitlines()) if line["alpha"] == 0.15
    )
    keys = ("attempt_failure_rate", "help_rate", "aborted_rate", "by_feel_attempts", "max_excess_failures")
    assert {k: lines[True][k] for k in keys} == {k: recorded[k] for k in keys}
