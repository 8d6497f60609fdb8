"""The decision after the heft test: carry the product on, or set it back and ask (`after_probe`).

One pure function for the robot and the benchmark: the tree passes it to the probe's controller as its judge
(behaviours.probe_judge.ProbeJudge), the replay (``scone-bench gate --probe``) calls it on each recorded reading.
In order:

1. The hard safety judge (motion.probe.judge_probe: the fingers lost it, the load slid, the grip is near its
   friction limit): set back, in its words ("the olive oil slips in my fingers").
2. Without the strict promise (``exploration_credit: false``: the budget has no ``excess_allowance``) a product
   that held carries on, as before.
3. κ̂ again, on the context after the probe (what the fingers felt, experience.felt): at or above the threshold τ
   it carries on as a *confident* attempt.
4. Held fast (gate.probe.held_fast: the load at most ``sure_traction`` of the grip, a third of the friction limit
   the judge sets back at): it carries on, confident *by feel*, while the attempts after such probes keep a
   promise on their own record (one more failure keeps their failures ≤ α × their attempts + ``feel_allowance``,
   2: gate.budget.has_credit on `BudgetCounts.held_fast_record`). The record is read at the load this probe felt:
   the held-fast carries that fell although felt no heavier, and those that arrived although felt no lighter. A
   product held that fast does not slip from the carry's accelerations; when on this robot it fails anyway
   (slippery fingers, a drop at the place), the record at that load and above runs out and the rule stops there,
   while lighter products that arrived keep it for what is felt as light. The carries made by feel keep the same
   promise on their own (`BudgetCounts.by_feel_record`): a fall felt heavier says nothing at a lighter load, so
   without it falls at ever lighter loads would each find a clean record. Why 2 and not the budget's 1: a cold
   robot whose first carry held fast and failed anyway (a bag of seeds set down on its side) has spent the
   budget's credit and this record's at once, and κ̂, having seen only failures, is never sure again: the robot
   asked for everything after, 4 of 110 cold starts of the development streams (docs/results/probe.md). With 2
   the record sees a second held-fast carry first.
5. Below τ it carries on only while the strict rule's credit allows one more failure (gate.budget.has_credit):
   an *explored* attempt (a failure counts as an explored failure).
6. Else it is set back and the robot asks: "I am not sure I can carry the olive oil: please bring it" (where it
   held fast, with why it was not carried by feel: "…, as products I felt no heavier have fallen from my fingers",
   gate.probe.feel_doubt). κ̂ learns nothing from that (as from an ask); it learns a failure only from what the
   hard judge set back.

So with the strict promise on, every attempt whose κ̂ at the final decision was below τ was made on credit: the
budget's (explored) or the held-fast record's (by feel). Failures beyond α · attempts + 1 come from confident
attempts, by κ̂ or by feel, or from what a probe cannot feel before the grasp (fingers closing on nothing): a probe
needs no credit (gate.probe).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import partial

from scone_bt.gate.budget import BudgetCounts, has_credit
from scone_bt.gate.probe import feel_doubt, held_fast
from scone_bt.gate.rules import GateRules, threshold_options

__all__ = ["ProbeVerdict", "after_probe"]


@dataclass(frozen=True)
class ProbeVerdict:
    """What the robot does once it has hefted a product.

    Attributes:
        carry: Carry it on (else it is set back where it stood: an aborted attempt).
        reason: The robot's words for setting it back ("the jar slips in my fingers"); "" when it carries on.
        explored: It carries on although κ̂ after the probe is below τ, on the strict rule's credit.
        confidence: κ̂ on the context after the probe, in [0, 1] (asked even when the hard judge sets back).
        threshold: τ it was compared with (probability).
        felt_unsafe: Set back on the hard judge's word (the fingers felt it slip or strain): a label κ̂ learns
            (it could not carry it). A set-back on κ̂'s own doubt teaches nothing, like an ask: learning it as a
            failure would only confirm the doubt.
        held_fast: The probe felt the product held fast (gate.probe.held_fast), whatever it then did: an attempt
            that carries on counts in `BudgetCounts.held_fast_record`.
        by_feel: It carries on because it felt held fast, with κ̂ below τ (confident by feel, step 4).
        traction: The load over the grip the probe felt (motion.probe.ProbeReading.lift_traction; None where not
            measured): where a carry that felt it held fast sits in the held-fast record.
    """

    carry: bool
    reason: str = ""
    explored: bool = False
    confidence: float = math.nan
    threshold: float = math.nan
    felt_unsafe: bool = False
    held_fast: bool = False
    by_feel: bool = False
    traction: float | None = None

    @property
    def confident(self) -> bool:
        """It carries on with κ̂ after the probe at or above τ, or by feel."""
        return self.carry and not self.explored and (self.by_feel or self.confidence >= self.threshold)


def after_probe(
    rules: GateRules,
    counts: BudgetCounts,
    item: str,
    felt: tuple[bool, str],
    confidence: float,
    traction: float | None = None,
) -> ProbeVerdict:
    """Carry on or set back (module docstring).

    Args:
        rules: The gate's rules (the budget's τ and its strict rule).
        counts: The attempts so far, as at the decision to probe (a probe changes none of them).
        item: The product's name, for the robot's words.
        felt: The hard judge's (carry on, why not) on the probe's reading, e.g. (False, "slips in my fingers").
        confidence: κ̂ on the context after the probe (experience.felt).
        traction: The load the fingers felt over their grip (motion.probe.ProbeReading.lift_traction); None
            where it was not measured or the fingers pressed the product down rather than lifted it.
    """
    tau = threshold_options(rules, counts)[0].act_threshold
    holds, why = felt
    verdict = partial(ProbeVerdict, confidence=confidence, threshold=tau, traction=traction)
    if not holds:
        return verdict(False, f"the {item} {why}", felt_unsafe=True)
    fast = held_fast(rules.probe, traction)
    budget = rules.budget
    if budget is None or budget.excess_allowance is None or confidence >= tau:
        return verdict(True, held_fast=fast)
    doubt = feel_doubt(rules.probe, budget, counts, traction) if fast else ""
    if doubt is None:
        return verdict(True, held_fast=True, by_feel=True)
    if has_credit(budget, counts):
        return verdict(True, explored=True, held_fast=fast)
    why = f", {doubt}" if doubt else ""  # held fast but its record ran out: say which
    return verdict(False, f"I am not sure I can carry the {item}{why}", held_fast=fast)
