"""The simulated cameras render only the window of an image that changed, and it equals a whole render."""

import numpy as np
import pytest

from scone_bt.perception.camera import Camera
from scone_bt.world import camera as cam


def _rgb_matches(image, reference):
    """Equal but for a rare pixel on a triangle's edge that rounds to the other side (a handful per image)."""
    assert np.count_nonzero(np.any(image != reference, axis=-1)) <= 5


def _window_of(kitchen, camera, before):
    """A fresh image of ``camera`` that must be patched windows: it equals a whole render inside the windows and
    the image before it everywhere else."""
    image = kitchen.camera_image(camera)
    windows = cam.render_stats().last_windows
    assert image.fresh and windows
    rgb, depth = cam._render(kitchen, camera)
    inside = np.zeros(rgb.shape[:2], dtype=bool)
    for w in windows:
        inside[w.y0 : w.y0 + w.height, w.x0 : w.x0 + w.width] = True
    _rgb_matches(image.rgb[inside], rgb[inside])
    # Through another projection matrix the depth buffer rounds differently: micrometres at these distances.
    same = inside & np.all(image.rgb == rgb, axis=-1)
    assert np.abs(image.depth[same].astype(np.float64) - depth[same]).max() < 2e-5
    assert np.array_equal(image.rgb[~inside], before.rgb[~inside])
    assert np.array_equal(image.depth[~inside], before.depth[~inside])
    return image


@pytest.fixture
def stocked(kitchen, kitchen_cfg):
    names = kitchen_cfg.catalogue.names()[:12]
    kitchen.spawn([kitchen_cfg.catalogue.get(n) for n in names], np.random.default_rng(1))
    kitchen.advance(1.0)
    return kitchen, names


def test_taking_a_product_off_the_shelf_renders_only_the_window_that_changed(stocked, kitchen_cfg):
    kitchen, names = stocked
    shelf = Camera(kitchen_cfg.camera)
    table = Camera(kitchen_cfg.table_camera)
    before = {c: kitchen.camera_image(c) for c in (shelf, table)}
    assert all(image.fresh for image in before.values())  # the first image is always rendered whole
    name = next(n for n in names if cam.box_in_view(shelf, *kitchen.bc.getAABB(kitchen.objects[n])))
    stats = cam.render_stats()
    pixels = stats.pixels
    assert kitchen.human_place_on_table(name)
    kitchen.advance(1.0)
    for c in (shelf, table):
        _window_of(kitchen, c, before[c])
    # One product left the shelf camera's view and came into the table camera's: a few percent of two images.
    assert stats.pixels - pixels < 0.2 * 2 * shelf.spec.width * shelf.spec.height


def test_a_moving_arm_is_rendered_where_it_was_and_where_it_is(stocked, kitchen_cfg, robot_cfg):
    kitchen, _ = stocked
    table = Camera(kitchen_cfg.table_camera)
    before = kitchen.camera_image(table)
    # Swing the arm over the table: a window covers the links where they were (out of view) and where they are.
    kitchen.hold_arm([q + {0: -0.9, 1: 0.4}.get(i, 0.0) for i, q in enumerate(robot_cfg.home)])
    kitchen.advance(1.0)
    _window_of(kitchen, table, before)


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


def test_a_restocked_kitchen_patches_its_first_images_over_the_empty_kitchen(kitchen, kitchen_cfg):
    start = kitchen.bc.saveState()
    names = kitchen_cfg.catalogue.names()
    cameras = [Camera(spec) for spec in kitchen_cfg.shelf_cameras]
    stats = cam.render_stats()
    for batch in (names[:6], names[6:12]):
        kitchen.spawn([kitchen_cfg.catalogue.get(n) for n in batch], np.random.default_rng(4))
        for c in cameras:
            windows = stats.windows
            image = kitchen.camera_image(c)
            rgb, depth = cam._render(kitchen, c)
            assert image.fresh
            _rgb_matches(image.rgb, rgb)
            same = np.all(image.rgb == rgb, axis=-1)  # an edge pixel that rounded the other way has its depth
            assert np.abs(image.depth.astype(np.float64) - depth)[same].max() < 2e-5
            if any(cam.box_in_view(c, *kitchen.bc.getAABB(b)) for b in kitchen.objects.values()):
                assert stats.windows > windows  # only the products were rendered
        kitchen.clear_products(start)


