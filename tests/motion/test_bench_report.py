"""The motion benchmark's aggregation (pure): which queries count towards which rate."""

from __future__ import annotations

from scone_bt.benchmarks.motion import _report


def _rec(i, *, fits=True, payload=True, success=True, planned=True, reason=None, stage=None):
    rec = {
        "i": i,
        "target": f"t{i}",
        "fits_gripper": fits,
        "fits_payload": payload,
        "success": success,
        "stage": stage,
        "message": "m",
        "sim_s": 10.0,
        "planned": planned,
        "reason": reason,
    }
    if planned:
        rec.update(family="top", plan_ms=40.0 + i, plan_cpu_ms=30.0, ruckig_ms=[0.05], ompl_ms=[2.0])
    return rec


def test_rates_count_only_the_queries_they_are_about():
    records = [
        _rec(0),
        _rec(1),
        _rec(
            2, success=False, planned=False, reason="grasps_blocked", stage="planning"
        ),  # graspable, blocked
        _rec(3, fits=False, success=False, planned=False, reason="grasps_blocked", stage="planning"),
        _rec(4, fits=False, success=False, stage="grasp"),  # too wide: fails in the physics
        _rec(5, payload=False, success=False, stage="transit"),  # too heavy
        _rec(6, success=False, planned=False, reason="no_path", stage="planning"),
    ]
    r = _report(records, 1.0)
    assert r["queries"] == 7 and r["fits_gripper"] == 5 and r["fits_gripper_and_payload"] == 4
    assert r["blocked_by_clutter_rate"] == round(1 / 5, 4)  # the too-wide blocked query does not count
    assert r["physical_success_rate_graspable"] == round(2 / 4, 4)
    assert r["plan_success_rate_on_reachable"] == round(4 / 5, 4)  # no_path counts as reachable
    assert r["failures_by_reason"] == {
        "physical: grasp": 1,
        "physical: transit": 1,
        "planning: grasps_blocked": 2,
        "planning: no_path": 1,
    }
    assert set(r["failures_of_graspable"]) == {"planning: grasps_blocked", "planning: no_path"}
    assert r["targets_met"]["plan_success_rate_on_reachable"] is False
    assert r["blocked_by_scene_only"] == 0 and r["targets_off_shelf"] == []


def test_blocked_by_the_shelving_alone_and_fallen_targets_are_named_but_still_counted():
    records = [
        _rec(0),
        {**_rec(1, success=False, planned=False, reason="grasps_blocked"), "scene_only": True},
        {**_rec(2, success=False, planned=False, reason="grasps_blocked"), "on_shelf": False},
        {**_rec(3, fits=False, success=False, planned=False, reason="grasps_blocked"), "scene_only": True},
    ]
    r = _report(records, 1.0)
    assert r["blocked_by_clutter_rate"] == round(2 / 3, 4)  # the rate's definition is unchanged
    assert r["blocked_by_scene_only"] == 1  # the too-wide one is not a graspable query
    assert r["targets_off_shelf"] == ["t2"]
