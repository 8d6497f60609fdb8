"""One scenario runner: `scone-scenario run` and `pytest scenarios/` select, run and judge cases through
`scone_bt.scenario.runner`, and give a case the same verdict."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from scone_bt.errors import SconeError
from scone_bt.scenario import runner
from scone_bt.scenario.cli import main
from scone_bt.scenario.run import CaseResult

pytest_plugins = ["pytester"]

TINY = "description: A short run.\nworld: {max_ticks: 20}\nexpect:\n  - {completes: false}\n"
VERDICTS = ("passed", "xfail", "failed", "xpass", "error")


def _library(folder: Path) -> Path:
    """A scenario folder with one file per verdict, named after it; `fast` tags the first two."""
    folder.mkdir(parents=True, exist_ok=True)
    for k, verdict in enumerate(VERDICTS):
        tags = "tags: [fast]\n" if k < 2 else "tags: [slow]\n"
        (folder / f"{verdict}.yaml").write_text(TINY + tags, encoding="utf-8")
    return folder


def _judged_by_name(monkeypatch: pytest.MonkeyPatch, ran: list[str]) -> None:
    """Each case runs to the verdict its file is named after (no episode)."""

    def run_one(case: Any, out_dir: Any, record_failures: bool = True, force: bool = False) -> CaseResult:
        ran.append(case.name)
        return CaseResult(case.name, str(case.path), case.name, f"because {case.name}")

    monkeypatch.setattr(runner, "run_one", run_one)


def test_selection_by_name_and_tags_refuses_an_empty_result(tmp_path: Path) -> None:
    cases = runner.load_cases([_library(tmp_path / "lib")], None)
    names = [c.name for c in cases]
    assert sorted(names) == sorted(VERDICTS)
    assert [c.name for c in runner.Selection(name="pass").apply(cases)] == ["passed", "xpass"]
    assert {c.name for c in runner.Selection(tags=("fast",)).apply(cases)} == {"passed", "xfail"}
    assert {c.name for c in runner.Selection(skip_tags=("fast",)).apply(cases)} == {
        "failed",
        "xpass",
        "error",
    }
    with pytest.raises(SconeError, match=r"^-k 'nothing': no case name contains it$"):
        runner.Selection(name="nothing").apply(cases)
    with pytest.raises(
        SconeError, match=r"^no case left after --tag/--skip-tag; the cases' tags: fast, slow$"
    ):
        runner.Selection(tags=("fast",), skip_tags=("fast",)).apply(cases)
    with pytest.raises(SconeError, match=r"^--jobs 0: give 1 or more$"):
        runner.check_jobs(0)


def test_tally_counts_each_verdict_and_what_fails() -> None:
    results = [CaseResult(v, "f.yaml", v, "") for v in (*VERDICTS, "passed")]
    tally = runner.Tally.of(results)
    assert (tally.passed, tally.xfail, tally.failed, tally.xpass, tally.error) == (2, 1, 1, 1, 1)
    assert tally.not_ok == 3 and tally.total == 6
    assert tally.line(1.25) == (
        "6 cases: 2 passed, 1 failed as expected, 1 failed, 1 passed unexpectedly, 1 errors in 1.2 s wall"
    )


def test_the_cli_and_the_pytest_plugin_give_each_case_the_same_verdict(
    tmp_path: Path,
    pytester: pytest.Pytester,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    ran: list[str] = []
    _judged_by_name(monkeypatch, ran)
    folder = _library(pytester.path / "scenarios")
    assert main(["run", str(folder), "--quiet", "--out", str(tmp_path / "out")]) == 1
    out = capsys.readouterr().out
    assert "5 cases: 1 passed, 1 failed as expected, 1 failed, 1 passed unexpectedly, 1 errors" in out
    assert sorted(ran) == sorted(VERDICTS)

    ran.clear()
    result = pytester.inline_run(
        str(folder), "-p", "no:cacheprovider", "--scenario-out", str(tmp_path / "out")
    )
    assert sorted(ran) == sorted(VERDICTS)
    outcome = {
        r.nodeid.split("::")[-1]: r for r in result.getreports("pytest_runtest_logreport") if r.when == "call"
    }
    assert outcome["passed"].passed
    assert outcome["xfail"].skipped and outcome["xfail"].wasxfail == "because xfail"
    for name in ("failed", "xpass", "error"):  # each fails, with the runner's report as its message
        assert outcome[name].failed and f"{name} ({folder / name}.yaml): {name}: because {name}" in str(
            outcome[name].longrepr
        )

    # the same selection by tag: `-t fast` on the command line, `-m fast` under pytest
    ran.clear()
    assert main(["run", str(folder), "--quiet", "-t", "fast", "--out", str(tmp_path / "out")]) == 0
    cli_ran = sorted(ran)
    ran.clear()
    pytester.inline_run(str(folder), "-p", "no:cacheprovider", "-m", "fast", "--scenario-out", str(tmp_path))
    assert sorted(ran) == cli_ran == ["passed", "xfail"]


def test_the_pytest_plugin_collects_scenarios_in_a_folder_named_on_the_command_line(
    tmp_path: Path, pytester: pytest.Pytester, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``pytest runs/demo/`` (the tutorial's folder is not called scenarios/): its scenario files are collected; a
    tree file and another project's YAML (several documents, a custom tag) beside them are not, even in a test
    folder; a scenario that does not parse is reported (one line), not skipped."""
    ran: list[str] = []
    _judged_by_name(monkeypatch, ran)
    demo = pytester.path / "runs" / "demo"
    demo.mkdir(parents=True)
    (demo / "passed.yaml").write_text(TINY, encoding="utf-8")
    (demo / "a-tree.yaml").write_text("root: {sequence: []}\n", encoding="utf-8")
    (demo / "k8s.yaml").write_text("a: 1\n---\nexpect: 2\n", encoding="utf-8")
    (demo / "cfn.yaml").write_text("description: x\nexpect: !Ref y\n", encoding="utf-8")
    result = pytester.inline_run(str(demo), "-p", "no:cacheprovider", "--scenario-out", str(tmp_path))
    assert len(result.getfailedcollections()) == 1  # cfn.yaml reads as a scenario: its error is reported
    (demo / "cfn.yaml").unlink()
    ran.clear()
    result = pytester.inline_run(str(demo), "-p", "no:cacheprovider", "--scenario-out", str(tmp_path))
    assert ran == ["passed"]
    result.assertoutcome(passed=1)

    (demo / "broken.yaml").write_text("description: d\nexpect: [\n", encoding="utf-8")
    ran.clear()
    result = pytester.inline_run(str(demo), "-p", "no:cacheprovider", "--scenario-out", str(tmp_path))
    assert len(result.getfailedcollections()) == 1  # pytest stops before running anything
    assert "broken.yaml: line 3 is not valid YAML" in str(result.getfailedcollections()[0].longrepr)

    # named itself, a file is collected wherever it lies; pytest's root, a long -k and no argument collect nothing
    # outside scenarios/
    ran.clear()
    pytester.inline_run(str(demo / "passed.yaml"), "-p", "no:cacheprovider", "--scenario-out", str(tmp_path))
    assert ran == ["passed"]
    ran.clear()
    pytester.inline_run(str(pytester.path), "-p", "no:cacheprovider", "--scenario-out", str(tmp_path))
    pytester.inline_run("-k", "x" * 300, "-p", "no:cacheprovider", "--scenario-out", str(tmp_path))
    assert ran == []
