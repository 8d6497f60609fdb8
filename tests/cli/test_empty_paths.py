"""An empty path option is refused in one line by every command: Path('') is '.', the working folder, where an
empty --out or --cache-dir used to write its files (and an empty --experience crashed)."""

from __future__ import annotations

import pytest

from scone_bt.cli.bench import main as bench_main
from scone_bt.cli.models import main as models_main
from scone_bt.cli.run import main as run_main
from scone_bt.scenario.cli import main as scenario_main
from scone_bt.study.cli import main as study_main

CASES = [
    (models_main, ["--cache-dir", "", "install", "mpnet"], "--cache-dir"),
    (study_main, ["analyze", "--ratings", "r.csv", "--out", ""], "--out"),
    (run_main, ["--robot", "sim", "--experience", ""], "--experience"),
    (run_main, ["--robot", "sim", "--save", " "], "--save"),
    (scenario_main, ["run", "scenarios", "--out", ""], "--out"),
    (bench_main, ["episode", "--json", ""], "--json"),
    (bench_main, ["if-states", "--out", ""], "--out"),  # wrote its files into the working folder
    (bench_main, ["gate", "--datasets", ""], "--datasets"),  # replayed the default streams instead
]


@pytest.mark.parametrize(("main", "argv", "flag"), CASES, ids=[f"{a[0]}-{f}" for _, a, f in CASES])
def test_an_empty_path_is_one_line_and_writes_nothing(main, argv, flag, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as done:
        main(argv)
    err = capsys.readouterr().err.strip()
    assert done.value.code == 2 and err.count("\n") == 0, err
    assert f"argument {flag}" in err and "an empty" in err, err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    "command", [["motion"], ["physics"], ["catalogue"], ["scenarios"], ["if", "--states", "s"]]
)
def test_an_empty_json_option_is_refused_not_skipped(command, tmp_path, monkeypatch, capsys):
    """A --json "" was falsy: the benchmark ran and wrote no report, without a word."""
    monkeypatch.chdir(tmp_path)
    assert bench_main([*command, "--json", ""]) == 2
    err = capsys.readouterr().err
    assert err == "scone-bench: --json: an empty path; give a file path, or leave the option out\n", err
