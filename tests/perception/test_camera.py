"""Pinhole model of the simulated camera (no rendering)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from scone_bt.errors import ConfigError
from scone_bt.perception import Camera
from scone_bt.perception.camera import intrinsics, project, world_from_camera


def test_target_projects_to_the_image_centre(kitchen_cfg):
    spec = kitchen_cfg.camera
    uv, depth = project(np.array([spec.target]), intrinsics(spec), world_from_camera(spec))
    np.testing.assert_allclose(uv[0], [(spec.width - 1) / 2, (spec.height - 1) / 2], atol=1e-9)
    assert depth[0] == pytest.approx(np.linalg.norm(np.subtract(spec.target, spec.position)))


def test_pose_is_a_right_handed_rotation_with_up_pointing_up_the_image(kitchen_cfg):
    pose = world_from_camera(kitchen_cfg.camera)
    rot = pose[:3, :3]
    np.testing.assert_allclose(rot.T @ rot, np.eye(3), atol=1e-12)
    assert np.linalg.det(rot) == pytest.approx(1.0)
    assert rot[:, 1] @ np.array(kitchen_cfg.camera.up) < 0  # image y (down) points against world up


def _in_view(camera, points):
    uv, depth = project(points, camera.intrinsics, camera.world_from_camera)
    inside = (uv >= 0) & (uv <= [camera.spec.width - 1, camera.spec.height - 1])
    return (depth > 0) & inside.all(axis=1)


def test_every_shelf_slot_is_in_view_of_a_shelf_camera(kitchen_cfg):
    cameras = [Camera(spec) for spec in kitchen_cfg.shelf_cameras]
    assert len(cameras) >= 2
    for x, y, z in kitchen_cfg.scene.shelf_slots():
        lids = np.array([(x, y, z + h) for h in (0.02, 0.23)])  # a low lid and a tall bottle's
        assert any(_in_view(camera, lids).all() for camera in cameras), (x, y, z)


def test_the_whole_table_top_is_in_view_of_the_table_camera(kitchen_cfg):
    camera = Camera(kitchen_cfg.table_camera)
    top = kitchen_cfg.scene.table_top_z
    spots = np.array([(x, y, top + h) for x, y in kitchen_cfg.scene.place_spots for h in (0.02, 0.25)])
    assert _in_view(camera, spots).all()
    (cx, cy, _), (sx, sy, _) = kitchen_cfg.scene.table
    corners = np.array([(cx + a * sx / 2, cy + b * sy / 2, top) for a in (-1, 1) for b in (-1, 1)])
    assert _in_view(camera, corners).all()


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"width": 8}, "width"),
        ({"fov_deg": 0.0}, "fov_deg"),
        ({"near": 2.0, "far": 1.0}, "near"),
        ({"noise_std": -1.0}, "noise_std"),
        ({"up": (-0.5, 0.0, -0.85)}, "parallel"),
    ],
)
def test_bad_camera_specs_are_one_line_errors(kitchen_cfg, change, message):
    spec = replace(kitchen_cfg.camera, **change)
    if "up" in change:  # make the viewing direction parallel to up
        spec = replace(spec, up=tuple(np.subtract(spec.target, spec.position)))
    with pytest.raises(ConfigError, match=message):
        Camera(spec)


def test_a_render_is_reused_until_something_in_view_moves(kitchen_cfg, robot_cfg):
    from scone_bt.world import Kitchen

    with Kitchen(kitchen_cfg, robot_cfg) as kitchen:
        kitchen.spawn([kitchen_cfg.catalogue.get(n) for n in ("salt", "sugar")], np.random.default_rng(0))
        kitchen.advance(1.0)
        shelf = {spec.name: Camera(spec) for spec in kitchen_cfg.shelf_cameras}
        table = Camera(kitchen_cfg.table_camera)
        rng = np.random.default_rng(0)
        first = {name: cam.capture(kitchen, rng) for name, cam in shelf.items()}
        table.capture(kitchen, rng)
        kitchen.advance(1.0)
        again = {name: cam.capture(kitchen, rng) for name, cam in shelf.items()}
        assert all(cam.renders == 1 and cam.reuses == 1 for cam in shelf.values())
        assert all(np.array_equal(first[n].rgb, again[n].rgb) for n in shelf)
        assert again["shelf_front"].sim_time == kitchen.sim_time  # a reused render still has the frame's time

        assert kitchen.human_place_on_table("salt")
        kitchen.advance(1.0)
        for cam in shelf.values():
            cam.capture(kitchen, rng)
        table.capture(kitchen, rng)
        moved_from = next(n for n, cam in shelf.items() if cam.renders == 2)
        assert table.renders == 2  # the salt is in its view now
        assert sum(cam.renders for cam in shelf.values()) <= len(shelf) + 1, moved_from
