"""ConfidenceGate (κ̂): predict success for the ranked actions and decide to act, ask or wait."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import py_trees

from scone_bt.affordances.types import action_text, object_of_action
from scone_bt.behaviours.base import Keys, StageBehaviour
from scone_bt.gate.types import Decision, DecisionKind

__all__ = ["ConfidenceGate", "DecisionIs"]


class ConfidenceGate(StageBehaviour):
    READS = (Keys.RANKED, Keys.ACTION_EMBEDDINGS, Keys.INSTRUCTION, Keys.STEP)
    WRITES = (Keys.CONFIDENCES, Keys.DECISION)

    def setup(self, **kwargs: object) -> None:
        from scone_bt.gate import GateOptions

        self.estimator = self.services.estimator()
        opts = self.services.options
        self.gate_options = GateOptions(
            confidence_threshold=opts.confidence_threshold,
            relevance_threshold=opts.relevance_threshold,
            use_self_confidence=opts.use_self_confidence,
            recipe_aware=opts.recipe_aware,
        )

    def update(self) -> py_trees.common.Status:
        from scone_bt.gate import decide

        ranked = self.read(Keys.RANKED, [])
        vectors = self.read(Keys.ACTION_EMBEDDINGS, {})
        confidences = (
            [float(c) for c in self.estimator.predict(np.stack([vectors[r.text] for r in ranked]))]
            if ranked
            else []
        )
        view = self.read(Keys.STEP)
        ambiguous = tuple(action_text(i) for i in view.selection.ambiguous) if view is not None else ()
        by_text = {r.text for r in ranked}
        decision = decide(ranked, confidences, self.gate_options, tuple(a for a in ambiguous if a in by_text))
        decision = self._failure_limit(decision)
        if decision.kind is DecisionKind.IDLE and view is not None:
            shelf = {object_of_action(r.text) for r in ranked}
            missing = [i for i in view.selection.named if i not in shelf]
            if missing:  # the step names an item the robot sees neither on the shelf nor on the table
                decision = replace(decision, reason=f"waiting: {', '.join(missing)} not in sight")
        self.write(Keys.CONFIDENCES, dict(zip([r.text for r in ranked], confidences, strict=True)))
        self.write(Keys.DECISION, decision)
        instruction = self.read(Keys.INSTRUCTION) or ""
        self.services.report_decision(instruction, decision, None if view is None else view.index)
        self.feedback_message = decision.reason
        return py_trees.common.Status.SUCCESS

    def _failure_limit(self, decision: Decision) -> Decision:
        """The paper's rule: after N failures on the same action, ask for help whatever κ̂ says."""
        limit = self.services.options.max_failures_per_action
        failed = self.services.stats.failures_by_action.get(decision.action or "", 0)
        if decision.kind is DecisionKind.ACT and decision.action is not None and failed >= limit:
            return replace(decision, kind=DecisionKind.ASK, reason=f"failed {limit} times on this action")
        return decision


class DecisionIs(StageBehaviour):
    """Condition: SUCCESS if the gate's decision is of the given kind."""

    READS = (Keys.DECISION,)

    def __init__(self, name: str, services: object, kind: str) -> None:
        super().__init__(name, services)  # type: ignore[arg-type]
        self.kind = DecisionKind(kind)

    def update(self) -> py_trees.common.Status:
        decision = self.read(Keys.DECISION)
        ok = decision is not None and decision.kind is self.kind
        return py_trees.common.Status.SUCCESS if ok else py_trees.common.Status.FAILURE
