"""Grasp and place geometry from a detection and the catalogue model (no simulator)."""

from __future__ import annotations

import numpy as np
import pytest

from scone_bt.motion import GraspParams, grasp_candidates, place_pose
from scone_bt.motion.grasp import object_pose, top_down_rotation
from scone_bt.perception.types import Detection


def _det(name, xyz, yaw=0.0):
    return Detection(name, 0, xyz, yaw, 1.0, (0, 0, 1, 1))


@pytest.mark.parametrize("yaw", [-2.0, -0.5, 0.0, 1.0, 3.0])
def test_top_down_rotation_is_a_rotation_pointing_down(yaw):
    r = top_down_rotation(yaw)
    assert np.allclose(r @ r.T, np.eye(3)) and np.linalg.det(r) == pytest.approx(1.0)
    assert np.allclose(r[:, 2], [0, 0, -1])
    assert np.allclose(r[:, 1], [np.cos(yaw), np.sin(yaw), 0])


def test_box_is_grasped_across_its_narrow_side(kitchen_cfg):
    sugar = kitchen_cfg.catalogue.get("sugar")  # 7 x 5 cm: the narrow side is the object's y axis
    det = _det("sugar", (0.5, 0.3, 0.18), yaw=0.3)
    cands = grasp_candidates(det, sugar)
    assert (
        len([c for c in cands if c.tilt == 0.0]) == 2
    )  # the same grasp with the wrist half-turned, as a fallback
    narrow_axis = np.array([-np.sin(0.3), np.cos(0.3), 0.0])
    for cand in cands:
        assert abs(cand.grasp[:3, 1] @ narrow_axis) == pytest.approx(1.0, abs=1e-9)
        assert cand.span == pytest.approx(0.05)
    assert abs(cands[0].closing_yaw - (-np.pi / 2)) <= np.pi / 2  # nearest the home wrist first


def test_grasp_is_below_the_top_and_above_the_support(kitchen_cfg):
    params = GraspParams()
    for name in ("butter", "salt", "olive oil"):
        spec = kitchen_cfg.catalogue.get(name)
        top = 0.06 + spec.height
        cand = grasp_candidates(_det(name, (0.5, 0.3, top)), spec, params)[0]
        z = cand.grasp[2, 3]
        assert top - params.max_depth - 1e-9 <= z < top
        assert z >= 0.06 + params.min_clearance - 1e-9
        assert cand.pregrasp[2, 3] == pytest.approx(z + params.approach)


def test_cylinder_prefers_closing_along_the_shelf_depth(kitchen_cfg):
    salt = kitchen_cfg.catalogue.get("salt")
    first = grasp_candidates(_det("salt", (0.5, 0.3, 0.16)), salt)[0]
    assert abs(first.grasp[:3, 1] @ np.array([1.0, 0, 0])) == pytest.approx(1.0)


def test_place_pose_sets_the_object_upright_just_above_the_spot(kitchen_cfg):
    spec = kitchen_cfg.catalogue.get("milk")
    det = _det("milk", (0.37, 0.3, spec.height), yaw=0.2)
    cand = grasp_candidates(det, spec)[0]
    params = GraspParams()
    ee = place_pose((0.49, -0.42, 0.0), spec, cand.object_in_ee, cand.closing_yaw + 0.5, params)
    obj = ee @ cand.object_in_ee
    assert np.allclose(obj[:3, 3], [0.49, -0.42, params.place_drop + spec.height / 2])
    assert obj[:3, 2] @ np.array([0, 0, 1.0]) == pytest.approx(1.0)
    assert np.allclose(object_pose(det, spec)[:3, 3], [0.37, 0.3, spec.height / 2])


def test_far_objects_get_tilted_approaches_leaning_away_from_the_robot(kitchen_cfg):
    salt = kitchen_cfg.catalogue.get("salt")
    cands = grasp_candidates(_det("salt", (0.63, 0.6, 0.22)), salt)
    assert cands[0].tilt == 0.0  # top-down first
    tilted = [c for c in cands if c.tilt != 0.0]
    assert tilted
    outward = np.array([0.63, 0.6, 0.0]) / np.hypot(0.63, 0.6)
    for c in tilted:
        approach = c.grasp[:3, 2]
        assert approach[2] < 0 and approach @ outward > 0  # down and away from the robot
        assert abs(c.grasp[2, 1]) < 1e-9  # the fingers still close horizontally
        assert np.allclose(c.grasp[:3, 3] - c.pregrasp[:3, 3], approach * GraspParams().approach)


def test_tilted_place_pose_keeps_the_object_upright(kitchen_cfg):
    salt = kitchen_cfg.catalogue.get("salt")
    cand = next(c for c in grasp_candidates(_det("salt", (0.63, 0.6, 0.22)), salt) if c.tilt != 0.0)
    ee = place_pose(
        (0.37, -0.3, 0.0), salt, cand.object_in_ee, cand.closing_yaw - 1.0, GraspParams(), cand.tilt
    )
    obj = ee @ cand.object_in_ee
    assert obj[:3, 2] @ np.array([0, 0, 1.0]) == pytest.approx(1.0)
    assert np.allclose(obj[:2, 3], [0.37, -0.3])
