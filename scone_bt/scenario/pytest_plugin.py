"""pytest plugin (entry point ``pytest11``): ``pytest scenarios/`` collects scenario files as tests.

Each case of a ``*.yaml`` file in a folder named ``scenarios`` is one test item (a sweep gives one per value), so
``-k``, ``-m <tag>`` (a file's ``tags:``; every case is also marked ``scenario``), ``--junitxml`` and ``-n``
(pytest-xdist) work as for any test. A case marked ``expected: fail`` is an
xfail (strict: passing is a failure). A failing case writes its event log and recording into ``--scenario-out``
and its report names the expectation, the tick and the events around it. Importing this module is cheap: the
simulator loads only when a scenario runs.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

__all__ = ["pytest_addoption", "pytest_collect_file", "pytest_configure"]

_MODELS: Any = None


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


def pytest_collect_file(parent: pytest.Collector, file_path: Path) -> pytest.Collector | None:
    if file_path.suffix == ".yaml" and file_path.parent.name == "scenarios":
        return ScenarioYaml.from_parent(parent, path=file_path)
    return None


def _out_dir(config: pytest.Config) -> Path:
    """Where a failing case's log and recording go: --scenario-out, else beside the JUnit report."""
    given = config.getoption("--scenario-out")
    if given:
        return Path(given)
    junit = getattr(config.option, "xmlpath", None)
    return Path(junit).parent if junit else Path("runs/scenarios")


class ScenarioYaml(pytest.File):
    """A scenario file: one item per case."""

    def collect(self) -> Any:
        from scone_bt.errors import SconeError
        from scone_bt.scenario.model import load_scenario, on_backend

        try:
            robot, arm = self.config.getoption("--robot"), self.config.getoption("--arm")
            cases = [on_backend(c, robot, arm) for c in load_scenario(self.path)]
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
        if case.spec.expected == "fail":
            self.add_marker(pytest.mark.xfail(reason=case.spec.reason, strict=True, raises=ScenarioFailed))

    def runtest(self) -> None:
        global _MODELS
        from scone_bt.episode.resources import ModelPool
        from scone_bt.scenario.run import Verdict, run_case

        if _MODELS is None:
            _MODELS = ModelPool()
        out = _out_dir(self.config)
        result = run_case(
            self.case, out, _MODELS, record_failures=not self.config.getoption("--scenario-no-recording")
        )
        self.user_properties.append(("sim_s", f"{result.sim_s:.1f}"))
        if result.verdict == Verdict.ERROR:
            raise ScenarioFailed(result.report())
        if result.failures:
            raise ScenarioFailed(result.report())

    def repr_failure(self, excinfo: pytest.ExceptionInfo[BaseException], style: Any = None) -> str:
        if isinstance(excinfo.value, ScenarioFailed):
            return str(excinfo.value)
        return str(super().repr_failure(excinfo))

    def reportinfo(self) -> tuple[Path, int, str]:
        return self.path, 0, f"scenario {self.name}"
