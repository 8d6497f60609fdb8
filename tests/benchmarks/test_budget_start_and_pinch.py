"""tools/budget_start_sweep.py replays the gate with another τ₀ and η, and tools/edge_pinch_reach.py tells a pinch
the arm reaches from one it does not."""

from __future__ import annotations

import pytest

from scone_bt.errors import SconeError
from scone_bt.gate.budget import BudgetOptions, initial_threshold


def test_the_threshold_starts_at_one_less_k_alpha():
    shipped = BudgetOptions(target_failure_rate=0.15)  # 1 − 5α
    assert initial_threshold(shipped) == pytest.approx(0.25)
    assert initial_threshold(BudgetOptions(target_failure_rate=0.15, start_margin=3.0)) == pytest.approx(0.55)
    # clipped to τ_min
    assert initial_threshold(BudgetOptions(target_failure_rate=0.2, start_margin=6.0)) == pytest.approx(0.2)
    with pytest.raises(SconeError, match="start_margin must be > 0"):
        BudgetOptions(start_margin=0.0)


def test_the_sweep_s_budget_reaches_the_replay_s_rules_with_its_own_rate():
    from scone_bt.benchmarks.replay import replay_rules

    swept = BudgetOptions(start_margin=5.0, step=0.02)
    rules = replay_rules("budget", 0.10, 0.08, excess_allowance=1.0, budget=swept)
    assert (rules.budget.start_margin, rules.budget.step) == (5.0, 0.02)
    assert (rules.budget.target_failure_rate, rules.budget.excess_allowance) == (0.10, 1.0)
    assert replay_rules("fixed", 0.10, 0.08, budget=swept).budget.step == 0.0  # a fixed threshold stays fixed
    rules = replay_rules("budget", 0.15, 0.08)
    assert rules.budget.start_margin == 5.0 and rules.budget.step == 0.05  # the shipped start, 1 − 5α


def test_a_swept_start_changes_the_replay(tool):
    """args.budget reaches every stream: a lower start asks for less on the same streams."""
    from scone_bt.benchmarks.gate import replay_args, stream_results
    from scone_bt.benchmarks.replay_rates import pooled_rates
    from scone_bt.benchmarks.replay_streams import load_streams
    from scone_bt.gate.probe import ProbeOptions

    args = replay_args("tools/data/sc_probe")
    streams = load_streams(args, oracle=False)

    def help_rate() -> float:
        return pooled_rates(stream_results(streams, "physical", "budget", 0.15, args, probe=ProbeOptions()))[
            "help_rate"
        ]

    shipped = help_rate()
    args.budget = BudgetOptions(start_margin=6.0, step=0.02)
    assert help_rate() < shipped


@pytest.mark.slow
def test_a_pack_out_over_the_lowest_tier_is_pinched_not_one_over_a_higher_tier(tool):
    check = tool("edge_pinch_reach").PinchCheck()
    tray = (0.14, 0.20, 0.045)
    assert check.reachable("front", 0, 0.40, tray, 0.045)
    # the hand's lower half would cut into the tier below, in front of it
    assert not check.reachable("front", 1, 0.40, tray, 0.045)


@pytest.mark.slow
@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_fingertips_slide_a_meat_tray_out_and_the_arm_lifts_it_by_its_edge(tool, monkeypatch, engine):
    # On MuJoCo this needs the products' contacts to multiply friction as Bullet's do (world.mj_model
    # `_product_pairs`): with MuJoCo's own rule (the larger) the shelf held the tray at 0.8 and it did not move.
    from scone_bt.config import load_kitchen

    monkeypatch.setenv("MUJOCO_GL", "egl")
    check = tool("slide_and_pinch_check")
    tray = load_kitchen("perception/kitchen.yaml").catalogue.get("chicken breast")
    run = check.Run(engine, tray, 0.004, 0.045)
    try:
        result = run.run()
    finally:
        run.k.close()
    assert result["slid_m"] > 0.03 and result["on_tier"] and result["held"]


