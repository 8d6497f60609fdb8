"""The named steps `ConfidenceGate` runs each tick, free of py_trees: what it sees, how it reports."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from scone_bt.affordances.types import Affordance
from scone_bt.behaviours.ports import AttemptHistory, ContextSource, SelfConfidence
from scone_bt.confidence.grounded import kappa_rows
from scone_bt.events import DecisionMade
from scone_bt.experience.types import ExecutionContext
from scone_bt.gate.budget import BudgetCounts
from scone_bt.gate.rules import ask_for_missing, waiting
from scone_bt.gate.types import LOOKING_AGAIN, Decision, DecisionKind
from scone_bt.perception.types import Detection, Frame
from scone_bt.relevance.types import RankedAction

__all__ = [
    "CARD_ITEMS_LEFT",
    "EVERY_STEP_SERVED",
    "gate_counts",
    "candidate_contexts",
    "confidences",
    "decision_event",
    "past_the_end",
    "probe_reasons",
    "settle_idle",
    "look_again_first",
    "shown_target",
]

EVERY_STEP_SERVED = "(every step is served)"
"""The instruction a decision reports past the recipe's last step, with nothing of the card left to fetch."""
CARD_ITEMS_LEFT = "(past the last step: items on the card)"
"""The instruction a decision reports past the recipe's last step while items of the card that no open step names
are still on the shelf (fetched as needed later; e.g. after the human answered "none of those" to a question)."""


def candidate_contexts(
    source: ContextSource | None,
    candidates: list[Affordance],
    detections: Sequence[Detection],
    frames: Mapping[str, Frame],
) -> dict[str, ExecutionContext]:
    """Each candidate affordance's execution context by action text, from this tick's perception."""
    if source is None or not candidates:
        return {}
    by_name = source([a.detection for a in candidates], detections, frames)
    return {a.text: by_name[a.object_name] for a in candidates if a.object_name in by_name}


def confidences(
    estimator: SelfConfidence,
    ranked: Sequence[RankedAction],
    vectors: Mapping[str, np.ndarray],
    contexts: Mapping[str, ExecutionContext],
) -> tuple[list[float], list[bool]]:
    """κ̂'s belief per ranked action, and the ε-greedy exploration draws (empty for estimators that do not explore).

    A grounded κ̂ (is_grounded) predicts from the embeddings followed by the contexts, any other from the
    embeddings alone. The belief is what the gate compares, prints and logs; an exploration draw only lets the
    gate act despite it (gate rule 4), so a user never reads a draw as a confidence.
    """
    if not ranked:
        return [], []
    X = kappa_rows(
        estimator, np.stack([vectors[r.text] for r in ranked]), [contexts.get(r.text) for r in ranked]
    )
    belief, explores = getattr(estimator, "belief", None), getattr(estimator, "explores", None)
    if belief is None or explores is None:
        return [float(c) for c in estimator.predict(X)], []
    return [float(c) for c in belief(X)], [bool(e) for e in explores(X)]


def gate_counts(history: AttemptHistory, estimator: SelfConfidence) -> BudgetCounts:
    """The attempts so far (folded from the events) and what κ̂ has learnt, as the budget reads them."""
    attempts, failures, explored_failures = history.budget_counts()
    learnt = int(getattr(estimator, "n_observations", 0))
    return BudgetCounts(attempts, failures, explored_failures, learnt, history.held_fast_carries())


def probe_reasons(history: AttemptHistory, ranked: Sequence[RankedAction]) -> dict[str, str]:
    """Why a heft test set each candidate's product back in this episode (only those it did)."""
    reasons = {r.text: history.probe_reason(r.text) for r in ranked}
    return {text: why for text, why in reasons.items() if why is not None}


def look_again_first(
    decision: Decision, missing: tuple[str, ...], looked_again: set[str]
) -> tuple[Decision, tuple[str, ...]]:
    """An IDLE decision while the step's items are seen nowhere, some of them not looked for again yet: wait one
    tick (IDLE, rule "missing", "(looking again)") while the next look averages several frames (perception.exposure),
    and return those items (added to ``looked_again``: once each). Otherwise the decision unchanged and ()."""
    if decision.kind is not DecisionKind.IDLE:
        return decision, ()
    new = tuple(i for i in missing if i not in looked_again)
    if not new:
        return decision, ()
    looked_again.update(new)
    return waiting(new, LOOKING_AGAIN, "missing"), new


def settle_idle(
    decision: Decision, missing: tuple[str, ...], budget_gate: bool, asked_missing: set[str]
) -> Decision:
    """An IDLE decision while the step's items are seen nowhere: the budget gate asks for them (once each, noted
    in ``asked_missing``); the paper's robot does not ask for what it cannot see: it says what it waits for."""
    if decision.kind is not DecisionKind.IDLE or not missing:
        return decision
    if budget_gate:
        return ask_for_missing(decision, missing, asked_missing)
    return waiting(missing, "", "")


def shown_target(decision: Decision, target: Affordance | None) -> Affordance | None:
    """The affordance the decision is about: its ACT target, or the one an ASK asks about (none for a missing
    item's ask, or for IDLE)."""
    if decision.kind is DecisionKind.ACT:
        return target
    return target if decision.kind is DecisionKind.ASK and decision.rule != "missing" else None


def past_the_end(later: bool) -> str:
    """What a decision past the recipe's last step is about: nothing left, or the card's leftover ``later`` items."""
    return CARD_ITEMS_LEFT if later else EVERY_STEP_SERVED


def decision_event(
    decision: Decision,
    *,
    sim_time: float,
    step: int,
    instruction: str,
    context: ExecutionContext | None,
    planning_s: float | None,
) -> DecisionMade:
    """The `DecisionMade` event for ``decision`` (``planning_s``: seconds planned before committing, or None)."""
    return DecisionMade(
        sim_time=sim_time,
        step=step,
        instruction=instruction,
        action=decision.action,
        relevance=decision.relevance,
        confidence=decision.confidence,
        verdict=decision.kind,
        need=decision.need,
        candidates=tuple(decision.candidates),
        object_name=decision.object_name,
        reason=decision.reason,
        explored=decision.explored,
        context=context,
        rule=decision.rule,
        planning_s=None if planning_s is None else round(planning_s, 4),
        probe=decision.probe,
    )
