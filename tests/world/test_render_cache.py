"""The empty kitchen's images kept on disk: read back equal to a render, in another process too, and never stale."""

import os
import subprocess
import sys

import numpy as np
import pytest

from scone_bt.perception.camera import Camera
from scone_bt.world import camera as cam
from scone_bt.world import render_cache


@pytest.fixture
def store(tmp_path, monkeypatch):
    """An empty cache directory of its own, and no background of this process kept in memory."""
    monkeypatch.setenv("SCONE_BT_CACHE", str(tmp_path))
    monkeypatch.delenv(render_cache.RENDER_CACHE_ENV, raising=False)
    monkeypatch.setattr(cam, "_BACKGROUNDS", {})
    return tmp_path / "renders"


def _stocked(kitchen_cfg, robot_cfg):
    from scone_bt.world import Kitchen

    k = Kitchen(kitchen_cfg, robot_cfg)
    k.spawn(
        [kitchen_cfg.catalogue.get(n) for n in kitchen_cfg.catalogue.names()[:3]], np.random.default_rng(3)
    )
    return k


def _backgrounds(kitchen, kitchen_cfg):
    return [cam._BACKGROUNDS[(kitchen.static_key, cam._geometry(Camera(s)))] for s in kitchen_cfg.cameras]


def test_a_stored_background_is_read_back_instead_of_rendered_and_equals_a_render(
    store, kitchen_cfg, robot_cfg
):
    stats = cam.render_stats()
    full, loaded = stats.full, stats.backgrounds_loaded
    with _stocked(kitchen_cfg, robot_cfg):
        pass
    n = len(kitchen_cfg.cameras)
    assert stats.full == full + n and stats.backgrounds_loaded == loaded
    assert len(list(store.glob("background-*.npz"))) == n
    cam._BACKGROUNDS.clear()  # as in a fresh process
    with _stocked(kitchen_cfg, robot_cfg) as k:
        assert stats.full == full + n and stats.backgrounds_loaded == loaded + n
        kept = _backgrounds(k, kitchen_cfg)
        for _, rgb, depth in kept:
            assert not rgb.flags.writeable and not depth.flags.writeable
        # Rendered now, with the products removed again: the same pixels and depths, bit for bit.
        for name in list(k.objects):
            k.bc.removeBody(k.objects.pop(name))
        for camera_spec, (_, rgb, depth) in zip(kitchen_cfg.cameras, kept, strict=True):
            fresh_rgb, fresh_depth = cam._render(k, Camera(camera_spec))
            assert np.array_equal(rgb, fresh_rgb) and np.array_equal(depth, fresh_depth)


def test_another_process_reads_the_backgrounds_this_one_rendered(store, kitchen_cfg, robot_cfg):
    with _stocked(kitchen_cfg, robot_cfg) as k:
        mine = [(rgb.copy(), depth.copy()) for _, rgb, depth in _backgrounds(k, kitchen_cfg)]
    script = (
        "import numpy as np; from scone_bt.config import load_kitchen, load_robot; from scone_bt.world import Kitchen;"
        "from scone_bt.world import camera as cam; from scone_bt.perception.camera import Camera;"
        "kc, rc = load_kitchen('kitchen'), load_robot('panda'); k = Kitchen(kc, rc);"
        "k.spawn([kc.catalogue.get(n) for n in kc.catalogue.names()[:3]], np.random.default_rng(3));"
        "print(cam.render_stats().full, cam.render_stats().backgrounds_loaded);"
        "[np.save(f'{i}-rgb.npy', cam._BACKGROUNDS[(k.static_key, cam._geometry(Camera(s)))][1]) "
        " for i, s in enumerate(kc.cameras)]"
    )
    out = subprocess.run(
        [sys.executable, "-c", script],
        cwd=store.parent,
        env=os.environ.copy(),
        capture_output=True,
        text=True,
    )
    assert out.returncode == 0, out.stderr
    full, loaded = map(int, out.stdout.split()[-2:])
    assert (full, loaded) == (0, len(kitchen_cfg.cameras))
    for i, (rgb, _) in enumerate(mine):
        assert np.array_equal(np.load(store.parent / f"{i}-rgb.npy"), rgb)


