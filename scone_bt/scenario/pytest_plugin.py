"""pytest plugin (entry point ``pytest11``): ``pytest scenarios/`` collects scenario files as tests.

Each case of a ``*.yaml`` file in a folder named ``scenarios``, of a file named on the command line, or of a file
with top-level ``description:`` and ``expect:`` in a folder named there (``pytest runs/demo/``), is one test item (a sweep gives one per value), so
``-k``, ``-m <tag>`` (a file's ``tags:``; every case is also marked ``scenario``), ``--junitxml`` and ``-n``
(pytest-xdist) work as for any test. A case marked ``expected: fail`` is an
xfail (strict: passing is a failure). A failing case writes its event log and recording into ``--scenario-out``
and its report names the expectation, the tick and the events around it. Importing this module is cheap: the
simulator loads only when a scenario runs.

A thin layer over `scone_bt.scenario.runner`, as ``scone-scenario run`` is: the cases, the output folder, each
case's run and its verdict come from there; the selection, the worker processes and the JUnit report from pytest
and pytest-xdist. The verdict maps one to one: passed passes, xfail is an xfail, failed, xpass and error fail.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

__all__ = ["pytest_addoption", "pytest_collect_file", "pytest_configure"]


def pytest_addoption(parser: pytest.Parser) -> None:
    group = parser.getgroup("scone-scenarios")
    group.addoption(
        "--scenario-out",
        default=None,
        help="folder for a failing scenario's event log and rerun recording (default: beside the --junitxml "
        "report, else runs/scenarios)",
    )
    group.addoption(
        "--robot",
        default=None,
        help="robot backend every scenario runs on: sim (PyBullet) or mujoco (default: each file's world.robot)",
    )
    group.addoption(
        "--arm",
        default=None,
        help="robot file every scenario runs with: a name in robots/ or a YAML path (default: each file's "
        "world.arm)",
    )
    group.addoption(
        "--scenario-no-recording",
        action="store_true",
        help="do not re-run a failing scenario to save its .rrd recording",
    )


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line("markers", "slow: physics-heavy simulation tests (every scenario case is one)")
    config.addinivalue_line("markers", "scenario: a scenario case (scenarios/*.yaml)")
    config.addinivalue_line("markers", "fast: a scenario tagged fast (the subset `make test` runs)")
    _check_scenario_out(config)


def _check_scenario_out(config: pytest.Config) -> None:
    """--scenario-out, once before any case runs (as ``scone-scenario run`` checks --out): a folder that cannot be
    made or written is a one-line usage error, not a traceback after the first failing case. Only when given: the
    plugin loads in every pytest run of an environment that has scone-bt."""
    given = config.getoption("--scenario-out", default=None)
    if not given:
        return
    from scone_bt.checks import check_output_dir
    from scone_bt.errors import SconeError

    try:
        check_output_dir(Path(given), "--scenario-out")
    except SconeError as exc:
        raise pytest.UsageError(str(exc)) from None


def pytest_collect_file(parent: pytest.Collector, file_path: Path) -> pytest.Collector | None:
    if file_path.suffix != ".yaml":
        return None
    named = _named_on_command_line(parent.config, file_path)
    if (
        file_path.parent.name == "scenarios"
        or named == "file"
        or (named == "folder" and _reads_as_scenario(file_path))
    ):
        return ScenarioYaml.from_parent(parent, path=file_path)
    return None


def _named_on_command_line(config: pytest.Config, file_path: Path) -> str:
    """ "file" if the file was given as an argument, "folder" if a folder above it other than pytest's root was,
    else "" (the arguments pytest was given, not its ``testpaths``)."""
    root, path = Path(config.rootpath).resolve(), file_path.resolve()
    for arg in getattr(config.option, "file_or_dir", None) or ():
        try:
            named = (config.invocation_params.dir / str(arg).split("::")[0]).resolve()
        except (OSError, ValueError):
            continue
        if named == path:
            return "file"
        if named != root and named in path.parents:
            return "folder"
    return ""


def _reads_as_scenario(file_path: Path) -> bool:
    """A file with top-level ``description:`` and ``expect:`` lines, read as text: the plugin loads in every pytest
    run of an environment that has scone-bt, so another project's YAML files beside its tests (several documents,
    custom tags, fixtures broken on purpose) are left alone rather than parsed. A scenario that does not parse is
    still collected, and its error reported."""
    import re

    try:
        with file_path.open(encoding="utf-8") as f:
            text = f.read(200_000)
    except (OSError, UnicodeDecodeError):
        return False
    return all(re.search(rf"^{key}\s*:", text, flags=re.M) for key in ("description", "expect"))


def _out_dir(config: pytest.Config) -> Path:
    """Where a failing case's log and recording go: --scenario-out, else beside the JUnit report."""
    from scone_bt.scenario.runner import default_out_dir

    given, junit = config.getoption("--scenario-out"), getattr(config.option, "xmlpath", None)
    return default_out_dir(Path(given) if given else None, Path(junit) if junit else None)


class ScenarioYaml(pytest.File):
    """A scenario file: one item per case."""

    def collect(self) -> Any:
        from scone_bt.errors import SconeError
        from scone_bt.scenario.runner import load_cases

        try:
            cases = load_cases([self.path], self.config.getoption("--robot"), self.config.getoption("--arm"))
        except SconeError as exc:
            raise self.CollectError(str(exc)) from None
        for case in cases:
            yield ScenarioItem.from_parent(self, name=case.name, case=case)


class ScenarioFailed(Exception):
    """A case whose expectations did not hold (its report is the message)."""


class ScenarioItem(pytest.Item):
    """One scenario case."""

    def __init__(self, *, case: Any, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.case = case
        self.add_marker(pytest.mark.slow)
        self.add_marker(pytest.mark.scenario)
        for tag in case.spec.tags:  # `pytest -m <tag>` selects by the file's tags
            self.config.addinivalue_line("markers", f"{tag}: scenarios tagged {tag}")
            self.add_marker(tag)

    def runtest(self) -> None:
        from scone_bt.scenario.run import Verdict
        from scone_bt.scenario.runner import run_one

        record = not self.config.getoption("--scenario-no-recording")
        result = run_one(self.case, _out_dir(self.config), record_failures=record)
        self.user_properties.append(("sim_s", f"{result.sim_s:.1f}"))
        if result.verdict == Verdict.XFAIL:
            pytest.xfail(result.reason)
        if not result.ok:  # failed, passed against its `expected: fail`, or an error
            raise ScenarioFailed(result.report())

    def repr_failure(self, excinfo: pytest.ExceptionInfo[BaseException], style: Any = None) -> str:
        if isinstance(excinfo.value, ScenarioFailed):
            return str(excinfo.value)
        return str(super().repr_failure(excinfo))

    def reportinfo(self) -> tuple[Path, int, str]:
        return self.path, 0, f"scenario {self.name}"
