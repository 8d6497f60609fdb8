"""The heft test in PyBullet (motion.probe): a heavy glass bottle held by a weak gripper slips during the probe; the
robot feels it in its fingers, sets the bottle back on its shelf, upright, and the outcome is aborted (not a
failure), in words the gate asks with. A bottle the gripper holds is carried on as without the probe."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from scone_bt.benchmarks.self_confidence import generate
from scone_bt.benchmarks.self_confidence.profiles import load_profile
from scone_bt.motion.probe import ProbeSettings

pytestmark = pytest.mark.slow

PROFILES = Path(__file__).resolve().parents[2] / "tools" / "profiles"


@pytest.fixture
def worker():
    """The generator's worker: its kitchen is the one the execution ran in (read after it, ground truth)."""
    return generate._WORKER


def test_a_heavy_bottle_that_slips_in_the_probe_is_set_back_on_its_shelf(
    kitchen_cfg, robot_cfg, worker
) -> None:
    weak = load_profile(PROFILES / "p01_weak_gripper.yaml")  # 8 N a finger
    record, _ = generate.run_execution(
        weak, 0, kitchen_cfg, robot_cfg, target_name="olive oil", probe=ProbeSettings()
    )
    assert record.detail == "set back after the probe: the olive oil slips in my fingers", record.detail
    assert not record.success and record.failure_stage is None  # aborted: neither a success nor a failure
    assert record.probe_held is not None and record.probe_load_n < 0.9 * 9.81  # it never carried its weight
    kitchen = worker.kitchen
    state = kitchen.object_state("olive oil")
    # Ground truth, for the test only: the bottle stands upright on a shelf, not on the table, not held.
    up = np.asarray(kitchen.bc.getMatrixFromQuaternion(state.orientation)).reshape(3, 3)[:, 2]
    assert up[2] > np.cos(np.radians(5.0))
    assert not kitchen.is_on_table("olive oil")
    from scone_bt.perception.context import shelf_place

    assert shelf_place(kitchen_cfg.scene, state.position) is not None
    assert kitchen.held_object(0.1) is None


def test_a_bottle_the_gripper_holds_is_carried_on_after_the_probe(kitchen_cfg, robot_cfg, worker) -> None:
    nominal = load_profile(PROFILES / "p00_nominal.yaml")  # 40 N a finger
    record, _ = generate.run_execution(
        nominal, 0, kitchen_cfg, robot_cfg, target_name="olive oil", probe=ProbeSettings()
    )
    assert record.success, record.detail
    assert record.probe_load_n == pytest.approx(0.9 * 9.81, rel=0.02)  # the fingers felt its weight


def test_a_pack_the_fingertips_press_on_is_set_back_without_a_made_up_mass() -> None:
    from scone_bt.benchmarks.motion import _query

    # The motion benchmark's query 2 (seed 0): the egg roll wrappers, a 3 cm pack wider than the gripper opens;
    # the fingertips land on its top and push it into the shelf (214 N) instead of lifting it.
    rec = _query("kitchen", "panda", 0, 11, 2, 2, probe=True)
    assert rec["target"] == "egg roll wrappers"
    assert rec["aborted"] and not rec["success"]
    assert rec["message"] == (
        "set back after the probe: the egg roll wrappers does not come up: my fingers press on it"
    )


def test_a_probe_that_carries_on_costs_no_more_than_its_lift_and_hold() -> None:
    from scone_bt.benchmarks.motion import _query

    # The motion benchmark's query 1 (seed 0): the barbecue sauce, carried on after the probe. The rest of the lift
    # goes at the plan's own pace, so the probe adds at most its little lift and its hold (simulated seconds).
    off = _query("kitchen", "panda", 0, 11, 2, 1, probe=False)
    on = _query("kitchen", "panda", 0, 11, 2, 1, probe=True)
    assert on["target"] == "barbecue sauce" and on["success"] and off["success"]
    settings = ProbeSettings()
    assert on["sim_s"] - off["sim_s"] <= settings.up_s + settings.hold_s + 1e-6


@pytest.mark.parametrize(
    ("i", "target"),
    [
        # The palm touches the box's top and presses it down: the fingers alone feel 26 → 23 N, the whole hand
        # (what a wrist force sensor reads) its weight, 5.1 N, steady.
        (31, "rigatoni"),
        # A neighbour leans on the bag: its load rises 1.6 % through the hold (the wrist's too) while its contacts stay
        # put on the pads (held fast, not sliding).
        (6, "grits"),
    ],
)
def test_a_product_held_fast_is_carried_on_though_something_pushes_on_it(i: int, target: str) -> None:
    from scone_bt.benchmarks.motion import _query

    rec = _query("kitchen", "panda", 0, 11, 2, i, probe=True)  # the motion benchmark's query i (seed 0)
    assert rec["target"] == target
    assert rec["success"] and not rec["aborted"], rec["message"]


def test_a_probe_whose_fingers_close_on_nothing_leaves_the_product_standing_and_is_aborted(
    kitchen_cfg, robot_cfg, worker
) -> None:
    nominal = load_profile(PROFILES / "p00_nominal.yaml")
    # Execution 31 of the nominal profile: the fingers close beside the taco shells, which stay where they stood.
    recorded, _ = generate.run_execution(nominal, 31, kitchen_cfg, robot_cfg)
    assert recorded.object == "taco shells"
    assert (recorded.failure_stage, recorded.detail) == (
        "grasp",
        "the fingers closed without holding the object",
    )
    assert recorded.probe_in_place is True and recorded.probe_held is None  # recorded beside the failure
    probed, _ = generate.run_execution(nominal, 31, kitchen_cfg, robot_cfg, probe=ProbeSettings())
    assert not probed.success and probed.failure_stage is None  # aborted: the product is back in its place
    assert probed.detail.endswith(
        "it stands where it stood: the taco shells is not in my fingers when they close"
    )
    assert not worker.kitchen.is_on_table("taco shells") and worker.kitchen.held_object(0.1) is None
    # Pushed farther than it may be to count as in its place: the same miss is a failed grasp.
    far, _ = generate.run_execution(
        nominal, 31, kitchen_cfg, robot_cfg, probe=ProbeSettings(in_place_m=0.001)
    )
    assert (far.failure_stage, far.detail) == ("grasp", "the fingers closed without holding the object")
