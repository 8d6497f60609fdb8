"""The gate's decision."""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum

__all__ = ["DecisionKind", "Decision", "DECISION_RULES", "LOOKING_AGAIN"]

DECISION_RULES: tuple[str, ...] = (
    "failure-limit",
    "infeasible",
    "missing",
    "declined",
    "too-wide",
    "self-confidence-off",
    "probe",
)
"""Every `Decision.rule` other than "" (κ̂ against the threshold decided): what a scenario's event match, the printer
and the tablet may name (`DecisionMade.rule` says what each means)."""

LOOKING_AGAIN = " (looking again)"
"""The note that ends a wait's reason while the next look averages frames for what the robot sees nowhere
(behaviours.gate_steps.look_again_first; the tablet reads it, study.words)."""


class DecisionKind(StrEnum):
    ACT = "act"  # confident enough: attempt the action
    ASK = "ask"  # ASK-HELP: not confident it can do the action; ask the human to do it
    CLARIFY = "clarify"  # ASK-CLARIFY: cannot tell which item the step wants; ask which one
    IDLE = "idle"  # no relevant action for the current instruction

    @property
    def label(self) -> str:
        """How the decision line and the viewers show it (ACT, ASK-HELP, ASK-CLARIFY, IDLE)."""
        return {"ask": "ASK-HELP", "clarify": "ASK-CLARIFY"}.get(self.value, self.value.upper())


@dataclass(frozen=True)
class Decision:
    """What the robot will do this cycle.

    Attributes:
        kind: act, ask (for help), clarify or idle.
        action: The chosen action text (None when idle or clarifying).
        relevance: Its cosine similarity to the instruction.
        confidence: κ̂'s success probability for it, in [0, 1].
        reason: One short sentence a user can read in the log.
        need: "now", "later" (recipe-aware ranking) or "" (the step's text alone).
        candidates: With clarify, the action texts the robot asks the human to choose between.
        object_name: The object the action moves (set by the tree's gate from the affordance it is about; None
            when idle or clarifying).
        explored: ACT although κ̂ was below the threshold, because the ε-greedy estimator drew exploration for
            this action (the robot tries it to learn; ``confidence`` is still κ̂'s belief).
        rule: What decided when it was not κ̂ against the threshold (see `DecisionMade.rule`); "" otherwise.
        probe: ACT, but heft the product first (κ̂ is unsure: within the probe band; gate.probe).
    """

    kind: DecisionKind
    action: str | None
    relevance: float
    confidence: float
    reason: str
    need: str = ""
    candidates: tuple[str, ...] = ()
    object_name: str | None = None
    explored: bool = False
    rule: str = ""
    probe: bool = False
