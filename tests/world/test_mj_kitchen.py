"""The MuJoCo kitchen: its frames feed the same ArUco detector, its contacts the same outcome sensing."""

from __future__ import annotations

import os

import numpy as np
import pytest

os.environ.setdefault("MUJOCO_GL", "egl")  # before mujoco is first imported (it reads it then)
pytest.importorskip("mujoco")

from scone_bt.perception.observe import Observer  # noqa: E402

pytestmark = pytest.mark.slow

NAMES = ("salt", "sugar", "honey", "pasta", "tomato sauce", "olive oil", "rice", "flour", "butter", "milk")


@pytest.fixture(scope="module")
def stocked(kitchen_cfg, robot_cfg):
    from scone_bt.world.mj_kitchen import MjKitchen

    kitchen = MjKitchen(kitchen_cfg, robot_cfg)
    kitchen.spawn([kitchen_cfg.catalogue.get(n) for n in NAMES], np.random.default_rng(0))
    yield kitchen
    kitchen.close()


def _top(kitchen, name: str) -> np.ndarray:
    top = np.array(kitchen.object_state(name).position)
    top[2] += kitchen.specs[name].height / 2
    return top


def test_the_detector_finds_every_stocked_product_on_mujoco_frames(stocked, kitchen_cfg):
    assert all(stocked.is_on_shelf(n) for n in NAMES)
    seen = Observer(kitchen_cfg).observe(stocked, np.random.default_rng(0))
    found = {d.name: d for d in seen.detections}
    assert set(found) == set(NAMES)
    errors = [float(np.linalg.norm(np.subtract(d.position, _top(stocked, n)))) for n, d in found.items()]
    assert np.median(errors) <= 0.002 and max(errors) <= 0.005, errors
    frame = seen.frame
    assert frame.rgb.shape == (frame.depth.shape[0], frame.depth.shape[1], 3)
    # Depth is metric along the optical axis: the detected lid lies at its true distance (checked above), and
    # nothing is nearer than the near plane.
    assert float(frame.depth.min()) >= kitchen_cfg.cameras[0].near


def test_an_unchanged_view_is_not_rendered_again_and_a_cover_hides_a_lid(stocked, kitchen_cfg):
    from scone_bt.perception.camera import Camera

    camera = Camera(kitchen_cfg.shelf_cameras[0])
    first = stocked.camera_image(camera)
    again = stocked.camera_image(camera)
    assert first.fresh and not again.fresh and again.rgb is first.rgb
    observer = Observer(kitchen_cfg)
    before = {d.name for d in observer.observe(stocked, np.random.default_rng(0)).detections}
    name = sorted(before)[0]
    spec = stocked.specs[name]
    x, y, z = stocked.object_state(name).position
    side = max(spec.size[:2]) + 0.024
    handle = stocked.add_cover((x, y, z + spec.height / 2 + 0.012), (side, side, 0.004))
    covered = {d.name for d in Observer(kitchen_cfg).observe(stocked, np.random.default_rng(0)).detections}
    stocked.remove_cover(handle)
    assert name not in covered and covered == before - {name}


def test_a_product_placed_by_hand_rests_on_the_table_and_parks_out_of_view(stocked):
    assert stocked.place_on_table("salt")
    stocked.advance(0.5)
    assert stocked.is_on_table("salt") and "salt" in stocked.objects_on_table()
    stocked.park_object("salt")
    stocked.advance(0.5)
    assert not stocked.is_on_table("salt") and not stocked.is_on_shelf("salt")


