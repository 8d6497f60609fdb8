"""The gate: act on the best relevant action when κ̂ is confident enough, otherwise ask for help with it."""

from scone_bt.gate.gate import GateOptions, decide
from scone_bt.gate.types import Decision, DecisionKind

__all__ = ["Decision", "DecisionKind", "GateOptions", "decide"]
