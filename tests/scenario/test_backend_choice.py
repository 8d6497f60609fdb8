"""Which robot backend a scenario runs on: ``world.robot``, the commands' ``--robot``, and ``expected_on``."""

from __future__ import annotations

from pathlib import Path

import pytest

from scone_bt.errors import ConfigError, SconeError
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
    with pytest.raises(SconeError, match="unknown robot backend; valid: mujoco, sim"):
        on_backend(_case(tmp_path, BASE), "gazebo")


@pytest.mark.parametrize("robot_file", ["iiwa7", "robots/iiwa7.yaml"])
def test_a_robot_file_given_as_the_backend_says_to_use_arm(tmp_path: Path, robot_file: str) -> None:
    with pytest.raises(SconeError) as info:
        on_backend(_case(tmp_path, BASE), robot_file)
    message = str(info.value)
    assert "\n" not in message and f"--arm {robot_file}" in message


def test_arm_names_the_robot_file_of_every_case(tmp_path: Path) -> None:
    case = _case(tmp_path, BASE + "world: {robot: mujoco}\n")
    assert case.spec.world.arm == "panda"
    on_iiwa = on_backend(case, None, "iiwa7")
    assert on_iiwa.spec.world.arm == "iiwa7" and on_iiwa.spec.world.robot == "mujoco"
    assert episode_options(on_iiwa).arm == "iiwa7"
    with pytest.raises(SconeError) as info:
        on_backend(case, "sim", "nosuch")
    assert "\n" not in str(info.value) and "iiwa7, panda" in str(info.value)


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
