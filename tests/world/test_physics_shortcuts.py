"""The physics shortcuts (coarser step, frozen resting objects, a sleeping scene not stepped) keep the outcomes of
seeded executions the same as the full-rate simulation (`scone-bench physics` on more queries)."""

from __future__ import annotations

import pytest

from scone_bt.benchmarks.physics import compare_query, outcome_class
from scone_bt.world import Kitchen
from scone_bt.world.kitchen import (
    FULL_RATE_SOLVER_RESIDUAL,
    FULL_RATE_STEP_S,
    full_rate_physics,
)

# Motion-benchmark queries (seed 0, 11 products of clutter, 2 on the table) with different outcomes at the full rate:
# a success, a product that slips out of the fingers while lifting, one that stays stuck between the open fingers
# after release, one whose grasps are all blocked.
PANDA_QUERIES = (0, 2, 5, 11)
# iiwa7 queries whose carried product dropped out of its gripper with a 1/120 s step (it keeps 1/240 s).
IIWA_QUERIES = (15, 35)


def test_full_rate_physics_is_the_reference_and_is_restored(kitchen_cfg, robot_cfg):
    with full_rate_physics(), Kitchen(kitchen_cfg, robot_cfg) as k:
        assert k.time_step == FULL_RATE_STEP_S and not k.freeze_resting
        assert Kitchen.SOLVER_RESIDUAL_DEFAULT == FULL_RATE_SOLVER_RESIDUAL
    with Kitchen(kitchen_cfg, robot_cfg) as k:
        assert k.time_step == 1.0 / robot_cfg.control.physics_hz > FULL_RATE_STEP_S and k.freeze_resting
        assert Kitchen.SOLVER_RESIDUAL_DEFAULT is None


def test_each_robot_file_sets_its_physics_rate(kitchen_cfg):
    from scone_bt.config import load_robot

    # The iiwa7's gripper drops carried products at 120 Hz (scone-bench physics): it keeps 240 Hz.
    rates = {name: load_robot(name).control.physics_hz for name in ("panda", "iiwa7")}
    assert rates == {"panda": 120.0, "iiwa7": 240.0}
    # The Panda's solver stops at a residual of 1e-5; the iiwa7 keeps PyBullet's 1e-7 (3 of 60 outcomes changed).
    residuals = {name: load_robot(name).control.solver_residual for name in ("panda", "iiwa7")}
    assert residuals == {"panda": 1e-5, "iiwa7": FULL_RATE_SOLVER_RESIDUAL}
    with Kitchen(kitchen_cfg, load_robot("iiwa7")) as k:
        assert k.time_step == FULL_RATE_STEP_S


@pytest.mark.slow
@pytest.mark.parametrize(
    ("arm", "index"), [*(("panda", i) for i in PANDA_QUERIES), *(("iiwa7", i) for i in IIWA_QUERIES)]
)
def test_a_seeded_execution_ends_the_same_with_the_shortcuts_as_at_the_full_rate(arm, index):
    result = compare_query("kitchen", arm, 0, 11, 2, index)
    assert result["shortcuts"]["class"] == result["full_rate"]["class"], result


def test_outcome_classes_name_the_stage_and_the_planners_reason():
    assert outcome_class({"success": True, "stage": None}) == "success"
    assert outcome_class({"success": False, "stage": "grasp", "reason": None}) == "grasp"
    failed = {"success": False, "stage": "planning", "reason": "grasps_blocked"}
    assert outcome_class(failed) == "planning: grasps_blocked"


def test_the_freeze_check_finds_the_boxes_near_a_mover_as_the_per_pair_test_does():
    import numpy as np

    from scone_bt.world.kitchen import _near_any

    rng = np.random.default_rng(0)
    margin = 0.08
    for trial in range(300):
        lo = rng.uniform(-1.0, 1.0, size=(rng.integers(1, 15), 3))
        boxes = np.stack([lo, lo + rng.uniform(0.01, 0.3, size=lo.shape)], axis=1)
        mlo = rng.uniform(-1.0, 1.0, size=(rng.integers(0, 15), 3))
        movers = np.stack([mlo, mlo + rng.uniform(0.01, 0.3, size=mlo.shape)], axis=1)
        if trial % 3 == 0 and len(movers):  # a box exactly at the margin of a mover: still near
            boxes[0, 0, 0] = movers[0, 1, 0] + margin
        expected = (
            (
                (boxes[:, None, 0, :] - margin <= movers[None, :, 1, :])
                & (movers[None, :, 0, :] <= boxes[:, None, 1, :] + margin)
            )
            .all(axis=2)
            .any(axis=1)
            if len(movers)
            else np.zeros(len(boxes), dtype=bool)
        )
        as_tuples = [tuple(map(tuple, b)) for b in boxes.tolist()]
        mover_tuples = [tuple(map(tuple, b)) for b in movers.tolist()]
        assert _near_any(as_tuples, mover_tuples, margin) == expected.tolist()


def test_an_arm_command_repeated_is_skipped_until_the_motors_were_set_otherwise(kitchen):
    import numpy as np

    sent = []
    real = kitchen.bc.setJointMotorControlArray

    def counting(*args, **kwargs):
        sent.append(kwargs["targetPositions"])
        return real(*args, **kwargs)

    kitchen.bc.setJointMotorControlArray = counting
    q = kitchen.arm_joint_positions() + 0.02  # not the home pose the kitchen already holds
    kitchen.command_arm(q)
    kitchen.command_arm(q.copy())  # the same target: the motors already have it
    assert len(sent) == 1
    kitchen.command_arm(q, np.full(len(q), 0.1))  # another feed-forward velocity
    kitchen.command_arm(q + 0.01)
    assert len(sent) == 3
    kitchen.hold_arm(q)  # holding goes through the same commands: a new target goes out
    kitchen.command_arm(q + 0.01)
    assert len(sent) == 5 and sent[-1] == (q + 0.01).tolist()
