"""Output paths of the scenario runners are checked before any case runs: ``scone-bench scenarios --out/--json``,
pytest's ``--scenario-out``; and ``--junit`` never replaces a YAML file, even with --force."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from scone_bt.checks import check_not_yaml
from scone_bt.cli.bench import main as bench_main
from scone_bt.errors import SconeError
from scone_bt.scenario import runner
from scone_bt.scenario.cli import main as scenario_main
from tests.scenario.test_cli_outputs import _no_case_runs, _one_line

pytest_plugins = ["pytester"]

FAILS = "description: A case that fails.\nworld: {max_ticks: 20}\nexpect:\n  - {completes: true}\n"


def _scenario(folder: Path, name: str = "a.yaml") -> Path:
    path = folder / name
    path.write_text(FAILS, encoding="utf-8")
    return path


def _blocked(tmp_path: Path) -> Path:
    """A path that can never be written: its parent is a file."""
    afile = tmp_path / "afile"
    afile.write_text("", encoding="utf-8")
    return afile / "x"


@pytest.fixture
def no_case_runs(monkeypatch: pytest.MonkeyPatch) -> None:
    _no_case_runs(monkeypatch)


def test_bench_scenarios_checks_out_before_any_case_runs(
    tmp_path: Path, no_case_runs: None, capsys: pytest.CaptureFixture[str]
) -> None:
    case, blocked = _scenario(tmp_path), _blocked(tmp_path)
    # was: the cases ran, then NotADirectoryError (rc 1)
    assert bench_main(["scenarios", str(case), "--out", str(blocked)]) == 2
    assert _one_line(capsys) == f"scone-bench: --out {blocked}: {blocked.parent} is a file, not a folder\n"


def test_bench_scenarios_checks_json_before_any_case_runs(
    tmp_path: Path, no_case_runs: None, capsys: pytest.CaptureFixture[str]
) -> None:
    case, other = _scenario(tmp_path), _scenario(tmp_path, "other.yaml")
    assert bench_main(["scenarios", str(case), "--json", str(other), "--force"]) == 2
    assert f"--json {other}: is a YAML file" in _one_line(capsys)
    assert other.read_text(encoding="utf-8") == FAILS
    recipe = tmp_path / "soup.json"
    recipe.write_text('{"steps": ["Boil."], "ingredients": ["water"]}', encoding="utf-8")
    assert bench_main(["scenarios", str(case), "--json", str(recipe)]) == 2
    assert "is not a benchmark report" in _one_line(capsys)


def test_pytest_scenario_out_is_a_one_line_usage_error_before_any_case_runs(
    tmp_path: Path, pytester: pytest.Pytester, no_case_runs: None, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(runner, "run_one", lambda *a, **k: pytest.fail("a case ran"))
    case, blocked = _scenario(pytester.path), _blocked(tmp_path)
    result = pytester.runpytest(str(case), "-p", "no:cacheprovider", "--scenario-out", str(blocked))
    assert result.ret == pytest.ExitCode.USAGE_ERROR  # was: the case ran, then a traceback (a failed test)
    err = [line for line in result.errlines if line.strip()]
    assert err == [f"ERROR: --scenario-out {blocked}: {blocked.parent} is a file, not a folder"], err
    assert "Traceback" not in result.stdout.str()


@pytest.mark.parametrize("name", ["other.yaml", "other.YML"])
def test_junit_never_replaces_a_yaml_file_even_with_force(
    tmp_path: Path, no_case_runs: None, capsys: pytest.CaptureFixture[str], name: str
) -> None:
    case, other = _scenario(tmp_path), _scenario(tmp_path, name)
    for extra in ([], ["--force"]):  # was: with --force the scenario file became JUnit XML
        assert scenario_main(["run", str(case), "--junit", str(other), *extra]) == 2
        err = _one_line(capsys)
        assert (
            err.startswith(f"scone-scenario: --junit {other}: is a YAML file") and "even with --force" in err
        )
        assert "(e.g. other.xml)" in err
    assert other.read_text(encoding="utf-8") == FAILS
    link = tmp_path / "report.xml"  # a link to a YAML file: where it leads counts
    link.symlink_to(other)
    assert scenario_main(["run", str(case), "--junit", str(link), "--force"]) == 2
    assert "is a YAML file" in _one_line(capsys) and other.read_text(encoding="utf-8") == FAILS


def test_check_not_yaml_lets_empty_new_and_own_files_through(tmp_path: Path) -> None:
    empty, new = tmp_path / "empty.yaml", tmp_path / "new.yaml"
    empty.touch()
    assert check_not_yaml(empty, "--junit", "a JUnit report", ".xml") == empty
    assert check_not_yaml(new, "--junit", "a JUnit report", ".xml") == new
    ours = tmp_path / "old.yml"
    ours.write_text("<testsuites/>\n", encoding="utf-8")
    assert check_not_yaml(ours, "--junit", "a JUnit report", ".xml", ours=lambda p: True) == ours
    with pytest.raises(SconeError, match=r"^--junit .*old.yml: is a YAML file .*\(e\.g\. old\.xml\)$"):
        check_not_yaml(ours, "--junit", "a JUnit report", ".xml")
    notes = tmp_path / "notes.txt"
    notes.write_text("x", encoding="utf-8")
    assert check_not_yaml(notes, "--junit", "a JUnit report", ".xml") == notes
    assert sorted(os.listdir(tmp_path)) == ["empty.yaml", "notes.txt", "old.yml"]  # nothing made or removed
