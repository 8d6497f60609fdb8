"""Which robot backend a scenario runs on: ``world.robot``, the commands' ``--robot``, and ``expected_on``."""

from __future__ import annotations

from pathlib import Path

import pytest

from scone_bt.errors import ConfigError, UnknownNameError
from scone_bt.scenario.model import load_scenario, on_backend
from scone_bt.scenario.run import episode_options

BASE = "description: d\nexpect:\n  - {completes: true}\n"
ON_MUJOCO = "expected_on:\n  mujoco: {expected: fail, reason: 'MuJoCo: measured difference'}\n"


def _case(tmp_path: Path, text: str):
    path = tmp_path / "case.yaml"
    path.write_text(text, encoding="utf-8")
    return load_scenario(path)[0]


def test_the_file_names_its_backend_and_the_episode_runs_on_it(tmp_path: Path) -> None:
    assert episode_options(_case(tmp_path, BASE)).backend == "sim"
    case = on_backend(_case(tmp_path, BASE + "world: {robot: mujoco}\n"), None)
    assert case.spec.world.robot == "mujoco" and episode_options(case).backend == "mujoco"


def test_an_unknown_backend_is_one_line_naming_the_valid_ones(tmp_path: Path) -> None:
    with pytest.raises(ConfigError) as info:
        _case(tmp_path, BASE + "world: {robot: gazebo}\n")
    assert "\n" not in str(info.value) and "valid: mujoco, sim" in str(info.value)
    with pytest.raises(ConfigError) as info:
        _case(tmp_path, BASE + "expected_on:\n  gazebo: {reason: r}\n")
    assert "gazebo" in str(info.value)
    with pytest.raises(UnknownNameError, match="valid: mujoco, sim"):
        on_backend(_case(tmp_path, BASE), "gazebo")


def test_expected_on_applies_only_on_its_backend(tmp_path: Path) -> None:
    case = _case(tmp_path, BASE + ON_MUJOCO)
    on_sim = on_backend(case, "sim")
    assert on_sim.spec.expected == "pass" and on_sim.spec.reason is None
    on_mujoco = on_backend(case, "mujoco")
    assert on_mujoco.spec.expected == "fail" and on_mujoco.spec.reason == "MuJoCo: measured difference"
    assert episode_options(on_mujoco).backend == "mujoco"
    # the --robot of a command overrides the file's world.robot, and the file's own expectation returns
    back = on_backend(_case(tmp_path, BASE + ON_MUJOCO + "world: {robot: mujoco}\n"), "sim")
    assert back.spec.expected == "pass" and episode_options(back).backend == "sim"
