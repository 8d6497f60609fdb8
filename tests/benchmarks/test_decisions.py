"""scone-bench decisions: fetch judging against the recipe's stocking, and the online gate replay's counts."""

from __future__ import annotations

import numpy as np

from scone_bt.benchmarks.decisions import GateCounts, judge_fetches, replay_gate
from scone_bt.events import DecisionMade, StepDone
from scone_bt.gate.types import DecisionKind

STEPS = [("salt",), ("pasta",), ("garlic", "olive oil"), ()]


def _d(kind: str, item: str | None, step: int, need: str = "now") -> DecisionMade:
    action = f"Put {item} on table" if item else None
    return DecisionMade(1.0, step, "a step", action, 0.5, 0.5, DecisionKind(kind), need)


def test_judge_counts_wrong_ahead_never_used_and_clarify() -> None:
    done = StepDone(2.0, "a step")
    events = [
        _d("act", "salt", 1),  # right: the human's step 1 needs it
        _d("act", "garlic", 1, "later"),  # ahead: step 3 needs it
        _d("act", "honey", 1),  # wrong and never used
        done,
        done,
        _d("ask", "pasta", 3),  # wrong: step 2 (pasta) is over
        _d("ask", "olive oil", 3),  # right
        _d("clarify", None, 3),
        _d("idle", None, 4),
    ]
    out = judge_fetches(events, STEPS)
    assert out == {"decisions": 7, "fetches": 5, "wrong": 2, "ahead": 1, "never_used": 1, "clarifications": 1}


def test_gate_replay_acts_learns_and_asks_without_learning() -> None:
    vectors = {"Put a on table": np.array([1.0, 0.0], dtype=np.float32)}
    # κ̂ starts at the prior (0.5 ≥ 0.5: act); after failures it asks, and asking teaches it nothing
    counts = replay_gate(["Put a on table"] * 6, [False] * 6, vectors, "knn", seed=0)
    assert counts.decisions == 6
    assert counts.acted_failure >= 1 and counts.asked_would_fail >= 1
    assert counts.acted_success == counts.asked_would_succeed == 0
    rates = counts.rates()
    assert rates["over_step_rate"] == counts.acted_failure / 6
    assert rates["attempted_failure_rate"] == counts.acted_failure / 6
    assert rates["help_rate"] + rates["over_step_rate"] == 1.0


def test_rates_of_an_all_success_stream() -> None:
    c = GateCounts(decisions=4, acted_success=3, acted_failure=0, asked_would_succeed=1, asked_would_fail=0)
    assert c.rates()["over_ask_rate"] == 0.25 and c.rates()["attempted_failure_rate"] == 0.0


def test_warmup_is_learnt_but_not_scored() -> None:
    vectors = {"Put a on table": np.array([1.0, 0.0], dtype=np.float32)}
    counts = replay_gate(["Put a on table"] * 6, [False] * 6, vectors, "knn", seed=0, warmup=4)
    assert counts.decisions == 2
    assert counts.asked_would_fail == 2  # four failures seen: it asks
