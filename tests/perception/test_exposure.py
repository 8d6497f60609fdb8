"""A longer look (perception.exposure): averaged frames have less noise, and a noisy camera that missed a spice
jar's marker in one frame finds it in the mean of `LOOK_AGAIN_EXPOSURES` (PyBullet, the generator's look)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from scone_bt.errors import ConfigError
from scone_bt.perception.exposure import LOOK_AGAIN_EXPOSURES, averaged
from scone_bt.perception.types import Frame

PROFILES = Path(__file__).resolve().parents[2] / "tools" / "profiles"


def _frame(rgb: np.ndarray, depth: np.ndarray, x: float = 0.0) -> Frame:
    pose = np.eye(4)
    pose[0, 3] = x
    return Frame(rgb=rgb, depth=depth, intrinsics=np.eye(3), world_from_camera=pose, sim_time=1.5)


def test_the_mean_of_n_noisy_frames_has_about_one_over_root_n_of_the_noise() -> None:
    rng = np.random.default_rng(0)
    clean_rgb = np.full((60, 80, 3), 128.0)
    clean_depth = np.full((60, 80), 1.0, dtype=np.float32)

    def noisy() -> Frame:
        rgb = np.clip(np.rint(clean_rgb + rng.normal(0, 45, clean_rgb.shape)), 0, 255).astype(np.uint8)
        depth = (clean_depth + rng.normal(0, 0.004, clean_depth.shape)).astype(np.float32)
        return _frame(rgb, depth)

    one = noisy()
    mean = averaged([noisy() for _ in range(LOOK_AGAIN_EXPOSURES)])
    ratio = np.std(mean.rgb.astype(float)) / np.std(one.rgb.astype(float))
    assert ratio == pytest.approx(1 / np.sqrt(LOOK_AGAIN_EXPOSURES), rel=0.15)
    assert np.std(mean.depth) < 0.5 * np.std(one.depth)
    assert mean.rgb.dtype == np.uint8 and mean.depth.dtype == np.float32 and mean.sim_time == 1.5


def test_one_frame_is_its_own_mean_and_frames_of_other_cameras_are_refused() -> None:
    rgb, depth = np.zeros((4, 4, 3), np.uint8), np.ones((4, 4), np.float32)
    only = _frame(rgb, depth)
    assert averaged([only]) is only
    with pytest.raises(ConfigError, match="different cameras"):
        averaged([only, _frame(rgb, depth, x=0.5)])
    with pytest.raises(ConfigError, match="no frame"):
        averaged([])


@pytest.mark.slow
def test_a_noisy_camera_finds_in_the_longer_look_the_jar_it_missed_in_one_frame(
    kitchen_cfg, robot_cfg
) -> None:
    """Execution 20 of ``p04_noisy_camera`` (the development stream): the citric acid's marker is lost in one
    frame's noise; the generator, as the tree, looks again and perceives it (its context measured in the mean)."""
    from scone_bt.benchmarks.self_confidence import generate
    from scone_bt.benchmarks.self_confidence.profiles import load_profile

    noisy = load_profile(PROFILES / "p04_noisy_camera.yaml")
    seed = noisy.execution_seed(20)
    target, others = generate._objects(noisy, 20, kitchen_cfg, None, None)
    assert target.name == "citric acid"
    rng = np.random.default_rng([seed, 1])
    injected = noisy.draw_injections(target, rng)
    kcfg, rcfg = generate._configs(noisy, kitchen_cfg, robot_cfg, injected)
    kitchen = generate._WORKER.empty_kitchen(kcfg, rcfg)
    kitchen.spawn([target, *others], rng)
    one, _ = generate._look(kitchen, kcfg, seed)
    longer, _ = generate._look(kitchen, kcfg, seed, LOOK_AGAIN_EXPOSURES)
    assert target.name not in one and target.name in longer
    assert set(one) <= set(longer)  # what one frame saw, the mean sees too
    seen = generate._perceive(kitchen, kcfg, seed, noisy, target.name, injected)
    assert seen.context.detected and seen.context.detected_width_m == pytest.approx(target.size[0], abs=0.01)
