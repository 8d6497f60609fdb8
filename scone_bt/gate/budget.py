"""The failure budget: the gate's threshold, calibrated online so that at most a stated share of attempts fail.

The user states ``target_failure_rate`` α: the share of the robot's attempts that may fail. The robot cannot
assume that the products it meets are exchangeable with those it learnt from (most are new), so a threshold fixed
in advance, or split-conformal calibration, does not keep α (docs/results/gate.md). Instead the threshold tracks
the realised failure rate online, as adaptive conformal inference does for coverage (Gibbs & Candès 2021), with
feedback only where the robot acted (intermittent feedback: an asked action gets no label; Zhao et al. 2025):

    τ = clip(τ₀ + η · (F − α · A), τ_min, τ_max)

where A and F are every labelled attempt so far (exploratory ones included: the promise covers every attempt)
and the failures among them, τ₀ = clip(1 − kα) with k = ``start_margin`` = 5, and η the step. Each failure
raises τ by η(1 − α); each success lowers it by ηα, so τ settles where failures are α of the attempts. While τ
stays inside its bounds, F − α · A = (τ − τ₀) / η exactly: the failures in excess of the budget are bounded by
(τ_max − τ₀) / η (14 at the default α = 0.15) whatever the products are. τ₀ and η were chosen on the development
streams, not on the held-out ones: a larger η tracks a stream of new products faster (tools/data/sc,
docs/results/gate.md). The start was 1 − 3α until the arm slid and pinched flat packs: with the heft probe that
robot spent about half its budget (0.078 of its attempts failed at α = 0.15). On the development streams recorded
with the skill (tools/data/sc_slide) 1 − 5α spends more of it and asks less: 0.311 of the decisions against 0.326
(the held-fast record then read whole; with the heft test's band at τ + 0.45, which the lower start needs to keep
feeling a weakened gripper; tools/budget_start_sweep.py, docs/results/probe.md). The price is that wider bound on
excess failures.

Exploration (the paper's ε-greedy, made principled): while κ̂ has learnt from fewer than ``explore_until``
outcomes and fewer than ``explore_failures`` exploratory attempts failed, an action below τ is tried with
probability ``explore_rate`` (a seeded draw), so a cold robot learns although asking teaches it nothing.
Exploratory attempts count in the realised rate and move τ like any other attempt: they are the stated price of
learning, paid from the same budget.

With ``excess_allowance`` set (the tree's ``exploration_credit: true`` sets it to 1; None, the default, keeps the
rule above alone), exploration spends only credit (`has_credit`): an attempt below τ is allowed only while one more
failure would keep F ≤ α · A + ``excess_allowance``, counted after that attempt. So a short episode keeps a strict
promise from its first attempt: with α = 0.05 a robot that explored and failed once does not explore again until
successes have earned it (the tomato pasta with a weak gripper failed 2 of 3 attempts before this rule). A robot
with no credit asks instead (or probes, gate.probe). Confident attempts (κ̂ ≥ τ) are not limited by it; nor is a
carry after a probe that felt the product held fast, which has a record of its own (gate.after_probe).

What the robot knows of its own hardware comes before κ̂: a product its depth image measures wider than its
gripper opens (`too_wide`) cannot be held, so it is asked about, never attempted or explored. In the self-confidence
datasets 2 of the 177 executions of such products succeeded (docs/results/gate.md).

`threshold`, `may_explore`, `has_credit` and `too_wide` are pure functions; the caller keeps the counts (the episode folds
them from its events, the replay from its stream).
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass

from scone_bt.config.tree_parameters import TREE_DEFAULTS
from scone_bt.errors import SconeError

__all__ = [
    "BudgetOptions",
    "BudgetCounts",
    "FeltCarry",
    "threshold",
    "may_explore",
    "has_credit",
    "excess_failures",
    "initial_threshold",
    "too_wide",
]


@dataclass(frozen=True)
class BudgetOptions:
    """The promise and how it is kept.

    Attributes:
        target_failure_rate: α, the share of attempts that may fail, in (0, 1).
        step: η, threshold change per unit of excess failures (probability per failure).
        tau_min: Lowest threshold, in [0, 1).
        tau_max: Highest threshold, in (tau_min, 1].
        explore_rate: Chance of trying an action below τ while exploring, in [0, 1].
        explore_until: Exploration stops once κ̂ has learnt from this many outcomes.
        explore_failures: Exploration stops once this many exploratory attempts failed.
        excess_allowance: Failures beyond α × attempts an exploratory attempt may risk (`has_credit`), ≥ 0;
            None: exploration needs no credit (the rule before the strict promise).
        start_margin: k in τ₀ = 1 − kα (`initial_threshold`), > 0.
    """

    target_failure_rate: float = TREE_DEFAULTS.target_failure_rate
    step: float = 0.05
    tau_min: float = 0.2
    tau_max: float = 0.95
    explore_rate: float = 0.5
    explore_until: int = 10
    explore_failures: int = 6
    excess_allowance: float | None = None
    start_margin: float = 5.0

    def __post_init__(self) -> None:
        checks = (
            ("target_failure_rate", 0.0 < self.target_failure_rate < 1.0, "in (0, 1)"),
            ("step", 0.0 <= self.step <= 1.0, "in [0, 1]"),
            ("tau_min", 0.0 <= self.tau_min < 1.0, "in [0, 1)"),
            ("tau_max", self.tau_min < self.tau_max <= 1.0, "in (tau_min, 1]"),
            ("explore_rate", 0.0 <= self.explore_rate <= 1.0, "in [0, 1]"),
            ("explore_until", self.explore_until >= 0, "≥ 0"),
            ("explore_failures", self.explore_failures >= 0, "≥ 0"),
            ("start_margin", self.start_margin > 0.0, "> 0"),
            (
                "excess_allowance",
                self.excess_allowance is None or self.excess_allowance >= 0.0,
                "≥ 0 or None",
            ),
        )
        for name, ok, allowed in checks:
            value = getattr(self, name)
            if not ok or (isinstance(value, float) and not math.isfinite(value)):
                raise SconeError(f"{name} must be {allowed}, got {value}")


@dataclass(frozen=True)
class FeltCarry:
    """One attempt carried on after a heft test that felt the product held fast (gate.probe.held_fast).

    Attributes:
        traction: The load the fingers felt over their grip during the lift (dimensionless, load N / grip N:
            motion.probe.ProbeReading.lift_traction); 0 for a fall whose load an older log did not keep (it counts
            against every load).
        success: The attempt ended with the product on the table.
        by_feel: It was carried on by feel alone (κ̂ below τ: gate.after_probe), not by κ̂'s confidence.
    """

    traction: float
    success: bool
    by_feel: bool = False

    @classmethod
    def of(
        cls, held_fast: bool, traction: float | None, success: bool, by_feel: bool = False
    ) -> FeltCarry | None:
        """An attempt as the held-fast record keeps it: None unless its probe felt the product held fast. A load
        not measured (an older log's outcome) keeps a fall at load 0, against every load, and drops a success."""
        if not held_fast:
            return None
        if traction is None or not math.isfinite(traction):
            return None if success else cls(0.0, False, by_feel)
        return cls(float(traction), success, by_feel)


@dataclass(frozen=True)
class BudgetCounts:
    """What the robot has done so far, as the budget reads it.

    Attributes:
        attempts: Labelled attempts, exploratory ones included.
        failures: Failures among them.
        explored_failures: Exploratory attempts that failed.
        learnt: Outcomes κ̂ has learnt from (stored experience included).
        held_fast: The attempts carried on after a probe that felt the product held fast (gate.probe.held_fast),
            in order, each with the load it felt; counted within ``attempts``.
    """

    attempts: int = 0
    failures: int = 0
    explored_failures: int = 0
    learnt: int = 0
    held_fast: tuple[FeltCarry, ...] = ()

    def held_fast_record(self, traction: float | None = None) -> BudgetCounts:
        """The held-fast carries as counts of their own (`has_credit` on them: may one more such carry fail
        within the promise?).

        With ``traction`` (the load over the grip the next carry's probe felt; None or not finite: the whole
        record), only the carries that say something about a product felt that heavy: those that failed although
        felt no heavier, and those that held although felt no lighter. Slipping in the carry grows with the load
        the fingers hold (the carry's accelerations add to it in proportion), so a fall at a lighter load counts
        against this one and a success at a heavier load for it; a success at a lighter load or a fall at a
        heavier one says nothing. On slippery fingers a 0.3 kg bottle held fast in the probe and fell in the carry
        while 0.15 kg jars arrived: the whole record ran out for both, this one does not for the jars
        (docs/results/probe.md).
        """
        if traction is None or not math.isfinite(traction):
            return _record(self.held_fast)
        return _record(
            c
            for c in self.held_fast
            if (c.traction <= traction and not c.success) or (c.traction >= traction and c.success)
        )

    def by_feel_record(self) -> BudgetCounts:
        """The carries made by feel alone, as counts of their own: the record read at a load never counts a fall
        felt heavier, so falls at ever lighter loads would each find it clean; this one bounds them all."""
        return _record(c for c in self.held_fast if c.by_feel)


def _record(carries: Iterable[FeltCarry]) -> BudgetCounts:
    """Carries as counts of their own: (attempts, failures)."""
    kept = tuple(carries)
    return BudgetCounts(len(kept), sum(not c.success for c in kept))


def initial_threshold(options: BudgetOptions) -> float:
    """τ₀ = max(τ_min, 1 − kα) with k = ``start_margin`` (5), capped at τ_max."""
    start = 1.0 - options.start_margin * options.target_failure_rate
    return min(options.tau_max, max(options.tau_min, start))


def threshold(options: BudgetOptions, counts: BudgetCounts) -> float:
    """The confidence an action needs now for ACT (module docstring)."""
    excess = excess_failures(options, counts)
    raw = initial_threshold(options) + options.step * excess
    return min(options.tau_max, max(options.tau_min, raw))


def excess_failures(options: BudgetOptions, counts: BudgetCounts) -> float:
    """F − α · A: failures beyond the budget so far (negative while successes have earned credit)."""
    return counts.failures - options.target_failure_rate * counts.attempts


def has_credit(options: BudgetOptions, counts: BudgetCounts) -> bool:
    """Whether one more attempt may fail within the promise: F + 1 ≤ α · (A + 1) + excess_allowance (always
    True without an allowance)."""
    if options.excess_allowance is None:
        return True
    after = BudgetCounts(counts.attempts + 1, counts.failures + 1)
    # a hair of tolerance: α · A is a float product, and the bound itself is allowed
    return excess_failures(options, after) <= options.excess_allowance + 1e-9


def may_explore(options: BudgetOptions, counts: BudgetCounts) -> bool:
    """Whether an action below τ may still be tried to learn (before the seeded draw): still learning, and
    credit left (`has_credit`)."""
    return (
        counts.learnt < options.explore_until
        and counts.explored_failures < options.explore_failures
        and has_credit(options, counts)
    )


def too_wide(width_m: float | None, opening_m: float | None) -> bool:
    """Whether a product measured ``width_m`` across (its narrowest horizontal extent, metres; None or NaN:
    not measured) is wider than a gripper that opens ``opening_m`` (metres; None: unknown)."""
    if width_m is None or opening_m is None or not math.isfinite(width_m):
        return False
    return width_m > opening_m
