"""The tree's judge after a heft test: gate.after_probe, given to the probe's controller (motion.probe).

The gate decides to probe; the arm lifts and holds the product; this judge then decides from what the fingers
felt: the hard safety judge (motion.probe.judge_probe), κ̂ on the context after the probe (experience.felt), a
product held fast (gate.probe.held_fast, on its own record) and the strict rule's credit, with the budget's counts
as they were at the decision (a probe changes none of them).
The replay (``scone-bench gate --probe``) calls the same gate.after_probe on its recorded readings.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from scone_bt.behaviours.ports import SelfConfidence
from scone_bt.confidence.grounded import kappa_rows
from scone_bt.experience.felt import felt_context
from scone_bt.experience.types import ExecutionContext
from scone_bt.gate.after_probe import ProbeVerdict, after_probe
from scone_bt.gate.budget import BudgetCounts
from scone_bt.gate.rules import GateRules
from scone_bt.motion.probe import ProbeReading, ProbeSettings, judge_probe

__all__ = ["ProbeJudge", "belief_of"]


def belief_of(estimator: SelfConfidence, vector: np.ndarray, context: ExecutionContext | None) -> float:
    """κ̂'s belief in [0, 1] for one action in one context (no exploration draw: that would move κ̂'s seeded
    stream)."""
    X = kappa_rows(estimator, np.asarray(vector, dtype=np.float64)[None], [context])
    belief = getattr(estimator, "belief", None) or estimator.predict
    return float(belief(X)[0])


class ProbeJudge:
    """(carry on, the robot's words) from a probe's reading; keeps its last `verdict` (gate.after_probe's).

    Args:
        rules: The gate's rules.
        counts: The budget's counts at the decision to probe.
        item: The product's name.
        settings: The probe's hard thresholds.
        kappa: κ̂'s belief for the action in a context (`belief_of` bound to κ̂ and the action's embedding).
        context: The context perceived when the gate decided.
    """

    def __init__(
        self,
        rules: GateRules,
        counts: BudgetCounts,
        item: str,
        settings: ProbeSettings,
        kappa: Callable[[ExecutionContext | None], float],
        context: ExecutionContext | None,
    ) -> None:
        self.rules = rules
        self.counts = counts
        self.item = item
        self.settings = settings
        self._kappa = kappa
        self.context = context
        self.verdict: ProbeVerdict | None = None

    def __call__(self, reading: ProbeReading) -> tuple[bool, str]:
        after = felt_context(self.context, reading)
        self.verdict = after_probe(
            self.rules,
            self.counts,
            self.item,
            judge_probe(reading, self.settings),
            self._kappa(after),
            reading.lift_traction,
        )
        return self.verdict.carry, self.verdict.reason