def test_the_digest_follows_what_the_renderer_is_given(store, kitchen, kitchen_cfg, robot_cfg):
    shelf = cam._geometry(Camera(kitchen_cfg.camera))
    table = cam._geometry(Camera(kitchen_cfg.table_camera))
    before = render_cache.background_digest(kitchen, shelf, cam.__file__)
    assert (
        render_cache.background_digest(kitchen, shelf, cam.__file__) == before
    )  # the same world, the same digest
    assert render_cache.background_digest(kitchen, table, cam.__file__) != before  # another camera
    # The arm one joint a little turned: every link after it is elsewhere.
    joint = kitchen.joint_index[robot_cfg.arm_joints[0]]
    q = kitchen.bc.getJointState(kitchen.robot_id, joint)[0]
    kitchen.bc.resetJointState(kitchen.robot_id, joint, q + 1e-6)
    turned = render_cache.background_digest(kitchen, shelf, cam.__file__)
    assert turned != before
    kitchen.bc.resetJointState(kitchen.robot_id, joint, q)
    assert render_cache.background_digest(kitchen, shelf, cam.__file__) == before
    # A body more, or a colour changed.
    import pybullet as p

    box = kitchen.bc.createMultiBody(0, -1, kitchen.bc.createVisualShape(p.GEOM_BOX, halfExtents=[0.1] * 3))
    assert render_cache.background_digest(kitchen, shelf, cam.__file__) not in (before, turned)
    kitchen.bc.removeBody(box)
    assert render_cache.background_digest(kitchen, shelf, cam.__file__) == before
    kitchen.bc.changeVisualShape(kitchen.bc.getBodyUniqueId(0), -1, rgbaColor=[0.1, 0.2, 0.3, 1.0])
    assert render_cache.background_digest(kitchen, shelf, cam.__file__) != before


def test_the_rendering_code_is_part_of_the_digest(store, kitchen, kitchen_cfg, monkeypatch):
    shelf = cam._geometry(Camera(kitchen_cfg.camera))
    before = render_cache.background_digest(kitchen, shelf, cam.__file__)
    real = render_cache._file_digest
    monkeypatch.setattr(
        render_cache,
        "_file_digest",
        lambda path: "edited" if os.fsdecode(path) == cam.__file__ else real(path),
    )
    assert render_cache.background_digest(kitchen, shelf, cam.__file__) != before


def test_a_damaged_file_is_rendered_again_and_replaced(store, kitchen_cfg, robot_cfg):
    with _stocked(kitchen_cfg, robot_cfg):
        pass
    files = sorted(store.glob("background-*.npz"))
    files[0].write_bytes(b"not an npz")
    files[1].write_bytes(files[1].read_bytes()[:5000])  # a zip cut short
    cam._BACKGROUNDS.clear()
    stats = cam.render_stats()
    full, loaded = stats.full, stats.backgrounds_loaded
    with _stocked(kitchen_cfg, robot_cfg):
        pass
    assert (stats.full - full, stats.backgrounds_loaded - loaded) == (2, len(files) - 2)
    for f in files[:2]:
        assert np.load(f)["rgb"].shape[2] == 3  # written anew


def test_an_unwritable_cache_or_switched_off_cache_renders_as_before(
    tmp_path, monkeypatch, kitchen_cfg, robot_cfg
):
    monkeypatch.setattr(cam, "_BACKGROUNDS", {})
    blocked = tmp_path / "file"
    blocked.write_text("a file where the cache folder would be")
    monkeypatch.setenv("SCONE_BT_CACHE", str(blocked))
    stats = cam.render_stats()
    full = stats.full
    with _stocked(kitchen_cfg, robot_cfg):
        pass
    assert stats.full == full + len(kitchen_cfg.cameras)
    monkeypatch.setenv("SCONE_BT_CACHE", str(tmp_path / "cache"))
    monkeypatch.setenv(render_cache.RENDER_CACHE_ENV, "0")
    cam._BACKGROUNDS.clear()
    with _stocked(kitchen_cfg, robot_cfg):
        pass
    assert not (tmp_path / "cache").exists()
    assert stats.full == full + 2 * len(kitchen_cfg.cameras)


def test_a_covered_scene_is_not_stored(store, kitchen, kitchen_cfg):
    kitchen.add_cover((0.5, 0.4, 0.3), (0.05, 0.05, 0.05))
    cam.keep_background(kitchen, Camera(kitchen_cfg.camera))
    assert not store.exists() or not list(store.glob("background-*.npz"))


def test_the_oldest_backgrounds_go_beyond_the_limit(store, monkeypatch):
    monkeypatch.setattr(render_cache, "MAX_FILES", 2)
    rgb, depth = np.zeros((4, 6, 3), np.uint8), np.ones((4, 6), np.float32)
    for k, digest in enumerate(("a", "b", "c")):
        assert render_cache.save_background(digest, rgb, depth)
        path = store / f"background-{digest}.npz"
        os.utime(path, ns=(k * 10**9, k * 10**9))  # written in this order
    assert sorted(f.name for f in store.glob("*.npz")) == ["background-b.npz", "background-c.npz"]
    loaded = render_cache.load_background("c", 6, 4)
    assert loaded is not None and np.array_equal(loaded[1], depth)
    assert render_cache.load_background("c", 7, 4) is None  # not the size asked for