def test_the_gain_counts_lowest_tier_flat_packs_held_with_each_streams_gripper(tool, capsys, monkeypatch):
    import json
    import sys

    gain = tool("wide_pack_gain")
    results = ["docs/results/slide_and_pinch.jsonl", "docs/results/slide_and_pinch_profiles.jsonl"]
    argv = ["wide_pack_gain", "--datasets", "tools/data/sc_heldout_probe", "--results", *results]
    monkeypatch.setattr(sys, "argv", argv)
    gain.main()
    (out,) = json.loads(capsys.readouterr().out)["splits"]
    assert out["scored_decisions"] == 240 and out["not_in_results"] == []
    by_stream = {s["stream"]: s for s in out["streams"]}
    # the nominal gripper slides and lifts its two; the old robot's pads (0.6) cannot drag a pack the shelf (0.8) holds
    assert (by_stream["p00_nominal"]["rows"], by_stream["p00_nominal"]["held"]) == (2, 2)
    assert by_stream["p09_old_robot"]["held"] == 0
    assert out["held"] == sum(s["held"] for s in out["streams"])
    assert out["help_rate_drop_at_most"] == round(out["held"] / 240, 4)


@pytest.mark.slow
def test_the_what_if_replays_the_shipped_gate_and_a_skill_that_held_every_pack(
    tool, capsys, monkeypatch, whole_held_fast_record
):
    """--replay-margins: as recorded it is the shipped replay itself; with the held packs carried, it asks for
    no more, and each emulated row is a success the too-wide rule lets the robot try."""
    import csv
    import json
    import sys
    import tempfile
    from pathlib import Path

    from scone_bt.config.grasp import DEFAULT_OPENING_M
    from scone_bt.config.robot import load_robot

    gain = tool("wide_pack_gain")
    results = ["docs/results/slide_and_pinch.jsonl", "docs/results/slide_and_pinch_profiles.jsonl"]
    held = gain.held_in_check(results, "pybullet")
    with tempfile.TemporaryDirectory() as tmp:
        changed = gain._emulate(
            Path("tools/data/sc_heldout2_probe"), Path(tmp), held, load_robot("panda").gripper
        )
        rows = [r for p in sorted(Path(tmp).glob("*.csv")) for r in csv.DictReader(p.open(encoding="utf-8"))]
    emulated = [r for r in rows if r["detected_width_m"] == f"{DEFAULT_OPENING_M - 0.002:.4f}"]
    assert changed == len(emulated) > 0 and all(r["outcome"] == "success" for r in emulated)
    assert all(gain._lowest_tier_flat_wide(r, DEFAULT_OPENING_M) for r in emulated)

    argv = ["wide_pack_gain", "--datasets", "tools/data/sc_heldout2_probe", "--results", *results]
    monkeypatch.setattr(sys, "argv", [*argv, "--replay-margins", "3"])
    # the committed replay's gate: the heft band of its day (τ + 0.3; the tree's default since is τ + 0.45)
    import dataclasses

    import scone_bt.gate.probe as gate_probe

    @dataclasses.dataclass(frozen=True)
    class BandOfItsDay(gate_probe.ProbeOptions):
        above: float = 0.3

    monkeypatch.setattr(gate_probe, "ProbeOptions", BandOfItsDay)
    gain.main()
    replay = json.loads(capsys.readouterr().out)["replay"]["margins"]["3"]
    shipped = json.loads(Path("docs/results/probe_alpha_heldout2.json").read_text(encoding="utf-8"))[
        "default"
    ]
    assert replay["recorded"]["help_rate"] == shipped["help_rate"]
    assert replay["recorded"]["help_rate_over_starts_mean"] == shipped["over_starts"]["help_rate_mean"]
    assert replay["with_skill"]["help_rate"] < replay["recorded"]["help_rate"]
