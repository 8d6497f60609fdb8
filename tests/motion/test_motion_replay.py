"""tools/motion_replay.py: the recording a refactor of the motion code is checked with repeats, and its diff names
what differs."""

from __future__ import annotations

import copy

import pytest


@pytest.fixture(scope="module")
def replay(tool):
    return tool("motion_replay")


def test_the_sampling_functions_digests_repeat(replay):
    first, second = replay._functions(6), replay._functions(6)
    assert first == second
    assert len(first["grasp_candidates"]) == 12 and all(first["grasp_candidates"])
    assert len(first["sample_placements"]) == 6 and len(first["plan_joint_path"]) == 1


def test_diff_names_the_row_that_differs(replay):
    a = {
        "queries": {"panda": [{"i": 0, "success": True}, {"i": 1, "success": False}]},
        "functions": {"plan_joint_path": [["success", "RRTConnect: 3 waypoints", 0, "ab"]]},
    }
    lines, total = replay._diff(a, copy.deepcopy(a))
    assert total == 0 and "queries panda: 2 vs 2 rows, 0 differ" in lines
    b = copy.deepcopy(a)
    b["queries"]["panda"][1]["success"] = True
    b["functions"]["plan_joint_path"][0][3] = "cd"
    lines, total = replay._diff(a, b)
    assert total == 2
    assert "  queries panda #1 differs" in lines and "  functions plan_joint_path #0 differs" in lines
