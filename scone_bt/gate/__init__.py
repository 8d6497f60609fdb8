"""The gate: act on the best relevant action when κ̂ is confident enough, otherwise ask for help with it.

Start at `gate_decision` (rules.py): the one pure function the robot's `ConfidenceGate` and ``scone-bench gate``
both call. It takes the threshold from the failure budget (budget.py) or the paper's fixed one, applies the
paper's relevance and threshold rules (`decide`, gate.py), then the rules that overrule them (the failure limit,
the heft test of probe.py, a product too wide to grasp). after_probe.py decides once a heft test has felt the
product.
"""

from scone_bt.gate.gate import GateOptions, decide
from scone_bt.gate.rules import GateInput, GateResult, GateRules, gate_decision
from scone_bt.gate.types import Decision, DecisionKind

__all__ = [
    "Decision",
    "DecisionKind",
    "GateInput",
    "GateOptions",
    "GateResult",
    "GateRules",
    "decide",
    "gate_decision",
]
