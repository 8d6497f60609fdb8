"""Scenarios run as real (short) episodes: a false expectation fails with its name and leaves its event log and
recording; a repeat gives the identical event log; the CLI's and pytest's JUnit files list every case."""

from __future__ import annotations

import json
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from scone_bt.episode.resources import ModelPool
from scone_bt.scenario.model import load_scenario
from scone_bt.scenario.run import Verdict, run_case

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def models() -> ModelPool:
    return ModelPool()


def _file(tmp_path: Path, text: str, name: str = "short.yaml") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def test_a_false_expectation_fails_with_its_name_and_leaves_log_and_recording(tmp_path: Path, models) -> None:
    path = _file(
        tmp_path,
        "description: The robot keeps off the salt (false, the salt is its first fetch).\n"
        "world: {max_ticks: 120}\n"
        "expect:\n  - {never_attempts: salt}\n  - {max_failures: 5}\n",
    )
    (case,) = load_scenario(path)
    out = tmp_path / "out"
    result = run_case(case, out, models)
    assert result.verdict == Verdict.FAILED
    assert result.reason == "never_attempts: salt: the robot attempted 'salt'"
    (failure,) = result.failures
    assert failure.tick >= 0 and any("act" in line and "salt" in line for line in failure.around)
    log, rrd = (Path(a) for a in result.artifacts)
    assert log.name == "short.events.jsonl" and rrd.name == "short.rrd"
    assert [json.loads(line) for line in log.read_text().splitlines()][0]["event"] == "decision"
    assert rrd.stat().st_size > 0 and result.replay.endswith(str(rrd))
    report = result.report()
    assert "expectation 'never_attempts: salt' failed at tick" in report and "replay: " in report


def test_expected_failure_and_a_repeat_gives_the_identical_event_log(tmp_path: Path, models) -> None:
    path = _file(
        tmp_path,
        "description: A short run with a camera covered and a fault mid-run, twice.\n"
        "expected: fail\nreason: the recipe cannot be done in 12 s\n"
        "world: {max_ticks: 120}\n"
        "events:\n  - {at: 2, cover_camera: shelf_left}\n  - {at: 3, fault: {gripper_force: 10}}\n"
        "expect:\n  - {completes: true}\n",
    )
    (case,) = load_scenario(path)
    first, second = run_case(case, None, models), run_case(case, None, models)
    assert first.verdict == Verdict.XFAIL and first.reason.startswith("expected failure (the recipe cannot")
    assert first.events and first.events == second.events
    assert [line for line in first.log if line.startswith("scenario:")] == [
        "scenario: t=2.0 s tick 15: event 0 (cover_camera: shelf_left)",
        "scenario: t=3.0 s tick 25: event 1 (fault: {'gripper_force': 10.0})",
    ]


def test_cli_and_pytest_junit_list_every_case(tmp_path: Path) -> None:
    folder = tmp_path / "scenarios"
    folder.mkdir()
    tiny = _file(
        folder,
        "description: Two seeds, each a short run that does not finish the recipe.\n"
        "world: {max_ticks: 20}\nsweep:\n  world.seed: [0, 1]\nexpect:\n  - {completes: false}\n",
        "tiny.yaml",
    )
    _file(
        folder,
        "description: One short run on the hummus recipe.\nworld: {max_ticks: 20, recipe: 'example:hummus'}\n"
        "tags: [fast]\nexpect:\n  - {completes: false}\n",
        "other.yaml",
    )
    exe = Path(sys.executable).parent
    junit = tmp_path / "cli.xml"
    run = subprocess.run(
        [str(exe / "scone-scenario"), "run", str(tiny), "--jobs", "1", "--junit", str(junit)],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert run.returncode == 0, run.stdout + run.stderr
    names = [c.get("name") for c in ET.parse(junit).iter("testcase")]
    assert names == ["tiny[world.seed=0]", "tiny[world.seed=1]"]
    assert "2 cases: 2 passed" in run.stdout
    xml = tmp_path / "pytest.xml"
    run = subprocess.run(
        [sys.executable, "-m", "pytest", str(folder), "-q", "-p", "no:cacheprovider", "-k", "other",
         f"--junitxml={xml}", "--rootdir", str(tmp_path), "-o", "addopts=", "-o", "testpaths="],
        capture_output=True,
        text=True,
        timeout=600,
        cwd=tmp_path,
    )  # fmt: skip
    assert run.returncode == 0, run.stdout + run.stderr
    assert [c.get("name") for c in ET.parse(xml).iter("testcase")] == ["other"]
    # -m selects by the files' tags, -n runs the cases in parallel workers (pytest-xdist)
    run = subprocess.run(
        [sys.executable, "-m", "pytest", str(folder), "-q", "-p", "no:cacheprovider", "-m", "not fast",
         "-n", "2", f"--junitxml={xml}", "--rootdir", str(tmp_path), "-o", "addopts=", "-o", "testpaths="],
        capture_output=True,
        text=True,
        timeout=600,
        cwd=tmp_path,
    )  # fmt: skip
    assert run.returncode == 0, run.stdout + run.stderr
    assert sorted(c.get("name") for c in ET.parse(xml).iter("testcase")) == [
        "tiny[world.seed=0]",
        "tiny[world.seed=1]",
    ]
    # the command line's tag filters, and one line when none is left
    run = subprocess.run(
        [str(exe / "scone-scenario"), "run", str(folder), "--tag", "fast", "--skip-tag", "fast"],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert run.returncode == 2
    assert run.stderr.strip().startswith(
        "scone-scenario: no case left after --tag/--skip-tag; the cases' tags: "
    )


def test_a_failing_case_leaves_its_log_and_recording_beside_the_junit_report(tmp_path: Path) -> None:
    path = _file(
        tmp_path,
        "description: The robot keeps off the salt (false, the salt is its first fetch).\n"
        "world: {max_ticks: 120}\nexpect:\n  - {never_attempts: salt}\n",
    )
    junit = tmp_path / "report" / "junit.xml"
    run = subprocess.run(
        [str(Path(sys.executable).parent / "scone-scenario"), "run", str(path), "--junit", str(junit)],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert run.returncode == 1, run.stdout + run.stderr
    assert sorted(p.name for p in junit.parent.iterdir()) == ["junit.xml", "short.events.jsonl", "short.rrd"]
    assert "replay: " in run.stdout and str(junit.parent / "short.rrd") in run.stdout
