"""URDF geometry reading, on the shipped Panda and on small hand-written files."""

from __future__ import annotations

import math

import pytest

from scone_bt.errors import ConfigError, UnknownNameError
from scone_bt.viz.urdf_visuals import read_robot_visuals, rpy_to_quat


def test_rpy_to_quat_matches_known_rotations():
    assert rpy_to_quat(0, 0, 0) == pytest.approx((0, 0, 0, 1))
    assert rpy_to_quat(0, 0, math.pi) == pytest.approx((0, 0, 1, 0), abs=1e-12)
    s = math.sqrt(0.5)
    assert rpy_to_quat(math.pi / 2, 0, 0) == pytest.approx((s, 0, 0, s))
    # fixed-axis order: roll then pitch about the fixed y axis
    assert rpy_to_quat(math.pi / 2, math.pi / 2, 0) == pytest.approx((0.5, 0.5, -0.5, 0.5))


def test_panda_visuals(robot_cfg):
    robot = read_robot_visuals(robot_cfg.urdf)
    assert robot.root_link == "panda_link0"
    assert robot.root_inertial_position == pytest.approx((0, 0, 0.05))
    links = robot.links()
    assert links[0] == "panda_link0" and "panda_hand" in links and "panda_rightfinger" in links
    assert "panda_link8" not in links  # a frame without geometry
    assert all(v.kind == "mesh" and v.mesh is not None and v.mesh.is_file() for v in robot.visuals)
    right = next(v for v in robot.visuals if v.link == "panda_rightfinger")
    assert right.quaternion == pytest.approx((0, 0, 1, 0), abs=1e-9)
    assert right.mesh.parent.name == "visual"
    assert not robot.skipped
    coarse = read_robot_visuals(robot_cfg.urdf, "collision")
    assert {v.mesh.parent.name for v in coarse.visuals} == {"collision"}


def test_primitives_materials_and_undrawable_geometry(tmp_path):
    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "part.stl").write_bytes(b"solid x\nendsolid x\n")
    urdf = tmp_path / "bot.urdf"
    urdf.write_text(
        """<robot name="bot">
  <material name="red"><color rgba="1 0 0 1"/></material>
  <link name="base"><inertial><origin xyz="0 0 0.1"/><mass value="1"/></inertial>
    <visual><origin xyz="0 0 0.5" rpy="0 0 0"/><geometry><box size="0.1 0.2 0.3"/></geometry>
      <material name="red"/></visual></link>
  <link name="arm">
    <visual><geometry><cylinder radius="0.05" length="0.4"/></geometry></visual>
    <visual><geometry><sphere radius="0.02"/></geometry><material name="m"><color rgba="0 1 0 1"/></material></visual>
    <visual><geometry><mesh filename="package://bot/meshes/part.stl" scale="2"/></geometry></visual>
    <visual><geometry><mesh filename="meshes/part.dae"/></geometry></visual>
    <visual><geometry><mesh filename="meshes/missing.obj"/></geometry></visual>
  </link>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/></joint>
</robot>"""
    )
    robot = read_robot_visuals(urdf)
    assert robot.name == "bot" and robot.root_link == "base"
    assert robot.root_inertial_position == pytest.approx((0, 0, 0.1))
    kinds = [(v.link, v.kind) for v in robot.visuals]
    assert kinds == [("base", "box"), ("arm", "cylinder"), ("arm", "sphere"), ("arm", "mesh")]
    box, cyl, sphere, mesh = robot.visuals
    assert box.size == (0.1, 0.2, 0.3) and box.position == (0, 0, 0.5) and box.rgba == (1, 0, 0, 1)
    assert cyl.size == (0.05, 0.05, 0.4)
    assert sphere.rgba == (0, 1, 0, 1)
    assert mesh.mesh == tmp_path / "meshes" / "part.stl" and mesh.scale == (2, 2, 2)
    assert len(robot.skipped) == 2
    assert "not drawable" in robot.skipped[0] and "not found" in robot.skipped[1]


def test_bad_inputs_give_one_line_errors(tmp_path, robot_cfg):
    with pytest.raises(UnknownNameError, match="valid: collision, visual"):
        read_robot_visuals(robot_cfg.urdf, "fancy")
    bad = tmp_path / "bad.urdf"
    bad.write_text("<robot><link")
    with pytest.raises(ConfigError, match="cannot read URDF"):
        read_robot_visuals(bad)
