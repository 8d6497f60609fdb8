"""Grasp generation and place geometry from a detection and a catalogue model (no simulator)."""

from __future__ import annotations

import numpy as np
import pytest

from scone_bt.config import ObjectSpec
from scone_bt.config.grasp import GraspParams
from scone_bt.errors import ConfigError
from scone_bt.motion import GraspFamily, grasp_candidates, place_pose
from scone_bt.motion.grasp import object_pose, side_rotation, top_down_rotation
from scone_bt.perception.types import Detection


def _spec(name, shape, size):
    return ObjectSpec(name, (), shape, size, 0.3, 0.6, "test", (1, 1, 1, 1), 0)


BOTTLE = _spec("bottle", "cylinder", (0.05, 0.05, 0.18))
BOX = _spec("box", "box", (0.07, 0.05, 0.12))
FLAT = _spec("flat", "box", (0.065, 0.035, 0.03))
WIDE = _spec("wide", "cylinder", (0.09, 0.09, 0.12))


def _det(name, xyz, yaw=0.0):
    return Detection(name, 0, xyz, yaw, 1.0, (0, 0, 1, 1))


def _is_rotation(r):
    return np.allclose(r @ r.T, np.eye(3)) and np.linalg.det(r) == pytest.approx(1.0)


@pytest.mark.parametrize("yaw", [-2.0, -0.5, 0.0, 1.0, 3.0])
def test_top_down_and_side_rotations_close_along_the_yaw(yaw):
    top = top_down_rotation(yaw)
    assert _is_rotation(top) and np.allclose(top[:, 2], [0, 0, -1])
    assert np.allclose(top[:, 1], [np.cos(yaw), np.sin(yaw), 0])
    side = side_rotation(yaw)
    assert _is_rotation(side) and abs(side[2, 2]) < 1e-12  # horizontal approach
    assert np.allclose(side[:, 1], [np.cos(yaw), np.sin(yaw), 0])


def test_a_tall_cylinder_gets_all_three_families_ordered_by_cost():
    cands = grasp_candidates(_det("bottle", (0.5, 0.3, 0.24)), BOTTLE, GraspParams(), opening=0.08)
    families = {c.family for c in cands}
    assert families == {GraspFamily.TOP, GraspFamily.TILTED, GraspFamily.SIDE}
    costs = [c.cost for c in cands]
    assert costs == sorted(costs)
    assert cands[0].family is GraspFamily.TOP
    # The yaw sweep: 8 closing axes x 2 wrist angles of top grasps, each at the full and at the shallow depth.
    tops = [c for c in cands if c.family is GraspFamily.TOP]
    assert len(tops) == 32
    top_z = 0.24 - GraspParams().max_depth, 0.24 - GraspParams().shallow_depth
    assert sorted({round(c.grasp[2, 3], 6) for c in tops}) == pytest.approx(sorted(top_z))
    # A shallow grasp costs more than the same grasp at full depth.
    deep = min(c.cost for c in tops if c.grasp[2, 3] < 0.22)
    assert min(c.cost for c in tops if c.grasp[2, 3] > 0.22) > deep
    # The first grasp's wrist is nearest the preferred yaw (-pi/2).
    assert abs(np.cos(cands[0].closing_yaw + np.pi / 2)) > np.cos(np.pi / 8) - 1e-9


def test_side_grasps_approach_horizontally_from_the_robots_side():
    det = _det("bottle", (0.5, 0.3, 0.24))
    params = GraspParams()
    sides = [c for c in grasp_candidates(det, BOTTLE, params) if c.family is GraspFamily.SIDE]
    assert sides
    outward = np.array([0.5, 0.3, 0.0]) / np.hypot(0.5, 0.3)
    support = 0.24 - BOTTLE.height
    for c in sides:
        approach = c.grasp[:3, 2]
        assert abs(approach[2]) < 1e-9 and approach @ outward >= -1e-9  # never from behind
        assert abs(c.grasp[2, 1]) < 1e-9  # fingers close horizontally
        assert support + params.side_min_height - 1e-9 <= c.grasp[2, 3] <= 0.24 - params.side_top_margin
        assert np.allclose(c.grasp[:3, 3] - c.pregrasp[:3, 3], approach * params.approach)
        # The grasp point lies on the bottle's axis (its radius is within side_depth).
        assert np.allclose(c.grasp[:2, 3], [0.5, 0.3], atol=1e-9)


