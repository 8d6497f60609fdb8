"""The camera and detector on rendered PyBullet scenes (TinyRenderer, DIRECT mode)."""

from __future__ import annotations

import numpy as np
import pytest

from scone_bt.benchmarks.detection_scoring import ground_truth, score_frame
from scone_bt.perception import Camera, Detector, Tracker

pytestmark = pytest.mark.slow

# Five groups of five cover the whole catalogue; each group stands in a row on one step (no object hides another).
GROUP_PLACES = [(group, group % 3) for group in range(5)]


@pytest.mark.parametrize(("group", "tier"), GROUP_PLACES)
def test_every_catalogue_object_is_detected_in_a_clean_scene(staged_kitchen, kitchen_cfg, group, tier):
    names = kitchen_cfg.catalogue.names()[group * 5 : group * 5 + 5]
    kitchen = staged_kitchen({name: (tier, slot) for slot, name in enumerate(names)}, yaw=0.2)
    camera = Camera(kitchen_cfg.camera)
    frame = camera.capture(kitchen, np.random.default_rng(0))
    detections = Detector(kitchen_cfg.catalogue).detect(frame)
    truth = ground_truth(kitchen, camera)
    assert all(t.unoccluded for t in truth), "the clean scene must not hide any lid"
    score = score_frame(detections, truth)
    assert sorted(score.true_positives) == sorted(names)
    assert score.false_positives == ()
    # The position bound: the centre of each top face to within a centimetre, yaw from the marker.
    assert np.median(score.position_errors) <= 0.01
    assert max(score.position_errors) <= 0.02
    assert max(score.yaw_errors) <= np.radians(5)
    for det in detections:
        assert 0.0 < det.confidence <= 1.0
        x0, y0, x1, y1 = det.bbox
        assert 0 <= x0 < x1 < frame.rgb.shape[1] and 0 <= y0 < y1 < frame.rgb.shape[0]


def test_a_tall_bottle_hides_the_butter_behind_it(staged_kitchen, kitchen_cfg):
    """Documented occlusion: the camera looks down from behind the shelf (x > 0.7), so an object on a higher step
    stands between the camera and the step below it. Olive oil (22 cm) on the top step hides the lid of the
    butter (3 cm) on the middle step in the same row; with the bottle gone the butter is seen again."""
    kitchen = staged_kitchen({"olive oil": (2, 2), "butter": (1, 2)})
    camera, detector = Camera(kitchen_cfg.camera), Detector(kitchen_cfg.catalogue)
    rng = np.random.default_rng(0)

    truth = {t.name: t for t in ground_truth(kitchen, camera)}
    assert truth["butter"].in_view and truth["butter"].visible_fraction < 1.0
    seen = {d.name for d in detector.detect(camera.capture(kitchen, rng))}
    assert seen == {"olive oil"}

    assert kitchen.human_place_on_table("olive oil")
    kitchen.advance(0.3)
    seen = {d.name for d in detector.detect(camera.capture(kitchen, rng))}
    assert "butter" in seen


def test_heavy_pixel_noise_costs_detections_not_precision(staged_kitchen, kitchen_cfg):
    from dataclasses import replace

    names = ["black pepper", "chocolate", "cinnamon", "butter", "salt"]
    kitchen = staged_kitchen({name: (0, slot) for slot, name in enumerate(names)})
    detector = Detector(kitchen_cfg.catalogue)
    clean = detector.detect(Camera(kitchen_cfg.camera).capture(kitchen, np.random.default_rng(0)))
    noisy_camera = Camera(replace(kitchen_cfg.camera, noise_std=60.0))
    noisy = detector.detect(noisy_camera.capture(kitchen, np.random.default_rng(0)))
    assert len(noisy) < len(clean) == len(names)
    truth = ground_truth(kitchen, noisy_camera)
    assert score_frame(noisy, truth).false_positives == ()


def test_noise_is_seeded(kitchen, kitchen_cfg):
    from dataclasses import replace

    camera = Camera(replace(kitchen_cfg.camera, noise_std=8.0, depth_noise_std=0.002, width=160, height=120))
    a = camera.capture(kitchen, np.random.default_rng(3))
    b = camera.capture(kitchen, np.random.default_rng(3))
    c = camera.capture(kitchen, np.random.default_rng(4))
    assert np.array_equal(a.rgb, b.rgb) and np.array_equal(a.depth, b.depth)
    assert not np.array_equal(a.rgb, c.rgb)


def test_frame_matches_the_camera_spec(kitchen, kitchen_cfg):
    spec = kitchen_cfg.camera
    frame = Camera(spec).capture(kitchen, np.random.default_rng(0))
    assert frame.rgb.shape == (spec.height, spec.width, 3) and frame.rgb.dtype == np.uint8
    assert frame.depth.shape == (spec.height, spec.width) and frame.depth.dtype == np.float32
    assert spec.near <= float(frame.depth.min()) and float(frame.depth.max()) <= spec.far + 1e-3
    np.testing.assert_allclose(frame.world_from_camera[:3, 3], spec.position)
    assert frame.sim_time == kitchen.sim_time


def test_track_ids_survive_a_move_to_the_table(staged_kitchen, kitchen_cfg):
    kitchen = staged_kitchen({"sugar": (0, 1), "coffee": (2, 3)})
    camera, detector, tracker = Camera(kitchen_cfg.camera), Detector(kitchen_cfg.catalogue), Tracker()
    rng = np.random.default_rng(0)
    frame = camera.capture(kitchen, rng)
    first = {d.name: d.track_id for d in tracker.update(detector.detect(frame), frame.sim_time)}
    assert set(first) == {"sugar", "coffee"} and len(set(first.values())) == 2

    kitchen.human_place_on_table("coffee")
    kitchen.advance(0.3)
    frame = camera.capture(kitchen, rng)
    second = {d.name: d.track_id for d in tracker.update(detector.detect(frame), frame.sim_time)}
    assert "sugar" in second
    assert all(first[name] == track_id for name, track_id in second.items())
    assert tracker.tracks["coffee"].misses == (0 if "coffee" in second else 1)
