"""The robot file: a home pose outside the joints' range is one line naming the joint, before the robot acts."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
import yaml

from scone_bt.config import load_robot
from scone_bt.errors import ConfigError
from scone_bt.resources import data_dir


def _robot(tmp_path: Path) -> dict:
    return yaml.safe_load((data_dir("robots") / "panda.yaml").read_text())


def _refused(tmp_path: Path, doc: dict, *parts: str) -> None:
    path = tmp_path / "arm.yaml"
    path.write_text(yaml.safe_dump(doc))
    with pytest.raises(ConfigError) as err:
        load_robot(path)
    msg = str(err.value)
    assert "\n" not in msg and str(path) in msg
    for part in parts:
        assert part in msg, msg


@pytest.mark.parametrize("name", ["panda", "iiwa7"])
def test_committed_robots_load(name: str):
    robot = load_robot(name)
    assert len(robot.home) == robot.dof


@pytest.mark.parametrize(
    ("index", "value", "parts"),
    [
        (0, 1e6, ("home[0] (panda_joint1)", "outside")),
        (3, -7.0, ("home[3] (panda_joint4)", "outside")),
        (3, 0.5, ("home[3] (panda_joint4)", "limits", "panda.urdf")),  # within 2 pi, outside the URDF's range
        (1, math.inf, ("home[1]",)),
    ],
)
def test_home_outside_joint_limits_is_refused(
    tmp_path: Path, index: int, value: float, parts: tuple[str, ...]
):
    doc = _robot(tmp_path)
    doc["home"][index] = value
    _refused(tmp_path, doc, *parts)


@pytest.mark.parametrize(
    ("key", "value"),
    [
        ("yaw_step_deg", 1.0e-9),
        ("yaw_step_deg", 720.0),
        ("side_max_angle_deg", 1e9),
        ("ik_alternatives", 10**9),
        ("path_retries", 10**9),
    ],
)
def test_grasp_loop_settings_are_bounded(tmp_path: Path, key: str, value: float):
    doc = _robot(tmp_path)
    doc["grasp"][key] = value
    _refused(tmp_path, doc, f"grasp.{key}", "between")


@pytest.mark.parametrize(
    ("key", "index", "value", "parts"),
    [
        (
            "arm_joints",
            2,
            "panda_jointX",
            ("arm_joints[2]: 'panda_jointX' is not a movable joint of panda.urdf",),
        ),
        (
            "gripper.joints",
            0,
            "finger",
            ("gripper.joints[0]: 'finger' is not a movable joint", "panda_finger_joint1"),
        ),
        ("end_effector_frame", None, "nosuch", ("end_effector_frame: 'nosuch' is not a link of panda.urdf",)),
        ("collision.hand_links", 0, "palm", ("collision.hand_links[0]: 'palm' is not a link", "panda_hand")),
    ],
)
def test_unknown_joint_or_frame_names_the_file_and_key(
    tmp_path: Path, key: str, index: int | None, value: str, parts: tuple[str, ...]
):
    doc = _robot(tmp_path)
    *outer, last = key.split(".")
    section = doc
    for part in outer:
        section = section.setdefault(part, {})
    if index is None:
        section[last] = value
    else:
        section.setdefault(last, ["panda_hand"])[index] = value
    _refused(tmp_path, doc, *parts, "valid: ")


@pytest.mark.parametrize("value", [4.0, 0.6])
def test_a_gripper_opening_past_a_metre_names_the_file_and_the_keys(tmp_path: Path, value: float):
    doc = _robot(tmp_path)
    doc["gripper"]["open_position"] = value
    _refused(tmp_path, doc, "gripper:", f"open_position ({value})", "closed_position (0.0)", "not below 1 m")


def test_a_finger_position_past_the_urdfs_limit_or_a_repeated_finger_joint_is_refused(tmp_path: Path):
    """Both loaded before: a finger told to open 0.2 m stops at 0.04, and the gate believed in a 0.4 m opening."""
    doc = _robot(tmp_path)
    doc["gripper"]["open_position"] = 0.2
    _refused(tmp_path, doc, "gripper.open_position: 0.2 is outside panda_finger_joint1's limits [0, 0.04]")
    doc = _robot(tmp_path)
    doc["gripper"]["joints"] = ["panda_finger_joint1", "panda_finger_joint1"]
    _refused(tmp_path, doc, "gripper: joints: a joint is listed twice")


def test_a_gripper_joint_that_is_an_arm_joint_is_blamed_on_gripper_joints(tmp_path: Path):
    doc = _robot(tmp_path)
    doc["gripper"]["joints"] = ["panda_joint7", "panda_finger_joint2"]
    _refused(
        tmp_path,
        doc,
        "gripper.joints[0]: 'panda_joint7' is one of arm_joints; a gripper joint moves a finger",
        "panda_finger_joint1",
    )


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("", "is not valid XML (no element found"),
        ('<robot name="x"><link name="a"></robot>', "is not valid XML (mismatched tag"),
        ("<sdf/>", "is not a URDF (its root element is <sdf>, not <robot>)"),
    ],
)
def test_a_urdf_that_is_not_one_is_refused_at_load_in_one_line(tmp_path: Path, text: str, expected: str):
    """PyBullet glued its parser's output to the error (and an empty file printed a line at exit)."""
    urdf = tmp_path / "arm.urdf"
    urdf.write_text(text)
    doc = _robot(tmp_path)
    doc["urdf"] = str(urdf)
    _refused(tmp_path, doc, f"urdf: {urdf} {expected}")


