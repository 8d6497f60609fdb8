"""scone-bench: every registered module adds its subcommands; the light benchmarks run and print JSON."""

from __future__ import annotations

import json

import pytest

from scone_bt.cli.bench import BENCHMARK_MODULES, _parser, main


def test_every_registered_module_adds_a_subcommand() -> None:
    parser = _parser()
    sub = next(a for a in parser._actions if a.dest == "command")
    names = set(sub.choices)
    assert {"if", "if-states", "core", "viz"} <= names
    assert len(BENCHMARK_MODULES) == len(set(BENCHMARK_MODULES))


def test_unknown_subcommand_is_a_usage_error(capsys) -> None:
    with pytest.raises(SystemExit) as exc:
        main(["no-such-benchmark"])
    assert exc.value.code == 2
    assert "invalid choice" in capsys.readouterr().err


def test_viz_benchmark_prints_and_writes_json(tmp_path, capsys) -> None:
    out = tmp_path / "viz.json"
    assert main(["viz", "--ticks", "4", "--frame-every", "2", "--json", str(out)]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert printed == json.loads(out.read_text())
    assert printed["ticks"] == 4
    assert printed["rerun_recorder"]["tick_ms_mean"] > 0
