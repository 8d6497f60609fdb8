"""When to heft a product before committing: the probe band around the budget's threshold.

An action κ̂ is sure of is acted on (κ̂ ≥ τ + ``above``) or asked about (κ̂ < τ − ``below``) as before. In between
κ̂ is unsure, and a grasp and a 1–2 cm lift tell more than asking does (motion.probe): the robot probes, then
carries on or sets the product back and asks (gate.after_probe decides which). A probe is not an exploration: it
needs no exploration credit, with or without the strict promise (``exploration_credit: true``): a robot with no
credit asks, or probes. A product that slips is set back, not dropped; what the probe cannot catch (a product that
holds in the probe and falls later, or one the fingers never got hold of) counts against the budget like any
attempt. Whether what it felt lets it carry on is gate.after_probe's: κ̂ on the context after the probe, a product
held fast (`held_fast`, on its own record), or the strict rule's credit. ``credit`` makes a probe below τ need
credit too (`probe_credit`: tried, docs/results/probe.md; it left a cold robot whose first attempt failed asking
for everything).

The band below τ narrows with the promise: at a target failure rate α under ``full_band_at`` it is
``below · (α / full_band_at)⁴`` (`band_below`). A probe that passes still carries on a product that may fall later
(about one in eight of those the fingers held fast, on the development streams), so at a strict α the robot probes
only what κ̂ is nearly sure of; at α ≥ ``full_band_at`` every action down to ``below`` under τ is probed. The
power was chosen on `tools/data/sc_probe` (docs/results/probe.md): the smallest of 1–4 that keeps the realised
rate within α + 0.02 at α = 0.05, 0.10, 0.15 and 0.20.

`ProbeOptions` carries the band and the motion's settings (the tree file's ``probe:`` parameters, validated here:
one line naming the key and its range); `in_band` is a pure function.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

from scone_bt.config.ranges import Range
from scone_bt.config.tree_parameters import PROBE_RANGES, TREE_DEFAULTS

if TYPE_CHECKING:
    from scone_bt.gate.budget import BudgetCounts, BudgetOptions

__all__ = [
    "ProbeOptions",
    "in_band",
    "band_below",
    "probe_credit",
    "feel_credit",
    "feel_doubt",
    "FELL_NO_HEAVIER",
    "FELL_BY_FEEL",
    "held_fast",
    "NARROWING_POWER",
]

NARROWING_POWER = 4.0
"""How fast the band below τ narrows under ``full_band_at`` (`band_below`)."""


@dataclass(frozen=True)
class ProbeOptions:
    """The probe band and the heft test's motion.

    Attributes:
        below: Probe actions down to this far below the threshold τ (probability), in [0, 1], at a target
            failure rate of ``full_band_at`` or more (`band_below`).
        above: Probe actions up to this far above τ (probability), in [0, 1]; 0 probes only what would be asked.
        lift_m: How far the product is lifted, metres, in [0.005, 0.05].
        hold_s: How long it is held up while the fingers feel it, seconds, in [0.1, 3].
        max_unsteady: Set back when the felt load changes by more than this share during the hold, in (0, 1].
        max_traction: Set back when the felt load over the grip force exceeds this, in (0, 10].
        full_band_at: Under this target failure rate α the band below τ narrows (`band_below`), in [0, 1); 0:
            never.
        credit: A probe below τ is made only while one more failure keeps failures ≤ α × attempts + ``credit``
            (gate.budget.has_credit with this allowance), in [0, 100]; None (the default): a probe needs no
            credit.
        sure_traction: A probe whose fingers held the product fast (the hard judge passed) with the load at most
            this share of the grip, in (0, ``max_traction``], lets it carry on although κ̂ is unsure, while such
            carries keep the promise on their own record (`held_fast`, gate.after_probe): a third of the
            friction limit the judge sets back at.
        feel_allowance: Such carries by feel go on while one more failure keeps their failures ≤ α × their
            attempts + this (gate.budget.has_credit on `BudgetCounts.held_fast_record` at the load this probe felt:
            the carries felt no heavier that fell, no lighter that held), in [0, 100]. 2: a held-fast carry that
            fails before any success does not end the rule (`gate.after_probe`).

    The intervals are config.tree_parameters.PROBE_RANGES (the tree file's own, and the judge's limits).
    """

    below: float = TREE_DEFAULTS.probe.below
    above: float = TREE_DEFAULTS.probe.above
    lift_m: float = TREE_DEFAULTS.probe.lift_m
    hold_s: float = TREE_DEFAULTS.probe.hold_s
    max_unsteady: float = 0.01
    max_traction: float = 0.3
    credit: float | None = None
    full_band_at: float = TREE_DEFAULTS.probe.full_band_at
    sure_traction: float = 0.1
    feel_allowance: float = 2.0

    def __post_init__(self) -> None:
        for name, allowed in PROBE_RANGES.items():
            allowed.check(f"probe.{name}", getattr(self, name))
        if self.credit is not None:
            Range(0.0, 100.0).check("probe.credit", self.credit)
        Range(0.0, 100.0).check("probe.feel_allowance", self.feel_allowance)
        sure = Range(0.0, float(self.max_traction), low_open=True)  # its upper end is another field's value
        sure.check("probe.sure_traction (at most max_traction)", self.sure_traction)

    @classmethod
    def of(cls, params: object) -> ProbeOptions | None:
        """From a tree file's validated ``probe:`` section (config.tree_parameters.ProbeParameters, read by its
        attributes); None when it is not enabled."""
        if not getattr(params, "enabled", True):
            return None
        names = ("below", "above", "lift_m", "hold_s", "full_band_at")
        return cls(**{n: getattr(params, n) for n in names if hasattr(params, n)})


def band_below(options: ProbeOptions, alpha: float | None) -> float:
    """How far below τ the robot probes at target failure rate ``alpha`` (None: no budget, the full band)."""
    if alpha is None or options.full_band_at <= 0.0 or alpha >= options.full_band_at:
        return options.below
    return options.below * (alpha / options.full_band_at) ** NARROWING_POWER


def in_band(
    confidence: float,
    threshold: float,
    options: ProbeOptions | None,
    credit: bool = True,
    alpha: float | None = None,
) -> bool:
    """Whether κ̂'s ``confidence`` is unsure enough, against the gate's ``threshold``, to probe first.

    ``credit``: whether the failure budget has room for one more failure within ``options.credit``
    (`probe_credit`); read only below the threshold. ``alpha``: the budget's target failure rate (the band below
    τ narrows under ``options.full_band_at``, `band_below`); None: the full band.
    """
    if options is None or not math.isfinite(confidence):
        return False
    if confidence < threshold and not credit:
        return False
    return threshold - band_below(options, alpha) <= confidence < threshold + options.above


def probe_credit(options: ProbeOptions | None, budget: BudgetOptions, counts: BudgetCounts) -> bool:
    """Whether a probe below τ may be made: always, unless ``options.credit`` is set (then gate.budget.has_credit
    with that allowance). A probe is not an exploration (module docstring)."""
    from dataclasses import replace

    from scone_bt.gate.budget import has_credit

    if options is None or options.credit is None:
        return True
    return has_credit(replace(budget, excess_allowance=options.credit), counts)


FELL_NO_HEAVIER = "as products I felt no heavier have fallen from my fingers"
"""Why a product held fast is not carried by feel: the held-fast record at its load has run out (`feel_doubt`)."""
FELL_BY_FEEL = "as what I carried by feel alone has fallen too often"
"""Why a product held fast is not carried by feel: the carries by feel have spent their own record (`feel_doubt`)."""


def feel_doubt(
    options: ProbeOptions | None, budget: BudgetOptions, counts: BudgetCounts, traction: float | None = None
) -> str | None:
    """None where one more carry by feel may fail within its own promise, else why not, in the robot's words.

    The promise: gate.budget.has_credit, with ``options.feel_allowance``, on the held-fast record read at this
    load (`BudgetCounts.held_fast_record`: with ``traction``, the load over the grip this probe felt, the carries
    felt no heavier that fell and no lighter that held; else `FELL_NO_HEAVIER`) and on the carries made by feel so
    far (`BudgetCounts.by_feel_record`, which bounds falls at ever lighter loads; else `FELL_BY_FEEL`). Without a
    probe there is no feel to carry on: "".
    """
    from dataclasses import replace

    from scone_bt.gate.budget import has_credit

    if options is None:
        return ""
    own = replace(budget, excess_allowance=options.feel_allowance)
    if not has_credit(own, counts.held_fast_record(traction)):
        return FELL_NO_HEAVIER
    if not has_credit(own, counts.by_feel_record()):
        return FELL_BY_FEEL
    return None


def feel_credit(
    options: ProbeOptions | None, budget: BudgetOptions, counts: BudgetCounts, traction: float | None = None
) -> bool:
    """Whether one more carry by feel may fail within its own promise (`feel_doubt` finds nothing against it)."""
    return feel_doubt(options, budget, counts, traction) is None


def held_fast(options: ProbeOptions | None, traction: float | None) -> bool:
    """Whether a probe that passed the hard judge felt the product held fast: its load at most ``sure_traction``
    of the grip (``traction``: load over grip; None or NaN: not measured, or pressed down rather than lifted)."""
    return options is not None and traction is not None and 0.0 <= traction <= options.sure_traction
