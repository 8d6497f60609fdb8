"""The outputs of ``scone-scenario``: --junit and the schema FILE are checked before anything runs and never
replace a scenario (or any other) file; a killed worker process loses only the cases it had not finished."""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from dataclasses import replace
from pathlib import Path
from typing import Any

import pytest

from scone_bt.scenario import cli, model, run, runner
from scone_bt.scenario.cli import main

TINY = "description: A short run that does not finish the recipe.\nworld: {max_ticks: 20}\nexpect:\n  - {completes: false}\n"


def _scenario(tmp_path: Path, name: str = "a.yaml") -> Path:
    path = tmp_path / name
    path.write_text(TINY, encoding="utf-8")
    return path


def _no_case_runs(monkeypatch: pytest.MonkeyPatch) -> None:
    def refuse(*args: Any, **kwargs: Any) -> None:
        raise AssertionError("a case ran although an output path is bad")

    monkeypatch.setattr(runner, "run_cases", refuse)


def _one_line(capsys: pytest.CaptureFixture[str]) -> str:
    err = capsys.readouterr().err
    assert "Traceback" not in err and err.count("\n") == 1, err
    return err


def test_junit_that_is_the_scenario_file_is_refused_even_with_force(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    path = _scenario(tmp_path)
    _no_case_runs(monkeypatch)
    for extra in ([], ["--force"]):
        assert main(["run", str(path), "--junit", str(path), *extra]) == 2
        assert _one_line(capsys).startswith(
            f"scone-scenario: --junit {path}: is the scenario input of this run"
        )
    # the folder named instead of the file: its scenario files are inputs all the same
    assert main(["run", str(tmp_path), "--junit", str(path), "--force"]) == 2
    assert "is the scenario input of this run" in _one_line(capsys)
    assert path.read_text(encoding="utf-8") == TINY


def test_junit_folder_device_and_other_files_are_refused_before_any_case_runs(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    path = _scenario(tmp_path)
    _no_case_runs(monkeypatch)
    folder = tmp_path / "somedir"
    folder.mkdir()
    assert main(["run", str(path), "--junit", str(folder)]) == 2
    assert "is a folder" in _one_line(capsys)
    assert main(["run", str(path), "--junit", os.devnull]) == 2
    assert "not a file" in _one_line(capsys)
    notes = tmp_path / "notes.xml"
    notes.write_text("<robot name='arm'/>\n", encoding="utf-8")  # XML, but not a JUnit report
    assert main(["run", str(path), "--junit", str(notes)]) == 2
    err = _one_line(capsys)
    assert "is not a JUnit XML report" in err and "--force" in err
    assert notes.read_text(encoding="utf-8") == "<robot name='arm'/>\n"
    blocker = tmp_path / "file"
    blocker.write_text("x", encoding="utf-8")
    assert main(["run", str(path), "--junit", str(blocker / "j.xml")]) == 2
    assert "is a file, not a folder" in _one_line(capsys)


def test_junit_report_is_replaced_and_force_replaces_another_file(tmp_path: Path) -> None:
    report = tmp_path / "old.xml"
    report.write_text("<?xml version='1.0'?>\n<!-- ci -->\n<testsuites><testsuite name='x'/></testsuites>\n")
    assert cli.is_junit_report(report)
    assert cli.check_junit(report, [], force=False) == report
    other = tmp_path / "notes.txt"
    other.write_text("keep me\n")
    assert not cli.is_junit_report(other)
    assert cli.check_junit(other, [], force=True) == other
    empty = tmp_path / "empty.xml"
    empty.touch()
    assert cli.is_junit_report(empty)


def test_schema_never_replaces_a_scenario_file_and_asks_force_for_other_files(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = _scenario(tmp_path)
    for extra in ([], ["--force"]):
        assert main(["schema", str(path), *extra]) == 2
        err = _one_line(capsys)
        assert err.startswith(f"scone-scenario: schema {path}: is a YAML file") and "never replaces it" in err
    assert path.read_text(encoding="utf-8") == TINY
    notes = tmp_path / "notes.txt"
    notes.write_text("keep me\n", encoding="utf-8")
    assert main(["schema", str(notes)]) == 2
    assert "is not a JSON file" in _one_line(capsys) and notes.read_text(encoding="utf-8") == "keep me\n"
    assert main(["schema", str(tmp_path)]) == 2
    assert "is a folder" in _one_line(capsys)
    # a schema file is rewritten (also one named .yaml), another file only with --force
    schema = tmp_path / "scenario.schema.json"
    assert main(["schema", str(schema)]) == 0 and main(["schema", str(schema)]) == 0
    assert '"$schema"' in schema.read_text(encoding="utf-8")
    as_yaml = tmp_path / "scenario.schema.yaml"
    as_yaml.write_text(schema.read_text(encoding="utf-8"), encoding="utf-8")
    assert main(["schema", str(as_yaml)]) == 0
    assert main(["schema", str(notes), "--force"]) == 0 and '"$schema"' in notes.read_text(encoding="utf-8")
    assert sorted(p.name for p in tmp_path.iterdir() if p.name.startswith(".")) == []  # no temporary left


# ------------------------------------------------------------------------------------------------ a killed worker
class _InWorker:
    """Runs `code` where it is unpickled: in the spawned worker process that takes the case, never here."""

    def __init__(self, code: str) -> None:
        self.code = code

    def __reduce__(self) -> tuple[Any, tuple[str]]:
        return exec, (self.code,)


def _kills_its_worker(flag: Path) -> _InWorker:
    # waits until the first case's result is in (so that one finished), then dies as under kill -9
    return _InWorker(
        "import os, signal, time\n"
        "end = time.monotonic() + 60\n"
        f"while not os.path.exists({str(flag)!r}) and time.monotonic() < end:\n"
        "    time.sleep(0.02)\n"
        "os.kill(os.getpid(), signal.SIGKILL)\n"
    )


@pytest.mark.slow
def test_a_killed_worker_keeps_the_finished_results_and_reports_the_lost_cases(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    path = _scenario(tmp_path)
    flag = tmp_path / "first-result-in"
    load, run_cases = model.load_scenarios, runner.run_cases

    def with_doomed_cases(paths: Any) -> list[model.Case]:
        (case,) = load(paths)
        killer = replace(case, name="killer", sweep=(("doom", _kills_its_worker(flag)),))
        # never finishes: lost with the pool when the killer dies (the pool stops every worker)
        stuck = replace(case, name="stuck", sweep=(("doom", _InWorker("import time; time.sleep(60)")),))
        return [case, killer, stuck]

    def touching_the_flag(*args: Any, on_result: Any = None, **kwargs: Any) -> list[run.CaseResult]:
        def seen(result: run.CaseResult) -> None:
            flag.touch()
            on_result(result)

        return run_cases(*args, on_result=seen, **kwargs)

    monkeypatch.setattr(model, "load_scenarios", with_doomed_cases)
    monkeypatch.setattr(runner, "run_cases", touching_the_flag)
    junit = tmp_path / "rep" / "j.xml"
    assert main(["run", str(path), "--jobs", "2", "--junit", str(junit), "--quiet"]) == 1
    out, err = capsys.readouterr()
    assert "Traceback" not in err
    assert err.splitlines() == [
        "scone-scenario: a worker process died (e.g. killed or out of memory); 2 cases did not run to the end: "
        "killer, stuck"
    ]
    assert "3 cases: 1 passed, 0 failed as expected, 0 failed, 0 passed unexpectedly, 2 errors" in out
    cases = {c.get("name"): c for c in ET.parse(junit).iter("testcase")}
    assert list(cases) == ["a", "killer", "stuck"]
    assert cases["a"].find("error") is None
    for name in ("killer", "stuck"):
        error = cases[name].find("error")
        assert error is not None and error.get("message") == runner.WORKER_DIED


@pytest.mark.slow
def test_ctrl_c_stops_the_workers_at_once_and_says_how_far_the_run_got(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    path = _scenario(tmp_path)
    marker = tmp_path / "a-slow-case-finished"
    go = tmp_path / "go"
    load, run_cases = model.load_scenarios, runner.run_cases

    def with_slow_cases(paths: Any) -> list[model.Case]:
        (case,) = load(paths)
        # Each waits for `go` (written only after the interrupt), then leaves the marker: a worker left running
        # would do so; one terminated cannot. Waiting on a file, not a sleep, keeps a loaded machine (a first case
        # slower than any fixed sleep) from finishing a slow case before the interrupt.
        slow = _InWorker(
            "import os, pathlib, time\n"
            "end = time.monotonic() + 60\n"
            f"while not os.path.exists({str(go)!r}) and time.monotonic() < end:\n"
            "    time.sleep(0.02)\n"
            f"pathlib.Path({str(marker)!r}).touch()\n"
        )
        return [case] + [replace(case, name=f"slow{k}", sweep=(("doom", slow),)) for k in range(3)]

    def interrupted_after_the_first(*args: Any, on_result: Any = None, **kwargs: Any) -> list[run.CaseResult]:
        def seen(result: run.CaseResult) -> None:
            on_result(result)
            raise KeyboardInterrupt  # as Ctrl-C lands in the parent while the slow cases run

        return run_cases(*args, on_result=seen, **kwargs)

    monkeypatch.setattr(model, "load_scenarios", with_slow_cases)
    monkeypatch.setattr(runner, "run_cases", interrupted_after_the_first)
    junit = tmp_path / "j.xml"
    assert main(["run", str(path), "--jobs", "2", "--junit", str(junit)]) == 130
    out, err = capsys.readouterr()
    assert "Traceback" not in err and out == ""
    assert err.splitlines()[-1] == (
        f"scone-scenario: interrupted after 1 of 4 cases (their lines are above); --junit {junit} was not written"
    )
    import time

    go.touch()
    time.sleep(2.0)  # time enough for a slow case to see `go` and finish, had its worker been left running
    assert not marker.exists() and not junit.exists()


def test_a_failed_case_reports_the_wall_time_of_its_own_run_not_of_the_recording(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A failing case runs again to save its recording; that second run is not the case's time."""
    path = tmp_path / "f.yaml"
    path.write_text(TINY.replace("{completes: false}", "{completes: true}"), encoding="utf-8")  # fails
    (case,) = model.load_scenarios([path])
    clock = [0.0]
    episode = run._episode

    def recording_takes_an_hour(case: Any, models: Any, rrd: Any, store: Any) -> Any:
        result = episode(case, models, rrd, store)
        clock[0] += 3600.0 if rrd is not None else 1.0
        return result

    monkeypatch.setattr(run, "_episode", recording_takes_an_hour)
    monkeypatch.setattr(run.time, "perf_counter", lambda: clock[0])
    result = run.run_case(case, tmp_path / "out")
    assert result.verdict == run.Verdict.FAILED and result.wall_s == 1.0
    assert (tmp_path / "out" / "f.rrd").exists()


@pytest.mark.parametrize("suffix", [".rrd", ".events.jsonl"])
def test_out_files_that_are_not_earlier_outputs_are_refused_before_any_case_runs(
    suffix: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    path = _scenario(tmp_path)
    out = tmp_path / "out"
    out.mkdir()
    notes = out / f"a{suffix}"  # where case "a" would write, a user's own file
    notes.write_text("my precious notes\n", encoding="utf-8")
    _no_case_runs(monkeypatch)
    assert main(["run", str(path), "--out", str(out)]) == 2
    err = _one_line(capsys)
    assert (
        f"--out {out}: {notes.name} exists and is not" in err and "case 'a' writes there if it fails" in err
    )
    assert "give another --out folder, or --force to replace it" in err, err
    assert notes.read_text(encoding="utf-8") == "my precious notes\n"
    # an earlier run's outputs are replaced without --force, a foreign file with it
    cases = runner.load_cases([path], None)
    runner.check_outputs(cases, out, force=True)
    notes.write_text('{"tick": 0}\n', encoding="utf-8") if suffix.endswith("jsonl") else notes.write_bytes(
        b""
    )
    runner.check_outputs(cases, out)


@pytest.mark.slow
def test_a_failing_case_keeps_a_foreign_file_unless_forced(tmp_path: Path) -> None:
    """A file made in --out after the check is kept and the report says so; with --force the case's log replaces
    it (--force let the run start but then wrote nothing)."""
    path = tmp_path / "a.yaml"
    path.write_text(TINY.replace("{completes: false}", "{completes: true}"), encoding="utf-8")  # fails
    (case,) = model.load_scenarios([path])
    out = tmp_path / "out"
    out.mkdir()
    log, rrd = run.case_outputs(case.name, out)
    assert (log.name, rrd.name) == ("a.events.jsonl", "a.rrd")
    log.write_text("not an event log\x00", encoding="utf-8")
    kept = run.run_case(case, out, record_failures=False)
    assert kept.verdict == run.Verdict.FAILED and kept.artifacts == () and kept.kept == (str(log),)
    assert f"not written: {log} exists and holds something else" in kept.report()
    assert log.read_text(encoding="utf-8") == "not an event log\x00"
    forced = run.run_case(case, out, record_failures=False, force=True)
    assert forced.artifacts == (str(log),) and forced.kept == ()
    assert log.read_text(encoding="utf-8").startswith('{"tick": ')


def test_an_unknown_arm_names_the_flag(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys) -> None:
    _no_case_runs(monkeypatch)
    assert main(["run", str(_scenario(tmp_path)), "--arm", "nosuch"]) == 2
    assert _one_line(capsys) == "scone-scenario: --arm nosuch: unknown robot; valid: iiwa7, panda\n"
