"""The failure budget (scone_bt.gate.budget): the online threshold keeps a stated failure rate among attempts on a
stream whose κ̂ miscalibration drifts, where a fixed threshold does not; the closed form; the pinned boundaries."""

from __future__ import annotations

import numpy as np
import pytest

from scone_bt.errors import SconeError
from scone_bt.gate.budget import (
    BudgetCounts,
    BudgetOptions,
    excess_failures,
    has_credit,
    initial_threshold,
    may_explore,
    threshold,
)

_N = 8000  # decisions; the miscalibration jumps half-way
_LAST = 3000  # the realised rate is read over these last decisions (1000 after the jump)
_TOLERANCE = 0.03


def _drifting_stream(seed: int) -> tuple[np.ndarray, np.ndarray]:
    """κ̂ scores p ~ U(0, 1) and outcomes with P(success) = sigmoid(15 (p − b)): b = 0.65 for the first half
    (the rate α is met somewhere inside [τ_min, τ_max] for α = 0.1 and 0.2), then b = 0.8 (κ̂ over-confident:
    τ₀ = 1 − 2α lets 0.21 resp. 0.50 of the attempts fail)."""
    rng = np.random.default_rng(seed)
    p = rng.random(_N)
    b = np.where(np.arange(_N) < _N // 2, 0.65, 0.8)
    success = rng.random(_N) < 1.0 / (1.0 + np.exp(-15.0 * (p - b)))
    return p, success


def _realised_failure_rate(options: BudgetOptions, p: np.ndarray, success: np.ndarray) -> float:
    """Act iff p ≥ τ(counts); only an attempt updates the counts (an asked action has no label)."""
    counts = BudgetCounts()
    attempts = failures = 0
    for t in range(len(p)):
        if p[t] < threshold(options, counts):
            continue  # asked: censored
        ok = bool(success[t])
        counts = BudgetCounts(counts.attempts + 1, counts.failures + (not ok))
        if t >= len(p) - _LAST:
            attempts += 1
            failures += not ok
    assert attempts > 100  # the gate still acts: the rate is not met by asking for everything
    return failures / attempts


@pytest.mark.parametrize("alpha", [0.1, 0.2])
def test_online_threshold_tracks_the_stated_rate_on_a_drifting_stream(alpha: float) -> None:
    p, success = _drifting_stream(seed=0)
    options = BudgetOptions(start_margin=3.0, target_failure_rate=alpha, explore_until=0)
    assert abs(_realised_failure_rate(options, p, success) - alpha) <= _TOLERANCE


@pytest.mark.parametrize("alpha", [0.1, 0.2])
def test_a_fixed_threshold_misses_the_rate_on_the_same_stream(alpha: float) -> None:
    """The same rule with step 0 (τ stays τ₀): what the tracking test must be able to tell apart."""
    p, success = _drifting_stream(seed=0)
    fixed = BudgetOptions(start_margin=3.0, target_failure_rate=alpha, step=0.0, explore_until=0)
    assert abs(_realised_failure_rate(fixed, p, success) - alpha) > _TOLERANCE


def test_excess_failures_equal_the_threshold_shift_while_inside_the_bounds() -> None:
    """F − α·A = (τ − τ₀)/η at every step of a seeded sequence of attempts that keeps τ inside its bounds."""
    options = BudgetOptions(start_margin=3.0, target_failure_rate=0.2, step=0.01)
    tau0 = initial_threshold(options)
    rng = np.random.default_rng(3)
    attempts = failures = 0
    for ok in rng.random(400) < 0.8:
        attempts += 1
        failures += not ok
        tau = threshold(options, BudgetCounts(attempts, failures))
        assert options.tau_min < tau < options.tau_max
        assert failures - 0.2 * attempts == pytest.approx((tau - tau0) / options.step, abs=1e-9)
    assert failures > 0 and attempts - failures > 0


def test_a_failure_raises_tau_by_step_times_one_minus_alpha_and_a_success_lowers_it_by_step_times_alpha() -> (
    None
):
    options = BudgetOptions(start_margin=3.0, target_failure_rate=0.1, step=0.02)
    base = threshold(options, BudgetCounts(10, 1))
    assert threshold(options, BudgetCounts(11, 2)) - base == pytest.approx(0.02 * 0.9)
    assert threshold(options, BudgetCounts(11, 1)) - base == pytest.approx(-0.02 * 0.1)


@pytest.mark.parametrize(
    ("alpha", "tau_min", "tau_max", "tau0"),
    [
        (0.05, 0.5, 0.95, 0.75),  # 1 − 5α
        (0.15, 0.2, 0.95, 0.25),  # the tree's default
        (0.15, 0.3, 0.95, 0.3),  # 1 − 5α = 0.25 below τ_min
        (0.005, 0.5, 0.95, 0.95),  # 1 − 5α = 0.975 above τ_max
        (0.1, 0.2, 0.9, 0.5),
    ],
)
def test_initial_threshold(alpha: float, tau_min: float, tau_max: float, tau0: float) -> None:
    """The shipped start, τ₀ = 1 − 5α within [τ_min, τ_max] (the other tests here pin 1 − 3α, the start their
    figures were worked out at: the mechanics do not depend on it)."""
    options = BudgetOptions(target_failure_rate=alpha, tau_min=tau_min, tau_max=tau_max)
    assert initial_threshold(options) == pytest.approx(tau0)
    assert threshold(options, BudgetCounts()) == pytest.approx(tau0)


def test_threshold_is_clipped_to_its_bounds() -> None:
    options = BudgetOptions(start_margin=3.0, target_failure_rate=0.1, step=0.01, tau_min=0.55, tau_max=0.9)
    assert threshold(options, BudgetCounts(attempts=100, failures=100)) == 0.9
    assert threshold(options, BudgetCounts(attempts=1000, failures=0)) == 0.55
    # just inside: 0.7 + 0.01 · (10 − 0.1 · 100) = 0.7
    assert threshold(options, BudgetCounts(attempts=100, failures=10)) == pytest.approx(0.7)


def test_learnt_outcomes_do_not_move_tau_and_attempts_count_whatever_chose_them() -> None:
    options = BudgetOptions(start_margin=3.0)
    assert threshold(options, BudgetCounts(explored_failures=5, learnt=50)) == initial_threshold(options)
    # an exploratory failure is counted in `failures` like any other: the promise covers every attempt
    assert threshold(options, BudgetCounts(attempts=1, failures=1, explored_failures=1)) > initial_threshold(
        options
    )


def test_may_explore_stops_at_explore_until_learnt_outcomes() -> None:
    options = BudgetOptions(start_margin=3.0, explore_until=10, explore_failures=6)
    assert may_explore(options, BudgetCounts(learnt=9))
    assert not may_explore(options, BudgetCounts(learnt=10))
    assert not may_explore(options, BudgetCounts(learnt=11))
    assert not may_explore(BudgetOptions(start_margin=3.0, explore_until=0), BudgetCounts())


def test_may_explore_stops_at_explore_failures_failed_explorations() -> None:
    options = BudgetOptions(start_margin=3.0, explore_until=10, explore_failures=6)
    assert may_explore(options, BudgetCounts(explored_failures=5, learnt=0))
    assert not may_explore(options, BudgetCounts(explored_failures=6, learnt=0))
    assert not may_explore(BudgetOptions(start_margin=3.0, explore_failures=0), BudgetCounts())


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("target_failure_rate", 0.0),
        ("target_failure_rate", 1.0),
        ("target_failure_rate", float("nan")),
        ("step", -0.01),
        ("step", 1.5),
        ("step", float("inf")),
        ("tau_min", -0.1),
        ("tau_min", 1.0),
        ("tau_max", 0.2),  # not above the default tau_min
        ("tau_max", 1.01),
        ("explore_rate", -0.1),
        ("explore_rate", 1.1),
        ("explore_until", -1),
        ("explore_failures", -1),
    ],
)
def test_budget_options_refuse_out_of_range_values_naming_the_field(field: str, value: float) -> None:
    with pytest.raises(SconeError) as err:
        BudgetOptions(start_margin=3.0, **{field: value})
    message = str(err.value)
    assert message.startswith(f"{field} must be ") and "\n" not in message


