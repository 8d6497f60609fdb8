"""tools/slow_carry_check.py: which rows it re-runs, how it slows the arm, and one re-run reproducing its row."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def check(tool):
    return tool("slow_carry_check")


def test_only_slips_of_products_that_fit_are_re_run(check):
    rows = check.slipped_rows(ROOT / "tools/data/sc_probe/p02_slippery_fingers.csv", 0.08)
    assert rows and all(r["failure_stage"] in ("grasp", "transit") for r in rows)
    assert all(min(float(r["width_m"]), float(r["depth_m"] or r["width_m"])) <= 0.08 for r in rows)


def test_slower_scales_velocity_acceleration_and_jerk_as_s_s2_s3(check):
    from scone_bt.benchmarks.self_confidence.profiles import load_profiles
    from scone_bt.config import load_robot

    (weak,) = load_profiles(ROOT / "tools/profiles", ["p01_weak_gripper"])  # the robot's own limits
    limits = load_robot("panda").limits
    slow = check.slower(weak, limits, 0.5)
    assert slow.velocity_scale == pytest.approx(limits.velocity_scale * 0.5)
    assert slow.acceleration_scale == pytest.approx(limits.acceleration_scale * 0.25)
    assert slow.jerk_scale == pytest.approx(limits.jerk_scale * 0.125)
    assert check.slower(slow, limits, 0.5).velocity_scale == pytest.approx(limits.velocity_scale * 0.25)
    assert slow.gripper_max_force == weak.gripper_max_force


def test_at_scale_one_a_re_run_gives_the_recorded_failure(check, capsys, monkeypatch):
    monkeypatch.chdir(ROOT)
    check.main(["--profiles", "p01_weak_gripper", "--scales", "1", "--limit", "1"])
    line = json.loads(capsys.readouterr().out)
    assert line == {"profile": "p01_weak_gripper", "scale": 1.0, "slips": 1, "outcomes": {"grasp": 1}}
