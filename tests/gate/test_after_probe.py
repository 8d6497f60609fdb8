"""The decision after the heft test (gate.after_probe): the hard judge first, then κ̂ on what the fingers felt, then
the strict rule's credit."""

from __future__ import annotations

import math
from dataclasses import replace

import pytest

from scone_bt.errors import SconeError
from scone_bt.gate.after_probe import ProbeVerdict, after_probe
from scone_bt.gate.budget import BudgetCounts, BudgetOptions, FeltCarry
from scone_bt.gate.probe import FELL_BY_FEEL, FELL_NO_HEAVIER, ProbeOptions, in_band, probe_credit
from scone_bt.gate.rules import GateRules

ALPHA = 0.15
STRICT = BudgetOptions(start_margin=3.0, target_failure_rate=ALPHA, excess_allowance=1.0)
LOOSE = BudgetOptions(start_margin=3.0, target_failure_rate=ALPHA)
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


def test_a_probe_needs_no_credit_unless_the_options_ask_for_it() -> None:
    """A robot with no credit asks, or probes: a probe is not an exploration. ``credit`` (tried, not the default)
    makes a probe below τ need credit as exploration does."""
    spent = BudgetCounts(attempts=1, failures=1)
    band = ProbeOptions()
    assert probe_credit(band, STRICT, spent) and probe_credit(band, LOOSE, spent)
    assert in_band(0.4, TAU0, band, probe_credit(band, STRICT, spent), ALPHA)
    strict = ProbeOptions(credit=1.0)
    assert not probe_credit(strict, STRICT, spent) and probe_credit(strict, STRICT, BudgetCounts())
    assert not in_band(0.4, TAU0, strict, probe_credit(strict, STRICT, spent), ALPHA)
    assert in_band(0.6, TAU0, strict, probe_credit(strict, STRICT, spent), ALPHA)  # above τ: no credit needed


def test_held_fast_carries_on_by_feel_while_its_own_record_keeps_the_promise() -> None:
    """No credit left and κ̂ unsure after the probe, but the fingers held it fast (load ≤ 0.1 of the grip): it
    carries on, confident by feel, until such carries have failed beyond α × their attempts + 2
    (``feel_allowance``)."""
    spent = BudgetCounts(attempts=1, failures=1)
    v = after_probe(_rules(STRICT), spent, "jar", HOLDS, 0.3, traction=0.05)
    assert (v.carry, v.by_feel, v.held_fast, v.confident, v.explored) == (True, True, True, True, False)
    # not fast enough (0.2 of the grip), not measured, or the hard judge set it back: the rule does not apply
    for traction in (0.2, None, math.nan):
        v = after_probe(_rules(STRICT), spent, "jar", HOLDS, 0.3, traction=traction)
        assert (v.carry, v.by_feel) == (False, False)
    v = after_probe(_rules(STRICT), spent, "jar", (False, "slips in my fingers"), 0.3, traction=0.05)
    assert (v.carry, v.by_feel, v.felt_unsafe) == (False, False, True)
    # its own record: two held-fast carries that failed leave no credit (3 > 0.15 · 3 + 2) ...
    failed = BudgetCounts(attempts=2, failures=2, held_fast=(FeltCarry(0.04, False), FeltCarry(0.03, False)))
    v = after_probe(_rules(STRICT), failed, "jar", HOLDS, 0.3, traction=0.05)
    assert (v.carry, v.held_fast) == (False, True)
    assert (
        v.reason
        == "I am not sure I can carry the jar, as products I felt no heavier have fallen from my fingers"
    )
    # ... until successes earn it back, whatever the budget's own credit
    earned = BudgetCounts(
        attempts=9, failures=3, held_fast=(FeltCarry(0.04, False), *[FeltCarry(0.06, True)] * 7)
    )
    assert after_probe(_rules(STRICT), earned, "jar", HOLDS, 0.3, traction=0.05).by_feel
    # with credit the budget's it is still by feel, spending none of the exploration credit
    v = after_probe(_rules(STRICT), BudgetCounts(), "jar", HOLDS, 0.3, traction=0.05)
    assert (v.by_feel, v.explored) == (True, False)
    # sure after the probe: confident by κ̂, the probe's feel noted for the record
    v = after_probe(_rules(STRICT), spent, "jar", HOLDS, 0.9, traction=0.05)
    assert (v.carry, v.by_feel, v.held_fast, v.confident) == (True, False, True, True)


def test_a_first_held_fast_carry_that_failed_does_not_end_carrying_by_feel() -> None:
    """A cold robot's first carry held fast and failed anyway: that one failure spent the budget's credit
    (2 > 0.15 · 2 + 1) and, with an allowance of 1, the held-fast record's too. κ̂, having seen only failures, is
    never sure again, so that robot asked for everything after. With ``feel_allowance`` 2 the record sees one more
    held-fast carry; a success there earns the budget back."""
    first_failed = BudgetCounts(attempts=1, failures=1, held_fast=(FeltCarry(0.05, False),))
    v = after_probe(_rules(STRICT), first_failed, "jar", HOLDS, 0.25, traction=0.05)
    assert (v.carry, v.by_feel, v.confident, v.explored) == (True, True, True, False)
    one = GateRules(budget=STRICT, exploration=STRICT, probe=ProbeOptions(feel_allowance=1.0))
    v = after_probe(one, first_failed, "jar", HOLDS, 0.25, traction=0.05)
    assert (v.carry, v.reason) == (False, f"I am not sure I can carry the jar, {FELL_NO_HEAVIER}")


