"""``scone-bench <name> --json FILE``: one rule for FILE before the benchmark runs and at the write. An earlier
report is replaced; any other existing file only with --force (which reaches the write); a YAML file never."""

from __future__ import annotations

import ast
import json
from pathlib import Path
from typing import Any

import pytest

import scone_bt.benchmarks.catalogue as catalogue
from scone_bt.checks import REPORT_KEYS, is_output_kind
from scone_bt.cli.bench import main
from scone_bt.errors import SconeError
from scone_bt.reporting import emit_report

REPO = Path(__file__).resolve().parents[2]
RECIPE = {"id": "mine", "title": "My soup", "ingredients": ["water"], "steps": ["Boil the water."]}


@pytest.fixture
def ran(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """The catalogue benchmark, faked (a report in no time): the list says whether it ran."""
    calls: list[str] = []

    def fake(**kwargs: Any) -> dict[str, Any]:
        calls.append("ran")
        return {"products": 1, "wall_s": 0.1}

    monkeypatch.setattr(catalogue, "run_catalogue_benchmark", fake)
    return calls


def _one_line(capsys: pytest.CaptureFixture[str]) -> str:
    err = capsys.readouterr().err
    assert "Traceback" not in err and err.count("\n") == 1, err
    return err


def test_force_reaches_the_write(tmp_path: Path, ran: list[str], capsys: pytest.CaptureFixture[str]) -> None:
    notes = tmp_path / "notes.txt"
    notes.write_text("my notes\n")
    assert main(["catalogue", "--quiet", "--json", str(notes)]) == 2
    assert "--force" in _one_line(capsys) and ran == [] and notes.read_text() == "my notes\n"
    # was: the benchmark ran, then the write refused the file, asking for the --force it had been given
    assert main(["catalogue", "--quiet", "--json", str(notes), "--force"]) == 0, capsys.readouterr().err
    assert ran == ["ran"] and json.loads(notes.read_text()) == {"products": 1, "wall_s": 0.1}


@pytest.mark.parametrize(
    "content",
    [json.dumps(RECIPE), json.dumps([RECIPE]), json.dumps({"steps": ["x"]}), '"text"', "[]"],
    ids=["recipe", "list", "steps", "string", "empty-list"],
)
def test_a_json_file_that_is_not_a_report_is_kept_and_the_benchmark_does_not_run(
    tmp_path: Path, ran: list[str], capsys: pytest.CaptureFixture[str], content: str
) -> None:
    recipe = tmp_path / "soup.json"
    recipe.write_text(content)
    assert main(["catalogue", "--quiet", "--json", str(recipe)]) == 2
    err = _one_line(capsys)
    assert f"--json {recipe}: exists and is not a benchmark report" in err and "--force" in err, err
    assert "benchmark" in err and "wall_s" in err  # the rule, stated
    assert ran == [] and recipe.read_text() == content


def test_an_earlier_report_is_replaced_without_force(tmp_path: Path, ran: list[str]) -> None:
    for i, old in enumerate([{"benchmark": "x", "n": 1}, {"products": 9, "wall_s": 3.0}]):
        report = tmp_path / f"r{i}.json"
        report.write_text(json.dumps(old))
        assert main(["catalogue", "--quiet", "--json", str(report)]) == 0
        assert json.loads(report.read_text())["products"] == 1
    empty = tmp_path / "empty.json"
    empty.touch()
    assert main(["catalogue", "--quiet", "--json", str(empty)]) == 0


@pytest.mark.parametrize("name", ["kitchen.yaml", "robot.yml"])
def test_a_yaml_file_is_never_replaced_by_a_report_even_with_force(
    tmp_path: Path, ran: list[str], capsys: pytest.CaptureFixture[str], name: str
) -> None:
    target = tmp_path / name
    target.write_text("description: x\n")
    assert main(["catalogue", "--quiet", "--json", str(target), "--force"]) == 2
    err = _one_line(capsys)
    assert f"--json {target}: is a YAML file" in err and "even with --force" in err, err
    assert ran == [] and target.read_text() == "description: x\n"


def test_every_report_in_docs_results_may_be_replaced() -> None:
    """The rule holds for the reports people re-run into docs/results (one key of REPORT_KEYS at the top)."""
    written_elsewhere = {
        "mujoco_episodes.json"
    }  # tools/engine_episodes.py's own file, not a scone-bench report
    reports = [
        p for p in sorted((REPO / "docs" / "results").glob("*.json")) if p.name not in written_elsewhere
    ]
    assert reports
    not_reports = [p.name for p in reports if not is_output_kind(p, "report")]
    assert not_reports == [], f"give these a key of {REPORT_KEYS}: {not_reports}"
    assert not is_output_kind(REPO / "scenarios" / "scenario.schema.json", "report")


def test_emit_report_makes_its_folder_only_where_it_can(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    afile = tmp_path / "afile"
    afile.touch()
    with pytest.raises(SconeError, match=r"--json .*afile/x/r.json: .*afile is a file, not a folder"):
        emit_report({"wall_s": 1}, afile / "x" / "r.json", make_parent=True)  # was: NotADirectoryError
    emit_report({"wall_s": 1}, tmp_path / "a" / "r.json", make_parent=True)
    assert json.loads((tmp_path / "a" / "r.json").read_text()) == {"wall_s": 1}


def _benchmark_modules() -> list[Path]:
    folder = REPO / "scone_bt" / "benchmarks"
    return [*sorted(folder.glob("*.py")), REPO / "scone_bt" / "scenario" / "bench.py"]


def _calls(node: ast.AST, name: str) -> list[ast.Call]:
    return [
        c
        for c in ast.walk(node)
        if isinstance(c, ast.Call) and isinstance(c.func, ast.Name) and c.func.id == name
    ]


@pytest.mark.parametrize("path", _benchmark_modules(), ids=lambda p: p.name)
def test_every_benchmark_passes_force_to_the_write(path: Path) -> None:
    """A handler that writes a report gives its write --force (the same rule as the check before it runs)."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    for fn in (n for n in ast.walk(tree) if isinstance(n, ast.FunctionDef)):
        emits = _calls(fn, "emit_report")
        assert all(any(k.arg == "force" for k in c.keywords) for c in emits), f"{path.name}:{fn.name}"


def test_scone_bench_checks_every_benchmarks_report_file_before_it_runs() -> None:
    """One place checks --json (with --force) for every benchmark, before dispatching to it
    (`cli.bench.check_report_path`, with `reporting.check_report_file`'s rule)."""
    source = (REPO / "scone_bt" / "cli" / "bench.py").read_text(encoding="utf-8")
    tree = ast.parse(source)
    main = next(n for n in ast.walk(tree) if isinstance(n, ast.FunctionDef) and n.name == "main")
    calls = [c for c in ast.walk(main) if isinstance(c, ast.Call)]
    check = next(c for c in calls if isinstance(c.func, ast.Name) and c.func.id == "check_report_path")
    dispatch = next(c for c in calls if isinstance(c.func, ast.Attribute) and c.func.attr == "func")
    assert (check.lineno, check.col_offset) < (dispatch.lineno, dispatch.col_offset)
    checker = next(
        n for n in ast.walk(tree) if isinstance(n, ast.FunctionDef) and n.name == "check_report_path"
    )
    assert _calls(checker, "check_report_file")
