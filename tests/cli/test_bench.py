"""scone-bench: every registered module adds its subcommands; the light benchmarks run and print JSON."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from scone_bt.cli.bench import BENCHMARK_MODULES, _parser, main

ROOT = Path(__file__).resolve().parents[2]


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
    assert (
        main(["viz", "--ticks", "4", "--frame-every", "2", "--headless-runs", "0", "--json", str(out)]) == 0
    )
    printed = json.loads(capsys.readouterr().out)
    assert printed == json.loads(out.read_text())
    assert printed["ticks"] == 4
    assert printed["rerun_recorder"]["tick_ms_mean"] > 0
    assert printed["headless_run"] is None and printed["headless_run_meets_target"] is None


def test_viz_benchmark_times_the_headless_run_without_and_with_its_recording(capsys) -> None:
    """`make run`'s episode in two fresh processes, one recording: the recording costs something, and is there."""
    assert main(["viz", "--ticks", "2", "--headless-runs", "1"]) == 0
    run = json.loads(capsys.readouterr().out)["headless_run"]
    assert run["runs"] == 1 and run["command"].startswith("scone-run --robot sim --headless --seed 0")
    for side in ("without_save", "with_save"):
        assert run[side]["wall_s"] > 0 and run[side]["cpu_s"] > 0
    assert run["with_save"]["cpu_s"] > run["without_save"]["cpu_s"]  # importing rerun alone takes 0.3 s
    assert run["rrd_mb"] > 0.1  # the episode's recording was written