def test_far_apart_boxes_get_a_window_each_and_near_ones_one(kitchen_cfg):
    camera = Camera(kitchen_cfg.camera)
    spec = camera.spec
    a = [[0.45, 0.20, 0.00], [0.50, 0.25, 0.10]]
    b = [[0.60, 0.60, 0.12], [0.65, 0.65, 0.22]]  # the stand's other end, a tier up
    near_a = [[0.45, 0.255, 0.00], [0.50, 0.30, 0.10]]  # beside a
    apart = cam.dirty_windows(camera, np.array([a, b]))
    assert apart is not None and len(apart) == 2
    around = cam.dirty_window(camera, np.array([a, b]))
    assert sum(w.pixels for w in apart) + cam.WINDOW_COST_PX < around.pixels
    for w in apart:  # each inside the image and inside the one window around both
        assert w.x0 >= 0 and w.x0 + w.width <= spec.width and w.y0 >= 0 and w.y0 + w.height <= spec.height
        assert around.x0 <= w.x0 and w.x0 + w.width <= around.x0 + around.width
    together = cam.dirty_windows(camera, np.array([a, near_a]))
    assert together is not None and len(together) == 1
    assert (
        cam.dirty_windows(camera, np.array([[[-1.0, 3.0, 0.0], [-0.9, 3.1, 0.1]]])) == []
    )  # beside the view


def test_products_far_apart_are_patched_in_several_windows_equal_to_a_whole_render(stocked, kitchen_cfg):
    kitchen, names = stocked
    shelf = Camera(kitchen_cfg.camera)
    before = kitchen.camera_image(shelf)
    in_view = [n for n in names if cam.box_in_view(shelf, *kitchen.bc.getAABB(kitchen.objects[n]))]
    # The first and the last product the camera sees (far apart on the stand) go to the table.
    for name in (in_view[0], in_view[-1]):
        assert kitchen.human_place_on_table(name)
    kitchen.advance(1.0)
    windows = cam.render_stats().windows
    _window_of(kitchen, shelf, before)
    assert len(cam.render_stats().last_windows) >= 2 and cam.render_stats().windows >= windows + 2


def test_a_second_kitchen_of_the_same_scene_patches_its_first_images_over_the_empty_kitchen(
    kitchen_cfg, robot_cfg
):
    from scone_bt.world import Kitchen

    names = kitchen_cfg.catalogue.names()[12:20]
    shelf = Camera(kitchen_cfg.camera)
    stats = cam.render_stats()
    with Kitchen(kitchen_cfg, robot_cfg) as first:
        first.spawn([kitchen_cfg.catalogue.get(n) for n in names[:4]], np.random.default_rng(5))
        first.camera_image(shelf)
    with Kitchen(kitchen_cfg, robot_cfg) as second:
        assert second.static_key == first.static_key and second.keep_backgrounds
        second.spawn([kitchen_cfg.catalogue.get(n) for n in names[4:]], np.random.default_rng(6))
        full = stats.full
        image = second.camera_image(shelf)
        assert stats.full == full and stats.last_windows  # patched, not rendered whole
        rgb, depth = cam._render(second, shelf)
        _rgb_matches(image.rgb, rgb)
        same = np.all(image.rgb == rgb, axis=-1)
        assert np.abs(image.depth.astype(np.float64) - depth)[same].max() < 2e-5
        # A cover makes a scene of its own: no background of the plain scene applies.
        second.add_cover((0.5, 0.4, 0.3), (0.05, 0.05, 0.05))
        assert second.static_key != first.static_key


def test_a_kitchen_sees_the_same_first_images_whether_or_not_one_came_before(kitchen_cfg, robot_cfg):
    from scone_bt.world import Kitchen

    # A whole render and a patched one differ by an edge pixel: every kitchen patches, the first one too, so
    # an episode's images do not depend on what ran before it in the process.
    names = kitchen_cfg.catalogue.names()[20:28]
    images = []
    for _ in range(2):
        with Kitchen(kitchen_cfg, robot_cfg) as k:
            k.spawn([kitchen_cfg.catalogue.get(n) for n in names], np.random.default_rng(7))
            images.append([k.camera_image(Camera(spec)) for spec in kitchen_cfg.cameras])
    for a, b in zip(*images, strict=True):
        assert np.array_equal(a.rgb, b.rgb) and np.array_equal(a.depth, b.depth)
