"""The robot's view of the table comes from its table camera alone (PyBullet DIRECT, TinyRenderer)."""

from __future__ import annotations

import numpy as np
import pytest

from scone_bt.perception.observe import Observer, free_place_spots, merge_detections
from scone_bt.perception.types import Detection

pytestmark = pytest.mark.slow


def _kitchen_with_table_products(kitchen_cfg, robot_cfg, names):
    from scone_bt.world import Kitchen

    kitchen = Kitchen(kitchen_cfg, robot_cfg)
    kitchen.spawn([kitchen_cfg.catalogue.get(n) for n in names], np.random.default_rng(0))
    for name in names[1:]:
        assert kitchen.human_place_on_table(name)
    kitchen.advance(0.5)
    return kitchen


def _cover_lens(kitchen, camera_spec) -> None:
    """An opaque card just in front of the camera, as if someone covered it."""
    import pybullet as p

    eye, target = np.asarray(camera_spec.position), np.asarray(camera_spec.target)
    centre = eye + 0.1 * (target - eye) / np.linalg.norm(target - eye)
    card = kitchen.bc.createVisualShape(
        p.GEOM_BOX, halfExtents=[0.1, 0.1, 0.002], rgbaColor=[0.2, 0.2, 0.2, 1]
    )
    kitchen.bc.createMultiBody(0, -1, card, basePosition=centre.tolist())


def test_table_detections_are_what_the_table_camera_sees(kitchen_cfg, robot_cfg):
    names = ["salt", "sugar", "honey"]
    with _kitchen_with_table_products(kitchen_cfg, robot_cfg, names) as kitchen:
        seen = Observer(kitchen_cfg).observe(kitchen, np.random.default_rng(0))
        assert sorted(d.name for d in seen.table_detections) == ["honey", "sugar"]
        assert "salt" in {d.name for d in seen.detections}  # still on the shelf
        for det in seen.table_detections:
            true = kitchen.object_state(det.name).position
            assert np.hypot(det.position[0] - true[0], det.position[1] - true[1]) < 0.01
        free = free_place_spots(seen.table_detections, kitchen_cfg.scene)
        assert len(free) == len(kitchen_cfg.scene.place_spots) - 2
        assert kitchen.free_place_spot() == free[0]  # the camera agrees with the truth


def test_a_covered_table_camera_sees_an_empty_table(kitchen_cfg, robot_cfg):
    names = ["salt", "sugar", "honey"]
    with _kitchen_with_table_products(kitchen_cfg, robot_cfg, names) as kitchen:
        _cover_lens(kitchen, kitchen_cfg.table_camera)
        seen = Observer(kitchen_cfg).observe(kitchen, np.random.default_rng(0))
        assert seen.table_detections == ()
        # The robot now believes the first spot is free; the truth says it is taken.
        free = free_place_spots(seen.table_detections, kitchen_cfg.scene)
        assert len(free) == len(kitchen_cfg.scene.place_spots)
        assert kitchen.free_place_spot() != free[0]


def test_without_a_table_camera_the_table_is_unknown(kitchen_cfg, robot_cfg):
    with _kitchen_with_table_products(kitchen_cfg, robot_cfg, ["salt", "sugar"]) as kitchen:
        seen = Observer(kitchen_cfg, table_camera=False).observe(kitchen, np.random.default_rng(0))
        assert seen.table_detections == () and "sugar" not in {d.name for d in seen.detections}


def test_merge_keeps_the_most_confident_detection_per_name():
    a = Detection("salt", -1, (0.0, 0.0, 0.0), 0.0, 0.4, (0, 0, 1, 1))
    b = Detection("salt", -1, (0.1, 0.0, 0.0), 0.0, 0.9, (0, 0, 1, 1))
    c = Detection("flour", -1, (0.2, 0.0, 0.0), 0.0, 0.5, (0, 0, 1, 1))
    assert merge_detections([[a, c], [b]]) == [c, b]


def test_an_unchanged_view_is_not_detected_again(kitchen_cfg, robot_cfg):
    with _kitchen_with_table_products(kitchen_cfg, robot_cfg, ["salt", "sugar"]) as kitchen:
        observer = Observer(kitchen_cfg)
        calls = []
        detect = observer.detector.detect
        observer.detector.detect = lambda frame: calls.append(frame) or detect(frame)
        rng = np.random.default_rng(0)
        first = observer.observe(kitchen, rng)
        kitchen.advance(1.0)
        second = observer.observe(kitchen, rng)
        assert len(calls) == len(observer.cameras)  # the second look reused every camera's answer
        assert [d.name for d in second.detections] == [d.name for d in first.detections]
        assert kitchen.human_place_on_table("salt")
        kitchen.advance(1.0)
        third = observer.observe(kitchen, rng)
        assert len(calls) > len(observer.cameras)
        assert {d.name for d in third.table_detections} == {"salt", "sugar"}
