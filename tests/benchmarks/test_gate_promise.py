"""The strict promise with the heft test, replayed on recorded development streams: wherever no confident attempt
failed, failures never exceed α · attempts + 1 (gate.budget.has_credit, gate.after_probe), but for a probe that
failed before the fingers felt anything.

A confident attempt is one whose κ̂ at the final decision (after the probe, if probed) was at or above τ, or that
carried on by feel (a probe that felt the product held fast, on that rule's own record); every other attempt that
can fail is an exploration or a carry-on below τ after a probe, made only on credit. A probe itself needs no credit
(a robot with no credit asks, or probes), so one that fails at the grasp is the exception the replay counts
(`probe_failures_before_feeling`).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from scone_bt.benchmarks.replay import StreamResult, replay_stream
from scone_bt.benchmarks.replay_streams import foreseen, probe_readings
from scone_bt.benchmarks.self_confidence.dataset import load_datasets
from scone_bt.benchmarks.self_confidence.evaldata import decision_time_context
from scone_bt.gate.budget import BudgetOptions
from scone_bt.gate.probe import ProbeOptions

DEV = Path(__file__).resolve().parents[2] / "tools" / "data" / "sc_probe"
STREAMS = ("p01_weak_gripper", "p03_fast_arm", "p08_transparent_blind", "p10_payload_limit")
"""Two streams that fail early and often, two that mostly succeed (probes carried on and set back in both)."""


def _replayed(alpha: float, allowance: float | None) -> list[StreamResult]:
    out = []
    for j, d in enumerate(load_datasets(DEV, names=STREAMS)):
        # one seeded vector per action: the promise is the rule's, whatever κ̂ makes of the names
        names = sorted(set(d.actions))
        table = {
            a: np.random.default_rng([j, i]).normal(size=16).astype(np.float32) for i, a in enumerate(names)
        }
        out.append(
            replay_stream(
                np.stack([table[a] for a in d.actions]),
                decision_time_context(d),
                np.asarray(d.success),
                tuple(d.objects),
                "physical",
                "budget",
                alpha,
                j,
                20,
                0.08,
                probe=ProbeOptions(),
                readings=probe_readings(d),
                excess_allowance=allowance,
                foreseen=foreseen(d),
                # the start these streams were chosen at (the robot before 1 − 5α): they explore, then fail
                budget=BudgetOptions(start_margin=3.0),
            )
        )
    return out


@pytest.mark.parametrize("alpha", [0.05, 0.10])
def test_where_no_confident_attempt_failed_failures_stay_within_alpha_times_attempts_plus_one(
    alpha: float,
) -> None:
    results = _replayed(alpha, 1.0)
    held = [r for r in results if r.confident_failures == 0 and r.unfelt_probe_failures == 0]
    assert held, "no stream without a confident failure: the property would be vacuous"
    for r in held:
        assert r.max_excess <= 1.0 + 1e-9, (r.max_excess, r.all_attempts, r.all_failures)
    assert sum(r.probes for r in results) > 0


def test_without_the_strict_promise_the_same_streams_break_it() -> None:
    """The property can fail: the probe without the strict rule lets unsure attempts fail beyond it."""
    results = _replayed(0.10, None)
    assert any(
        r.confident_failures == 0 and r.unfelt_probe_failures == 0 and r.max_excess > 1.0 for r in results
    )