def test_budget_options_accept_their_boundaries() -> None:
    BudgetOptions(
        start_margin=3.0,
        step=0.0,
        tau_min=0.0,
        tau_max=1.0,
        explore_rate=0.0,
        explore_until=0,
        explore_failures=0,
    )
    BudgetOptions(start_margin=3.0, step=1.0, explore_rate=1.0)


@pytest.mark.parametrize(
    ("width", "opening", "wide"),
    [(0.0801, 0.08, True), (0.08, 0.08, False), (0.05, 0.08, False), (None, 0.08, False),
     (float("nan"), 0.08, False), (0.2, None, False)],
)  # fmt: skip
def test_too_wide_is_strictly_wider_than_the_opening_and_unknown_is_not_wide(width, opening, wide) -> None:
    from scone_bt.gate.budget import too_wide

    assert too_wide(width, opening) is wide


def test_exploration_spends_only_earned_credit_from_the_first_attempt() -> None:
    """The tomato pasta at α = 0.05 with the strict rule on (the tree's exploration_credit): one failed
    exploration, then no more until successes earn credit."""
    options = BudgetOptions(start_margin=3.0, target_failure_rate=0.05, excess_allowance=1.0)
    assert has_credit(options, BudgetCounts())  # F + 1 = 1 ≤ 0.05 · 1 + 1
    after_one = BudgetCounts(attempts=1, failures=1, explored_failures=1, learnt=1)
    assert not has_credit(options, after_one)  # a second failure: 2 > 0.05 · 2 + 1
    assert not may_explore(options, after_one)
    # 19 successes later, α · A has grown by ~1: one more failure fits again
    assert has_credit(options, BudgetCounts(attempts=19, failures=1))
    assert not has_credit(options, BudgetCounts(attempts=18, failures=1))
    assert excess_failures(options, BudgetCounts(attempts=20, failures=2)) == pytest.approx(1.0)


