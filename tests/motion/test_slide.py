"""Slide and pinch (`motion.slide`): which packs it takes, how far it slides them, where it pinches and puts them
down; and, in PyBullet, a meat tray slid off the back of its tier, pinched and put on the table."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from scone_bt.config import load_kitchen
from scone_bt.motion.grasp import GraspFamily
from scone_bt.motion.ledge import ledge_of
from scone_bt.motion.placement import TableRegion
from scone_bt.motion.slide import (
    SLIDE_SETTINGS,
    front_face,
    pinch_candidates,
    pinch_placements,
    slide_distance,
    slide_ledge,
)
from scone_bt.perception.types import Detection

KITCHEN = load_kitchen("perception/kitchen.yaml")
TRAY = KITCHEN.catalogue.get("chicken breast")  # 20 x 14 x 4 cm
FRONT = KITCHEN.scene.shelves[0]  # u along world x; the lowest tier's front edge at u = 0.305


def _on_front(u: float, yaw: float, spec=TRAY, tier: int = 0) -> Detection:
    t = FRONT.tiers[tier]
    x, y = FRONT.to_world(u, 0.40)
    return Detection(spec.name, 1, (x, y, t.top_z + spec.height), yaw, 1.0, (0, 0, 1, 1))


def test_only_a_flat_pack_wider_than_the_gripper_on_a_lowest_tier_is_slid():
    square = math.pi / 2  # the tray's 14 cm across the tier, its 20 cm along it
    assert slide_ledge(_on_front(0.37, square), TRAY, 0.08, KITCHEN.scene) is not None
    assert slide_ledge(_on_front(0.50, square, tier=1), TRAY, 0.08, KITCHEN.scene) is None
    assert slide_ledge(_on_front(0.37, square), TRAY, 0.16, KITCHEN.scene) is None  # a wide gripper spans it
    jar = KITCHEN.catalogue.get("peanut butter")
    assert slide_ledge(_on_front(0.37, 0.0, jar), jar, 0.08, KITCHEN.scene) is None


def test_the_slide_brings_the_front_face_out_by_the_overhang_and_keeps_the_pack_on_its_tier():
    ledge = ledge_of(KITCHEN.scene, (0.37, 0.40, 0.0))
    assert ledge is not None and ledge.front_u == pytest.approx(0.305)
    centred = _on_front(0.37, math.pi / 2)
    face = front_face(centred, TRAY, ledge)
    assert face.overhang == pytest.approx(0.305 - (0.37 - 0.07))  # its 14 cm across the tier
    assert slide_distance(centred, TRAY, ledge) == pytest.approx(SLIDE_SETTINGS.overhang_m - face.overhang)
    # already sticking out: pinched as it stands; near the edge: slid only as far as keeps its centre on
    assert slide_distance(_on_front(0.33, math.pi / 2), TRAY, ledge) == 0.0  # out 4.5 cm
    assert slide_distance(_on_front(0.36, 0.0), TRAY, ledge) == 0.0  # its 20 cm across: out 4.5 cm already
    farther = dataclasses.replace(
        SLIDE_SETTINGS, overhang_m=0.10
    )  # never so far that its centre nears the edge
    assert slide_distance(centred, TRAY, ledge, farther) == pytest.approx(0.37 - 0.305 - farther.keep_on_m)


def test_a_turned_pack_is_pinched_square_to_its_face_with_the_fingers_closing_vertically():
    ledge = ledge_of(KITCHEN.scene, (0.30, 0.40, 0.0))
    yaw = math.pi / 2 + math.radians(
        14
    )  # stocked a little off the tier's line: its frontmost point is a corner
    det = _on_front(0.30, yaw)
    cands = pinch_candidates(det, TRAY, ledge, approach=0.1)
    assert cands and all(c.family is GraspFamily.PINCH for c in cands)
    first = cands[0]
    assert abs(first.grasp[2, 1]) == pytest.approx(1.0)  # closing along world z
    approach = first.grasp[:3, 2]
    assert approach[2] == pytest.approx(0.0)
    assert math.atan2(approach[1], approach[0]) == pytest.approx(
        math.remainder(yaw - math.pi / 2, 2 * math.pi)
    )
    assert first.span == pytest.approx(TRAY.height)
    # inside the pack by the pads' inset, along the face's centre line
    face = front_face(det, TRAY, ledge)
    assert np.linalg.norm(first.point - face.centre) == pytest.approx(SLIDE_SETTINGS.pad_inset_m)
    # a pack that does not stick out is not pinched
    assert pinch_candidates(_on_front(0.37, math.pi / 2), TRAY, ledge, approach=0.1) == []


def test_a_pinched_pack_is_put_down_sticking_out_over_a_table_edge_the_hand_outside():
    ledge = ledge_of(KITCHEN.scene, (0.30, 0.40, 0.0))
    cand = pinch_candidates(_on_front(0.30, math.pi / 2), TRAY, ledge, approach=0.1)[0]
    table = TableRegion.from_scene(KITCHEN.scene)
    spots = pinch_placements(table, TRAY, cand, np.zeros(3))
    assert spots
    base_dist = [math.hypot(s[0], s[1]) for s, _ in spots]
    assert base_dist == sorted(base_dist)
    (cx, cy), (sx, sy) = table.center, table.size
    for (x, y, z), turn in spots:
        assert z == table.top_z
        ee = cand.grasp.copy()
        c, s = math.cos(turn), math.sin(turn)
        approach = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]) @ cand.grasp[:3, 2]
        # the pack's centre inside the table, its edge the overhang beyond it, square to the edge crossed
        assert abs(x - cx) < sx / 2 and abs(y - cy) < sy / 2
        near = np.array([x, y]) - approach[:2] * 0.07
        outside = max(abs(near[0] - cx) - sx / 2, abs(near[1] - cy) - sy / 2)
        assert outside == pytest.approx(SLIDE_SETTINGS.table_overhang_m, abs=1e-6)
        del ee


@pytest.mark.slow
def test_pybullet_slides_a_tray_off_the_back_of_its_tier_pinches_it_and_puts_it_on_the_table():
    from scone_bt.benchmarks.self_confidence.generate import run_execution
    from scone_bt.benchmarks.self_confidence.profiles import load_profile
    from scone_bt.config.grasp import GraspParams
    from scone_bt.config.robot import load_robot

    robot = load_robot("panda")  # robots/panda.yaml slides and pinches
    assert GraspParams.of(robot).slide_pinch
    without = dataclasses.replace(robot, grasp=dataclasses.replace(GraspParams.of(robot), slide_pinch=False))
    profile = load_profile("tools/profiles/p00_nominal.yaml")
    rec, _ = run_execution(profile, 0, KITCHEN, robot, target_name="chicken breast")
    assert rec.shelf_tier == 0 and rec.success, rec.detail
    assert "slid towards me and pinched by its edge" in rec.detail
    # the same execution without the skill: the narrowest grasp is tried, and the tray slips out
    rec, _ = run_execution(profile, 0, KITCHEN, without, target_name="chicken breast")
    assert not rec.success and "slid" not in rec.detail