def test_a_flat_object_gets_no_side_grasp_and_stays_above_its_support():
    params = GraspParams()
    cands = grasp_candidates(_det("flat", (0.5, 0.3, 0.09)), FLAT, params, opening=0.08)
    assert cands and all(c.family is not GraspFamily.SIDE for c in cands)
    for c in cands:
        z = c.grasp[2, 3]
        assert 0.09 - params.max_depth - 1e-9 <= z < 0.09
        assert z >= 0.06 + params.min_clearance - 1e-9


def test_the_opening_filters_spans_unless_nothing_fits():
    det = _det("box", (0.5, 0.3, 0.18), yaw=0.3)
    both = grasp_candidates(det, BOX, opening=0.08)
    assert {round(c.span, 3) for c in both if c.family is GraspFamily.TOP} == {0.05, 0.07}
    narrow = grasp_candidates(det, BOX, opening=0.06)
    assert {round(c.span, 3) for c in narrow} == {0.05}
    axis = np.array([-np.sin(0.3), np.cos(0.3), 0.0])  # the box's narrow side
    for c in narrow:
        assert abs(c.grasp[:3, 1] @ axis) == pytest.approx(1.0, abs=1e-9)
    # Wider than the gripper every way: the narrowest grasps stay, for the physics to decide.
    wide = grasp_candidates(_det("wide", (0.5, 0.3, 0.18)), WIDE, opening=0.08)
    assert wide and all(c.span == pytest.approx(0.09) for c in wide)


def test_tilted_grasps_never_lean_towards_the_robot():
    det = _det("bottle", (0.63, 0.6, 0.3))
    tilted = [c for c in grasp_candidates(det, BOTTLE) if c.family is GraspFamily.TILTED]
    assert tilted
    outward = np.array([0.63, 0.6, 0.0]) / np.hypot(0.63, 0.6)
    for c in tilted:
        approach = c.grasp[:3, 2]
        assert approach[2] < 0 and approach @ outward >= -1e-9
        assert abs(c.grasp[2, 1]) < 1e-9


@pytest.mark.parametrize(
    "family", [f for f in GraspFamily if f is not GraspFamily.PINCH]
)  # pinch: test_slide
def test_place_pose_sets_the_object_upright_on_the_spot(family):
    det = _det("bottle", (0.5, 0.3, 0.24), yaw=0.2)
    cand = next(c for c in grasp_candidates(det, BOTTLE) if c.family is family)
    params = GraspParams()
    for turn in (0.0, -1.2, 0.7):
        ee = place_pose((0.49, -0.42, 0.0), BOTTLE, cand.object_in_ee, cand.grasp, turn, params)
        obj = ee @ cand.object_in_ee
        assert np.allclose(obj[:3, 3], [0.49, -0.42, params.place_drop + BOTTLE.height / 2])
        assert obj[2, 2] == pytest.approx(1.0)
    assert np.allclose(object_pose(det, BOTTLE)[:3, 3], [0.5, 0.3, 0.24 - BOTTLE.height / 2])


def test_grasp_settings_come_from_the_robot_file_section():
    params = GraspParams.from_section({"yaw_step_deg": 30, "side_grasps": False, "tilts_deg": [20]}, "r.yaml")
    assert params.yaw_step == pytest.approx(np.pi / 6) and not params.side_grasps
    assert params.tilts == pytest.approx((np.radians(20),))
    with pytest.raises(
        ConfigError, match=r"r\.yaml: grasp\.yaw_step is not a grasp setting; valid: .*yaw_step_deg"
    ):
        GraspParams.from_section({"yaw_step": 0.3}, "r.yaml")
    with pytest.raises(ConfigError, match="grasp.approach must be non-negative"):
        GraspParams.from_section({"approach": -0.1}, "r.yaml")
    with pytest.raises(ConfigError, match="grasp.side_grasps must be true or false"):
        GraspParams.from_section({"side_grasps": "yes"}, "r.yaml")