def test_the_strict_rule_bounds_excess_failures_of_any_exploration_sequence() -> None:
    """Whatever the outcomes, exploring only with credit keeps F ≤ α · A + 1 after every attempt."""
    rng = np.random.default_rng(0)
    for alpha in (0.05, 0.15, 0.4):
        options = BudgetOptions(
            start_margin=3.0,
            target_failure_rate=alpha,
            explore_until=10**6,
            explore_failures=10**6,
            excess_allowance=1.0,
        )
        counts = BudgetCounts()
        for _ in range(300):
            if not may_explore(options, counts):
                counts = BudgetCounts(counts.attempts + 1, counts.failures, counts.explored_failures)
                continue  # a confident attempt that succeeds (the rule leaves those alone)
            ok = bool(rng.random() < 0.3)
            counts = BudgetCounts(counts.attempts + 1, counts.failures + (not ok), counts.explored_failures)
            assert counts.failures <= alpha * counts.attempts + 1 + 1e-9


def test_excess_allowance_is_validated() -> None:
    with pytest.raises(SconeError, match="excess_allowance must be ≥ 0 or None"):
        BudgetOptions(start_margin=3.0, excess_allowance=-1.0)


def test_without_the_strict_rule_exploration_needs_no_credit() -> None:
    """Without the strict promise (exploration_credit: false; on in the shipped tree): the budget explores while
    learning, whatever the excess."""
    options = BudgetOptions(start_margin=3.0, target_failure_rate=0.05)
    after_one = BudgetCounts(attempts=1, failures=1, explored_failures=1, learnt=1)
    assert has_credit(options, after_one)
    assert may_explore(options, after_one)