def test_a_bug_in_a_benchmark_is_one_line_not_a_traceback(monkeypatch, capsys) -> None:
    def broken(args: object) -> int:
        raise ZeroDivisionError("division by zero")

    monkeypatch.delenv("SCONE_BT_DEBUG", raising=False)
    monkeypatch.setattr("scone_bt.cli.bench._parser", _parser_with({"func": broken}))
    assert main(["viz", "--ticks", "1"]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert err.startswith("scone-bench viz: ZeroDivisionError: division by zero (a program error")


def _parser_with(overrides: dict[str, object]):
    """`_parser`, with the parsed arguments' defaults replaced (e.g. a benchmark's func)."""

    def make():
        parser = _parser()
        parser.set_defaults(**overrides)
        for action in parser._actions:
            for child in getattr(action, "choices", None) or {}:
                action.choices[child].set_defaults(**overrides)
        return parser

    return make


@pytest.mark.slow
def test_ctrl_c_in_sc_generate_is_one_line_and_keeps_the_finished_executions(tmp_path) -> None:
    """A real Ctrl-C (SIGINT to the whole process group, workers included) once an execution is recorded."""
    import csv
    import os
    import signal
    import subprocess
    import sys
    import time
    from pathlib import Path

    bench = Path(sys.executable).parent / "scone-bench"
    out = tmp_path / "sc"
    argv = [str(bench), "sc", "generate", "--profiles", "p00_nominal", "--executions", "400"]
    argv += ["--workers", "2", "--out", str(out), "--no-progress", "--json", str(tmp_path / "r.json")]
    proc = subprocess.Popen(
        argv,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
        # As from a shell: a test worker (pytest-xdist) may ignore SIGINT, and an ignored signal stays ignored
        # across exec.
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    partial = out / ".p00_nominal.partial.csv"
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and proc.poll() is None:
        if partial.exists() and len(partial.read_text().splitlines()) >= 2:  # a header and one execution
            break
        time.sleep(0.1)
    assert proc.poll() is None, "the generation ended before it was interrupted"
    os.killpg(proc.pid, signal.SIGINT)
    stdout, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err[-2000:]
    assert "Traceback" not in err and stdout == "", err[-2000:]
    assert err.strip() == (
        f"scone-bench sc generate: interrupted; no report was printed and --json {tmp_path / 'r.json'} was not "
        f"written; the executions finished so far are kept in {out}, and the same command resumes them"
    )
    with partial.open() as f:
        rows = list(csv.DictReader(f))
    assert rows and all(r["object"] for r in rows)
    assert not (tmp_path / "r.json").exists()


def test_save_demo_never_overwrites_another_kind_of_file(tmp_path, capsys) -> None:
    victim = tmp_path / "p00_nominal.csv"
    victim.write_text("index,action\n0,Put salt on table\n")
    assert main(["viz", "--ticks", "2", "--save-demo", str(victim)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--save-demo" in err and "is not a rerun recording" in err, err
    assert victim.read_text() == "index,action\n0,Put salt on table\n"
    assert (
        main(["viz", "--ticks", "2", "--save-demo", str(tmp_path), "--json", str(tmp_path / "v.json")]) == 2
    )
    assert "is a folder" in capsys.readouterr().err and not (tmp_path / "v.json").exists()


@pytest.mark.parametrize("command", [["core"], ["viz", "--ticks", "1"]])
@pytest.mark.parametrize("report", ["/proc/x/a.json", "/sys/a.json", "/sys/kernel/missing/a.json"])
def test_a_report_that_cannot_be_written_is_refused_before_the_benchmark(
    command, report, tmp_path, monkeypatch, capsys
):
    def never(args: object) -> int:
        raise AssertionError("the benchmark ran")

    monkeypatch.setattr("scone_bt.cli.bench._parser", _parser_with({"func": never}))
    path = report.format(tmp=tmp_path)
    assert main([*command, "--json", path]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith(f"scone-bench: --json {path}:")


def test_a_missing_report_folder_is_made_before_the_benchmark_runs(tmp_path, monkeypatch) -> None:
    report = tmp_path / "missing" / "deeper" / "a.json"

    def benchmark(args: object) -> int:
        assert report.parent.is_dir()  # made before the work: the report is never lost to it
        return 0

    monkeypatch.setattr("scone_bt.cli.bench._parser", _parser_with({"func": benchmark}))
    assert main(["core", "--json", str(report)]) == 0


def test_a_report_is_never_written_over_a_file_of_an_input_folder(tmp_path, monkeypatch, capsys):
    folder = tmp_path / "scd"
    folder.mkdir()
    scenario = folder / "q.yaml"
    scenario.write_text("name: q\n")

    def never(args: object) -> int:
        raise AssertionError("the benchmark ran")

    monkeypatch.setattr("scone_bt.cli.bench._parser", _parser_with({"func": never}))
    assert main(["scenarios", str(folder), "--json", str(scenario), "--force"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "is the --paths input of this run" in err
    assert scenario.read_text() == "name: q\n"


@pytest.mark.parametrize(
    ("argv", "flag"),
    [
        (["viz", "--seed", "-1"], "--seed -1"),
        (["viz", "--headless-runs", "-1"], "--headless-runs -1"),
        (["tablet-load", "--seed", "-1"], "--seed -1"),
        (["perception", "--seed", "-1"], "--seed -1"),
        (["episode", "--seed", "-1"], "--seed -1"),
        (["motion", "--seed", "-1"], "--seed -1"),
        (["physics", "--seed", "-1"], "--seed -1"),
        (["gate", "--seed", "-1"], "--seed -1"),
        (["decisions", "--seed", "-1"], "--seed -1"),
        (["study-analysis", "--seed", "-1"], "--seed -1"),
        (["if-states", "--seed", "-1"], "--seed -1"),
        (["gate", "--distractors", "-1"], "--distractors -1"),
        (["decisions", "--warmup", "-1"], "--warmup -1"),
        (["physics", "--jobs", "0"], "--jobs 0"),
        (["scale", "--overhead-tasks", "-1"], "--overhead-tasks -1"),  # reported a negative overhead
        (["motion", "--queries", "0"], "--queries 0"),  # one line named four flags
        (["physics", "--clutter", "-1"], "--clutter -1"),
        (["scale", "--executions", "0"], "--executions 0"),
        (["soak", "--cache-dir", "/proc/x"], "--cache-dir /proc/x"),  # ran and wrote no cache
        (["sc", "probe", "--cache-dir", "/proc/x"], "--cache-dir /proc/x"),
    ],
)
def test_out_of_range_shared_options_are_one_line_before_the_benchmark(argv, flag, monkeypatch, capsys):
    def never(args: object) -> int:
        raise AssertionError("the benchmark ran")

    monkeypatch.setattr("scone_bt.cli.bench._parser", _parser_with({"func": never}))
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith(f"scone-bench: {flag}:")


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["trust", "--l2", "-1", "--write"], "--l2 -1.0: must be a number in [0, 1e+06]"),
        (["trust", "--l2", "nan"], "--l2 nan: must be a number"),
        (["trust-calibration", "--participants", "0"], "--participants 0: must be an integer in 1..10000"),
        (["trust-calibration", "--steps", "-2"], "--steps -2: must be an integer in 1..1000"),
    ],
)
def test_the_trust_benchmarks_refuse_a_fit_they_cannot_make_before_fitting(argv, message, capsys) -> None:
    from scone_bt.trust.transfer import FITTED_PARAMETERS

    shipped = FITTED_PARAMETERS.read_bytes()
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"scone-bench: {message}") and err.count("\n") == 1
    assert FITTED_PARAMETERS.read_bytes() == shipped  # --write wrote nothing


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["gate", "--arm", "foo", "--episodes", "1"], "--arm foo: unknown robot; valid: iiwa7, panda"),
        (["gate", "--no-replay"], "--no-replay with --episodes 0 and no --unseen: nothing to run"),
        (["gate", "--opening", "-1"], "--opening -1.0: must be in (0, 1) metres"),  # named an internal key
        (["gate", "--episodes", "-1"], "--episodes -1: must be 0 or more"),
        (
            ["sc", "evaluate", "--data", "tools/data/sc", "--epsilon", "2"],
            "--epsilon 2.0: must be a number in [0, 1]",
        ),
        (
            ["sc", "evaluate", "--data", "tools/data/sc", "--cache-dir", "/proc/x"],
            "--cache-dir /proc/x: cannot write",
        ),
        (
            ["sc", "evaluate", "--data", "tools/data/sc", "--refit-every", "0"],
            "--refit-every 0: must be an integer",
        ),
    ],
)
def test_settings_are_checked_before_the_datasets_are_read(argv, message, monkeypatch, capsys) -> None:
    """Each was found seconds to minutes in (after the replay, the embedding or the first cell)."""
    from scone_bt.benchmarks import gate
    from scone_bt.benchmarks.self_confidence import evaluate

    def never(*args: object, **kwargs: object) -> None:
        raise AssertionError("the datasets were read")

    monkeypatch.setattr(gate, "load_streams", never)
    monkeypatch.setattr(evaluate, "load_eval_datasets", never)
    monkeypatch.chdir(ROOT)
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"scone-bench: {message}") and err.count("\n") == 1


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["viz", "--ticks", "0"], "--ticks 0: must be an integer in 1..100000"),
        (["viz", "--frame-every", "-1"], "--frame-every -1: must be an integer in 1..100000"),
        (["viz", "--tick-seconds", "0"], "--tick-seconds 0.0: must be a number in [0.001, 10]"),
        (["study-recovery", "--seeds", "0"], "--seeds 0: must be an integer in 1..10000"),
        (["study-recovery", "--effect", "nan"], "--effect nan: must be a number in [-10, 10]"),
        (
            ["catalogue", "--pdr-heldout", "/nonexistent.jsonl"],
            "--pdr-heldout /nonexistent.jsonl: file not found",
        ),
        (["catalogue", "--pdr-labels", "/"], "--pdr-labels /: "),
        (["motion", "--arms", ""], "--arms '': a comma list with no empty item"),  # ran with no arm, rc 0
        (["physics", "--arms", "panda,"], "--arms 'panda,': a comma list with no empty item"),
        (["episode", "--recipes", "example:hummus,,"], "--recipes 'example:hummus,,': a comma list"),
    ],
)
def test_bad_settings_crashed_and_are_now_one_line_before_any_work(
    argv, message, monkeypatch, capsys
) -> None:
    """Each was an IndexError, ZeroDivisionError or FileNotFoundError (a program error) before."""
    from scone_bt.benchmarks import catalogue, viz
    from scone_bt.recipes import recipe

    def never(*args: object, **kwargs: object) -> None:
        raise AssertionError("the work started")

    monkeypatch.setattr(viz, "main", never)
    monkeypatch.setattr(recipe, "corpus_entries", never)
    monkeypatch.setattr(catalogue, "_normalisation", never)
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"scone-bench: {message}") and err.count("\n") == 1, err


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["decisions", "--estimator", "nosuch"], "--estimator 'nosuch': unknown estimator; valid: knn, lgbm"),
        (["decisions", "--estimators", "knn,nosuch"], "--estimators 'nosuch': unknown estimator; valid:"),
        (
            ["decisions", "--relevance-threshold", "5"],
            "--relevance-threshold 5.0: must be a number in [-1, 1]",
        ),
    ],
)
def test_decisions_checks_its_names_before_the_replay(argv, message, monkeypatch, capsys) -> None:
    from scone_bt.benchmarks import decisions

    def never(*args: object, **kwargs: object) -> None:
        raise AssertionError("the replay ran")

    monkeypatch.setattr(decisions, "_gate_metrics", never)
    monkeypatch.setattr(decisions, "_episodes", never)
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"scone-bench: {message}") and err.count("\n") == 1, err


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["perception", "--arm", "nosuch"], "--arm nosuch: unknown robot; valid: iiwa7, panda"),
        (["perception", "--kitchen", "nosuch"], "--kitchen nosuch: unknown kitchen; valid: kitchen"),
        (["motion", "--arms", "panda,nosuch"], "--arms nosuch: unknown robot; valid: iiwa7, panda"),
    ],
)
def test_a_robot_or_kitchen_name_is_checked_with_its_flag_before_any_benchmark(argv, message, capsys) -> None:
    """The line named neither the flag nor, for --arms, which item."""
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err == f"scone-bench: {message}\n", err
