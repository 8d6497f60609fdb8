"""The speed benchmarks check issue 29's targets, not an earlier issue's looser ones."""

from __future__ import annotations


def test_the_episode_benchmark_checks_20x_real_time_and_a_first_decision_within_2_s():
    from scone_bt.benchmarks.episode import TARGETS

    assert TARGETS == {
        "sim_per_wall": 20.0,
        "startup_to_first_decision_s": 2.0,
        "startup_to_first_decision_cold_s": 2.0,
    }


def test_the_motion_benchmark_checks_plans_of_10_ms_p50_and_40_ms_p95():
    from scone_bt.benchmarks.motion import TARGETS

    assert TARGETS["pick_place_plan_ms_p50"] == ("<=", 10.0)
    assert TARGETS["pick_place_plan_ms_p95"] == ("<=", 40.0)