def test_a_pick_and_place_holds_by_contact_friction_and_reports_its_outcome(kitchen_cfg, robot_cfg):
    from scone_bt.motion import MotionSystem
    from scone_bt.perception.types import Detection
    from scone_bt.world.mj_kitchen import MjKitchen

    def detect(kitchen, name):
        return Detection(name, 0, tuple(_top(kitchen, name)), kitchen.object_yaw(name), 1.0, (0, 0, 1, 1))

    with MjKitchen(kitchen_cfg, robot_cfg) as kitchen:
        kitchen.spawn(
            [kitchen_cfg.catalogue.get(n) for n in ("salt", "olive oil", "honey")], np.random.default_rng(1)
        )
        with MotionSystem.build(kitchen) as system:
            others = [(detect(kitchen, n), kitchen.specs[n]) for n in ("olive oil", "honey")]
            task = system.pick_and_place(detect(kitchen, "salt"), kitchen.specs["salt"], others, rng_seed=1)
            task.start()
            held_seen = False
            while not task.done():
                kitchen.advance(0.1)
                held_seen |= kitchen.held_object(1.0) == "salt"
            outcome = task.outcome()
        assert outcome.success, outcome.message
        assert held_seen and kitchen.is_on_table("salt") and kitchen.held_object(1.0) is None
        # Nothing attached the jar to the hand: a MuJoCo model has no weld or connect constraint but the fingers'.
        assert kitchen.model.neq == 1 and kitchen.model.eq_type[0] == kitchen.mujoco.mjtEq.mjEQ_JOINT


def test_a_weak_gripper_drops_a_heavy_bottle(kitchen_cfg, robot_cfg):
    """The same failure stage PyBullet reports when the grip cannot carry the product (a worn gripper)."""
    from scone_bt.motion import FailureStage, MotionSystem
    from scone_bt.perception.types import Detection
    from scone_bt.world.mj_kitchen import MjKitchen

    with MjKitchen(kitchen_cfg, robot_cfg) as kitchen:
        kitchen.spawn([kitchen_cfg.catalogue.get("olive oil")], np.random.default_rng(0))
        kitchen.set_gripper_properties(max_force=4.0, finger_friction=0.3)
        st = kitchen.object_state("olive oil")
        det = Detection(
            "olive oil",
            0,
            tuple(_top(kitchen, "olive oil")),
            kitchen.object_yaw("olive oil"),
            1.0,
            (0, 0, 1, 1),
        )
        with MotionSystem.build(kitchen) as system:
            task = system.pick_and_place(det, kitchen.specs["olive oil"], [], rng_seed=0)
            task.start()
            while not task.done():
                kitchen.advance(0.1)
            outcome = task.outcome()
        assert not outcome.success and outcome.stage in (FailureStage.GRASP, FailureStage.TRANSIT)
        assert st.position != kitchen.object_state("olive oil").position


def test_a_users_catalogue_file_works_unchanged_on_mujoco(tmp_path, robot_cfg):
    """A product of the user's own file (``--catalogue``): built with its size, mass and friction, and its ArUco lid
    found by the same detector."""
    from scone_bt.config import load_kitchen
    from scone_bt.world.mj_kitchen import MjKitchen

    mine = tmp_path / "mine.yaml"
    mine.write_text(
        "family: my jars\nsource: measured with a ruler\n"
        "defaults: {shape: cylinder, material: glass, friction: 0.4}\nproducts:\n"
        "  - {name: saffron syrup, size: [0.06, 0.06, 0.12], mass: 0.23, rgba: [0.9, 0.6, 0.1, 1], marker_id: 900}\n",
        encoding="utf-8",
    )
    cfg = load_kitchen(catalogues=[mine])
    with MjKitchen(cfg, robot_cfg) as kitchen:
        kitchen.spawn([cfg.catalogue.get(n) for n in ("saffron syrup", "salt")], np.random.default_rng(0))
        body = kitchen.model.body("saffron syrup")
        solid = kitchen.model.geom("saffron syrup")
        assert float(body.mass[0]) == pytest.approx(0.23)
        assert float(solid.friction[0]) == pytest.approx(0.4)
        assert tuple(solid.size[:2]) == pytest.approx((0.03, 0.06))  # cylinder: radius, half height
        assert kitchen.is_on_shelf("saffron syrup")
        found = {d.name: d for d in Observer(cfg).observe(kitchen, np.random.default_rng(0)).detections}
        assert "saffron syrup" in found  # named from its own marker id, 900
        error = np.linalg.norm(np.subtract(found["saffron syrup"].position, _top(kitchen, "saffron syrup")))
        assert error <= 0.005