def test_a_box_gets_off_centre_top_grasps_along_it_within_its_ends():
    params = GraspParams(offsets=(0.02, 0.035, 0.05))
    det = _det("box", (0.5, 0.3, 0.18))  # 7 cm along x, 5 cm along y
    tops = [c for c in grasp_candidates(det, BOX, params, opening=0.08) if c.family is GraspFamily.TOP]
    offsets = set()
    for c in tops:
        along = np.array([-np.sin(c.closing_yaw), np.cos(c.closing_yaw)])  # perpendicular to the closing axis
        off = c.grasp[:2, 3] - np.array([0.5, 0.3])
        assert abs(off @ c.grasp[:2, 1]) < 1e-9  # never along the closing axis: same faces, same span
        offsets.add((round(abs(float(off @ along)), 3), round(c.span, 3)))
    # Across the 5 cm side the box is 7 cm long: 2 cm fits (3.5 - 1.5 cm margin), 3.5 and 5 cm would leave it.
    assert offsets == {(0.0, 0.05), (0.02, 0.05), (0.0, 0.07)}
    centred = min(c.cost for c in tops if np.allclose(c.grasp[:2, 3], [0.5, 0.3]) and c.span < 0.06)
    assert all(c.cost > centred for c in tops if not np.allclose(c.grasp[:2, 3], [0.5, 0.3]))
    # A cylinder gripped off its axis would be held on a chord: none.
    bottle = grasp_candidates(_det("bottle", (0.5, 0.3, 0.24)), BOTTLE, params, opening=0.08)
    assert all(np.allclose(c.grasp[:2, 3], [0.5, 0.3]) for c in bottle if c.family is GraspFamily.TOP)


def test_side_grasps_come_at_both_depths_the_deeper_first():
    params = GraspParams(side_depth=0.045, side_shallow_depth=0.03)
    det = _det("box", (0.5, 0.3, 0.18))
    sides = [c for c in grasp_candidates(det, BOX, params, opening=0.08) if c.family is GraspFamily.SIDE]
    by_yaw: dict[float, list] = {}
    for c in sides:
        by_yaw.setdefault(round(c.closing_yaw, 6), []).append(c)
    assert by_yaw
    for group in by_yaw.values():
        approach = group[0].grasp[:3, 2]
        half = (abs(approach[0]) * BOX.size[0] + abs(approach[1]) * BOX.size[1]) / 2
        if half <= 0.03:  # thinner than the shallow depth: only the grasp at its centre
            assert len(group) == 1
            continue
        assert len(group) == 2
        deep, shallow = sorted(group, key=lambda c: c.cost)
        face_to_point = (deep.grasp[:3, 3] - shallow.grasp[:3, 3]) @ deep.grasp[:3, 2]
        # The deeper point is 1.5 cm farther along the approach (or at the centre, if the box is thinner).
        assert 0.0 < face_to_point <= 0.015 + 1e-9


def test_a_candidates_poses_are_made_when_asked_for_and_are_what_they_were():
    """The pre-grasp is `approach` back along the grasp's approach axis and the object's pose in the hand is the
    grasp's inverse times the object's: made on first access, then the same arrays."""
    cands = grasp_candidates(_det("box", (0.5, 0.1, 0.3), 0.4), BOX)
    assert cands and all("grasp" not in c.__dict__ for c in cands)
    cand = cands[0]
    grasp = cand.grasp
    assert np.array_equal(grasp[:3, :3], cand.rotation) and np.array_equal(grasp[:3, 3], cand.point)
    expected = grasp.copy()
    expected[:3, 3] -= grasp[:3, 2] * cand.approach
    assert np.array_equal(cand.pregrasp, expected)
    assert np.allclose(grasp @ cand.object_in_ee, cand.object_pose, atol=1e-12)
    assert cand.grasp is grasp and cand.object_in_ee is cand.object_in_ee