def test_the_held_fast_record_is_read_at_the_load_the_probe_felt() -> None:
    """Slipping grows with the load the fingers hold: a held-fast carry that fell counts against a product felt
    at least as heavy, one that arrived for a product felt no heavier. Slippery fingers, as on the development
    streams: three 0.3 kg bottles (traction 0.06) held fast in the probe and fell in the carry, five 0.15 kg jars
    (0.03) arrived. The whole record (3 of 8 fell: 4 > 0.15 · 9 + 2) leaves nothing to carry by feel; read at the
    load, a jar felt at 0.03 sees only the five that arrived, a bottle at 0.06 the three that fell."""
    carries = (*[FeltCarry(0.06, False)] * 3, *[FeltCarry(0.03, True)] * 5)
    slippery = BudgetCounts(attempts=10, failures=5, held_fast=carries)
    assert slippery.held_fast_record() == BudgetCounts(8, 3)
    assert slippery.held_fast_record(0.03) == BudgetCounts(5, 0)
    assert slippery.held_fast_record(0.06) == BudgetCounts(3, 3)
    assert slippery.held_fast_record(0.045) == BudgetCounts(0, 0)  # between the two: neither says anything
    jar = after_probe(_rules(STRICT), slippery, "jar", HOLDS, 0.3, traction=0.03)
    assert (jar.carry, jar.by_feel) == (True, True)
    bottle = after_probe(_rules(STRICT), slippery, "bottle", HOLDS, 0.3, traction=0.06)
    assert (bottle.carry, bottle.reason) == (
        False,
        f"I am not sure I can carry the bottle, {FELL_NO_HEAVIER}",
    )
    # a fall at a lighter load counts against a heavier product: three light falls end it for what is heavier
    light_falls = BudgetCounts(
        attempts=8, failures=3, held_fast=(*[FeltCarry(0.02, False)] * 3, *carries[3:])
    )
    assert light_falls.held_fast_record(0.03) == BudgetCounts(8, 3)
    assert not after_probe(_rules(STRICT), light_falls, "jar", HOLDS, 0.3, traction=0.03).carry


def test_falls_at_ever_lighter_loads_are_bounded_by_the_carries_made_by_feel() -> None:
    """A fall felt heavier says nothing at a lighter load, so held-fast carries that each fall a little lighter
    than the last would each find the record at their load clean. The carries made by feel keep the promise on
    their own record too (`BudgetCounts.by_feel_record`): with allowance 2, after two falls by feel a third is
    not risked (3 > 0.15 · 3 + 2)."""
    counts = BudgetCounts()
    carried = 0
    for load in (0.095, 0.09, 0.085, 0.08, 0.075, 0.07, 0.065, 0.06):
        assert counts.held_fast_record(load) == BudgetCounts(0, 0)  # read at the load: nothing against it
        v = after_probe(
            _rules(STRICT), replace(counts, attempts=99, failures=99), "jar", HOLDS, 0.2, traction=load
        )
        if not v.by_feel:
            break
        carried += 1
        counts = replace(counts, held_fast=(*counts.held_fast, FeltCarry(load, False, by_feel=True)))
    assert carried == 2 and counts.by_feel_record() == BudgetCounts(2, 2)
    assert (
        v.reason == f"I am not sure I can carry the jar, {FELL_BY_FEEL}"
    )  # the third: the carries by feel's own
    # carries κ̂ was sure of count at their load, not in the record of carries by feel
    sure = BudgetCounts(held_fast=(FeltCarry(0.05, False), FeltCarry(0.05, False), FeltCarry(0.05, False)))
    assert sure.by_feel_record() == BudgetCounts(0, 0) and sure.held_fast_record(0.06) == BudgetCounts(3, 3)


@pytest.mark.parametrize("load", [None, math.nan, math.inf])
def test_an_unmeasured_load_reads_the_whole_record(load: float | None) -> None:
    counts = BudgetCounts(held_fast=(FeltCarry(0.06, False), FeltCarry(0.03, True)))
    assert counts.held_fast_record(load) == BudgetCounts(2, 1)


@pytest.mark.parametrize("value", [-1.0, 101.0, math.nan])
def test_feel_allowance_is_validated(value: float) -> None:
    with pytest.raises(SconeError, match=r"probe.feel_allowance must be in \[0, 100\]"):
        ProbeOptions(feel_allowance=value)


def test_sure_traction_is_validated_against_the_friction_limit() -> None:
    with pytest.raises(
        SconeError, match=r"probe.sure_traction \(at most max_traction\) must be in \(0, 0.3\], got 0.5"
    ):
        ProbeOptions(sure_traction=0.5)


def test_a_verdict_that_sets_back_is_never_confident() -> None:
    v = ProbeVerdict(False, "the jar slips", confidence=0.9, threshold=0.5, felt_unsafe=True)
    assert not v.confident and math.isnan(ProbeVerdict(True).confidence)