def test_the_heft_test_feels_the_products_weight_in_mujocos_fingers(kitchen_cfg, robot_cfg):
    """The probe's force and tactile sensing on MuJoCo (`MjKitchen.finger_forces`, `wrist_load` and
    `pad_contacts`, as PyBullet's `ArmIO`): lifted a little and held, the salt weighs on the hand about its own
    weight, its contacts stay put on the pads, and the recording probe carries on."""
    from scone_bt.motion import MotionSystem
    from scone_bt.motion.probe import ProbeSettings
    from scone_bt.perception.types import Detection
    from scone_bt.world.mj_kitchen import MjKitchen

    with MjKitchen(kitchen_cfg, robot_cfg) as kitchen:
        kitchen.spawn([kitchen_cfg.catalogue.get("salt")], np.random.default_rng(1))
        assert kitchen.finger_forces("salt") == (0.0, 0.0)  # untouched
        assert kitchen.pad_contacts("salt") == (None, None)
        det = Detection(
            "salt", 0, tuple(_top(kitchen, "salt")), kitchen.object_yaw("salt"), 1.0, (0, 0, 1, 1)
        )
        with MotionSystem.build(kitchen) as system:
            task = system.pick_and_place(det, kitchen.specs["salt"], [], rng_seed=1)
            task.probe = ProbeSettings(set_back=False)
            task.start()
            while not task.done():
                kitchen.advance(0.1)
            outcome = task.outcome()
            reading = task.probe_reading
        assert outcome.success, outcome.message
        assert reading is not None and reading.held
        weight = kitchen.specs["salt"].mass * 9.81
        assert reading.load_n == pytest.approx(weight, rel=0.25) and reading.grip_n > reading.load_n
        # held fast, the salt's contacts stay put on the pads (`ProbeSettings.max_drift_mm`)
        assert reading.drift_mm is not None and reading.drift_mm <= ProbeSettings().max_drift_mm, reading
        # nothing else touches the hand: the wrist carries what the fingers carry
        assert reading.wrist_load_n == pytest.approx(reading.load_n, rel=0.01), reading


def test_products_meet_the_shelf_and_each_other_with_bullets_friction(stocked):
    """A product meets the fixed scene and every other product through a contact pair with the product of both
    surfaces' friction, as PyBullet's, and never through MuJoCo's own rule (the larger one), which held a 0.55
    product on its shelf at 0.8 instead of 0.44: a pack PyBullet's fingertips slide stood still on MuJoCo."""
    from scone_bt.world.scene_boxes import SCENE_FRICTION

    m = stocked.model
    gid = {n: int(m.geom(n).id) for n in NAMES}
    shelf = int(m.geom("shelf_tier0").id)
    pairs = {
        frozenset((int(m.pair_geom1[k]), int(m.pair_geom2[k]))): float(m.pair_friction[k][0])
        for k in range(m.npair)
    }
    salt, sugar = stocked.specs["salt"].friction, stocked.specs["sugar"].friction
    assert pairs[frozenset((gid["salt"], shelf))] == pytest.approx(salt * SCENE_FRICTION)
    assert pairs[frozenset((gid["salt"], gid["sugar"]))] == pytest.approx(salt * sugar)

    def collide(a: int, b: int) -> bool:  # MuJoCo's own contact filter
        return bool(m.geom_contype[a] & m.geom_conaffinity[b] or m.geom_contype[b] & m.geom_conaffinity[a])

    assert not collide(gid["salt"], shelf) and not collide(gid["salt"], gid["sugar"])
    arm = next(g for g in range(m.ngeom) if m.geom_bodyid[g] == int(m.body("panda_link5").id))
    assert collide(gid["salt"], arm)  # the arm's links still meet products on their own
