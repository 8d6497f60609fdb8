"""The simulated cameras render only the window of an image that changed, and it equals a whole render."""

import numpy as np
import pytest

from scone_bt.perception.camera import Camera
from scone_bt.world import camera as cam

MAX_CREEP_PIXELS = 40
"""Edge pixels a reused image (or a window's surroundings) may differ by: products creep by tenths of a millimetre,
under the reuse limits (`camera.REUSE_MAX_MOVE_M`), and a render now shows them there."""


def _full(kitchen, camera):
    return cam._render(kitchen, camera)


def _same_as_full(kitchen, camera, image):
    """The image equals a whole render now, up to products that crept by less than the reuse limits."""
    rgb, depth = _full(kitchen, camera)
    differ = np.any(image.rgb != rgb, axis=2)
    assert differ.sum() <= MAX_CREEP_PIXELS
    # A window's depth comes through another projection matrix (equal up to the depth buffer's rounding, micrometres
    # here); products that crept stand up to the reuse limit nearer or farther.
    error = np.abs(image.depth.astype(np.float64) - depth)[~differ]
    assert error.max() <= cam.REUSE_MAX_MOVE_M


@pytest.fixture
def stocked(kitchen, kitchen_cfg):
    names = kitchen_cfg.catalogue.names()[:12]
    kitchen.spawn([kitchen_cfg.catalogue.get(n) for n in names], np.random.default_rng(1))
    kitchen.advance(1.0)
    return kitchen, names


def test_taking_a_product_off_the_shelf_renders_a_window_equal_to_a_whole_render(stocked, kitchen_cfg):
    kitchen, names = stocked
    cameras = [Camera(spec) for spec in kitchen_cfg.cameras]
    for c in cameras:
        assert kitchen.camera_image(c).fresh  # the first image is always rendered whole
    stats = cam.render_stats()
    before = (stats.full, stats.windows, stats.pixels)
    assert kitchen.human_place_on_table(names[0])
    kitchen.advance(1.0)
    images = {c.spec.name: kitchen.camera_image(c) for c in cameras}
    assert stats.windows > before[1] and stats.full == before[0]
    # Two cameras changed (one shelf, the table): well under the pixels of two whole images.
    width, height = kitchen_cfg.camera.width, kitchen_cfg.camera.height
    assert stats.pixels - before[2] < 0.5 * 2 * width * height
    for c in cameras:
        _same_as_full(kitchen, c, images[c.spec.name])


def test_a_moving_arm_is_rendered_where_it_was_and_where_it_is(stocked, kitchen_cfg, robot_cfg):
    kitchen, _ = stocked
    cameras = [Camera(spec) for spec in kitchen_cfg.cameras]
    for c in cameras:
        kitchen.camera_image(c)
    kitchen.hold_arm([q + (0.5 if i in (0, 3) else 0.0) for i, q in enumerate(robot_cfg.home)])
    kitchen.advance(1.5)
    for c in cameras:
        _same_as_full(kitchen, c, kitchen.camera_image(c))


def test_an_unchanged_view_hands_back_the_same_arrays(stocked, kitchen_cfg):
    kitchen, _ = stocked
    camera = Camera(kitchen_cfg.camera)
    first = kitchen.camera_image(camera)
    kitchen.advance(0.5)
    again = kitchen.camera_image(camera)
    assert not again.fresh and again.rgb is first.rgb


def test_the_dirty_window_covers_the_projected_box_and_stays_in_the_image(kitchen_cfg):
    camera = Camera(kitchen_cfg.camera)
    spec = camera.spec
    box = np.array([[[0.45, 0.35, 0.30], [0.55, 0.45, 0.40]]])
    w = cam.dirty_window(camera, box)
    assert w is not None and 0 < w.pixels < spec.width * spec.height
    assert w.x0 >= 0 and w.x0 + w.width <= spec.width and w.y0 >= 0 and w.y0 + w.height <= spec.height
    behind = np.array([[[0.8, 0.3, 0.9], [1.0, 0.5, 1.1]]])  # around the camera itself
    assert cam.dirty_window(camera, behind) is None


def test_clearing_the_products_voids_every_render(kitchen, kitchen_cfg):
    state = kitchen.bc.saveState()
    kitchen.spawn([kitchen_cfg.catalogue.get("salt")], np.random.default_rng(0))
    camera = Camera(kitchen_cfg.camera)
    kitchen.camera_image(camera)
    uid = kitchen.uid
    kitchen.clear_products(state)
    assert kitchen.uid != uid