def test_a_urdf_with_a_default_namespace_loads(tmp_path: Path):
    """<robot xmlns="..."> (as Drake writes its URDFs): the same names, checked as without the namespace."""
    from scone_bt.config.robot import resolve_urdf

    doc = _robot(tmp_path)
    source = resolve_urdf(doc["urdf"], data_dir("robots") / "panda.yaml")
    namespaced = tmp_path / "panda_ns.urdf"
    namespaced.write_text(source.read_text().replace("<robot ", '<robot xmlns="http://drake.mit.edu" ', 1))
    assert 'xmlns="http://drake.mit.edu"' in namespaced.read_text()
    doc["urdf"] = str(namespaced)
    path = tmp_path / "arm.yaml"
    path.write_text(yaml.safe_dump(doc))
    assert load_robot(path).urdf == namespaced


def test_a_value_where_a_section_belongs_names_the_sections_keys_not_a_class(tmp_path):
    """pydantic said "Input should be a valid dictionary or instance of _PlannerFile": a class name, no keys."""
    from scone_bt.config import load_robot
    from scone_bt.errors import ConfigError
    from scone_bt.resources import data_dir

    path = tmp_path / "panda.yaml"
    path.write_text(
        (data_dir("robots") / "panda.yaml").read_text().replace("planner:\n", "planner: 7\nunused:\n", 1)
    )
    with pytest.raises(ConfigError) as err:
        load_robot(path)
    assert (
        "planner: must be a mapping of keys to values (name, time_limit_s, simplify, rng_seed, backend) (got 7)"
        in str(err.value)
    )
    assert "instance of" not in str(err.value)


def test_a_short_arm_joints_list_is_named_not_the_home_it_disagrees_with(tmp_path):
    """`arm_joints: [panda_joint1]` was reported as "home: expected 1 numbers"."""
    import re

    from scone_bt.config import load_robot
    from scone_bt.errors import ConfigError
    from scone_bt.resources import data_dir

    path = tmp_path / "panda.yaml"
    text = (data_dir("robots") / "panda.yaml").read_text()
    path.write_text(re.sub(r"(?m)^arm_joints: \[.*\]$", "arm_joints: [panda_joint1]", text))
    with pytest.raises(
        ConfigError, match=r"arm_joints: 1 joints listed, but home and limits give 7 values each"
    ):
        load_robot(path)
