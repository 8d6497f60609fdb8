"""The decision after the heft test (gate.after_probe): the hard judge first, then κ̂ on what the fingers felt, then
the strict rule's credit."""

from __future__ import annotations

import math

import pytest

from scone_bt.gate.after_probe import ProbeVerdict, after_probe
from scone_bt.gate.budget import BudgetCounts, BudgetOptions
from scone_bt.gate.probe import ProbeOptions, in_band, probe_credit
from scone_bt.gate.rules import GateRules

ALPHA = 0.15
STRICT = BudgetOptions(target_failure_rate=ALPHA, excess_allowance=1.0)
LOOSE = BudgetOptions(target_failure_rate=ALPHA)
TAU0 = 0.55  # 1 − 3α
HOLDS = (True, "")


def _rules(budget: BudgetOptions) -> GateRules:
    return GateRules(budget=budget, exploration=budget, probe=ProbeOptions())


def test_what_the_fingers_say_comes_first() -> None:
    v = after_probe(_rules(STRICT), BudgetCounts(), "olive oil", (False, "slips in my fingers"), 0.99)
    assert (v.carry, v.felt_unsafe, v.reason) == (False, True, "the olive oil slips in my fingers")


def test_sure_after_the_probe_carries_on_as_a_confident_attempt() -> None:
    v = after_probe(_rules(STRICT), BudgetCounts(), "jar", HOLDS, TAU0)
    assert v == ProbeVerdict(True, confidence=TAU0, threshold=pytest.approx(TAU0))
    assert v.confident and not v.explored


def test_unsure_after_the_probe_carries_on_only_on_credit() -> None:
    # no failure yet: one more keeps F ≤ αA + 1
    v = after_probe(_rules(STRICT), BudgetCounts(), "jar", HOLDS, 0.3)
    assert (v.carry, v.explored, v.confident) == (True, True, False)
    # one failure in one attempt: a second would make 2 > 0.15 · 2 + 1
    spent = BudgetCounts(attempts=1, failures=1)
    v = after_probe(_rules(STRICT), spent, "jar", HOLDS, 0.3)
    assert (v.carry, v.explored, v.felt_unsafe) == (False, False, False)
    assert v.reason == "I am not sure I can carry the jar"
    assert v.threshold == pytest.approx(TAU0 + 0.05 * (1 - ALPHA))  # τ as at the decision


def test_without_the_strict_promise_a_product_that_held_carries_on_as_before() -> None:
    spent = BudgetCounts(attempts=1, failures=1)
    v = after_probe(_rules(LOOSE), spent, "jar", HOLDS, 0.1)
    assert (v.carry, v.explored, v.confident) == (True, False, False)
    assert not after_probe(_rules(LOOSE), spent, "jar", (False, "slips out of my fingers"), 0.9).carry


def test_with_the_strict_promise_a_probe_below_the_threshold_needs_credit() -> None:
    """A probe grasps: it can fail before the fingers feel anything, so below τ it is an attempt below τ."""
    spent = BudgetCounts(attempts=1, failures=1)
    band = ProbeOptions()
    assert not probe_credit(band, STRICT, spent) and probe_credit(band, STRICT, BudgetCounts())
    assert probe_credit(band, LOOSE, spent)  # the rule off: as before
    assert not in_band(0.4, TAU0, band, probe_credit(band, STRICT, spent), ALPHA)
    assert in_band(0.6, TAU0, band, probe_credit(band, STRICT, spent), ALPHA)  # above τ: no credit needed
    assert in_band(0.4, TAU0, band, probe_credit(band, LOOSE, spent), ALPHA)


def test_a_verdict_that_sets_back_is_never_confident() -> None:
    v = ProbeVerdict(False, "the jar slips", confidence=0.9, threshold=0.5, felt_unsafe=True)
    assert not v.confident and math.isnan(ProbeVerdict(True).confidence)
