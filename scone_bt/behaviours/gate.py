"""ConfidenceGate (κ̂): predict success for the ranked actions and decide to act, ask or wait."""

from __future__ import annotations

import time
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np
import py_trees

from scone_bt.affordances.types import Affordance, action_text
from scone_bt.behaviours.base import Keys, StageBehaviour
from scone_bt.behaviours.context import EpisodeContext
from scone_bt.behaviours.pick_and_place import pick_request, scene_key
from scone_bt.behaviours.ports import (
    AttemptHistory,
    Clock,
    ContextSource,
    HumanChannel,
    PlannerSeeds,
    Provider,
    SelfConfidence,
)
from scone_bt.confidence.grounded import grounded_features, is_grounded
from scone_bt.events import DecisionMade, EventSink
from scone_bt.experience.types import ExecutionContext
from scone_bt.gate.budget import BudgetCounts, BudgetOptions
from scone_bt.gate.probe import ProbeOptions
from scone_bt.gate.rules import (
    GateInput,
    GateRules,
    apply_failure_limit,
    ask_for_missing,
    gate_decision,
    infeasible_decision,
    say_infeasible,
    waiting,
)
from scone_bt.gate.types import Decision, DecisionKind
from scone_bt.relevance.types import RankedAction
from scone_bt.robot.interface import Infeasible, PlannedPick, Robot

if TYPE_CHECKING:
    from scone_bt.gate import GateOptions

# apply_failure_limit and say_infeasible live in scone_bt.gate.rules; kept here for their callers
__all__ = ["ConfidenceGate", "DecisionIs", "apply_failure_limit", "say_infeasible"]

EVERY_STEP_SERVED = "(every step is served)"
"""The instruction a decision reports past the recipe's last step, with nothing of the card left to fetch."""
CARD_ITEMS_LEFT = "(past the last step: items on the card)"
"""The instruction a decision reports past the recipe's last step while items of the card that no open step names
are still on the shelf (fetched as needed later; e.g. after the human answered "none of those" to a question)."""


@dataclass(frozen=True)
class _Pending:
    """A decision waiting for its plan (plan before commit)."""

    decision: Decision
    target: Affordance | None
    contexts: dict[str, ExecutionContext]
    step_index: int | None
    key: tuple[object, ...] = ()
    planned: PlannedPick | None = None
    started: float = 0.0


class ConfidenceGate(StageBehaviour):
    """Decides, writes the decision and the affordance it is about (`Keys.TARGET`), and emits `DecisionMade`.

    With ``budget`` (the tree's ``gate: budget``) the threshold is the failure budget's, recomputed every decision
    from the attempts folded from the events (scone_bt.gate.budget), and while the budget explores an action below
    it is tried on a seeded draw (``explored``); without, the fixed ``gate`` options decide (the paper's gate).

    A step that names an item the robot can see nowhere (and did not place) makes it ask for that item once
    (ASK-HELP, rule "missing") instead of idling until the human intervenes.

    When the human declined to fetch an item ("try it yourself"), the robot does not ask for it again: it
    attempts it (rule "declined") if it may (a plan exists, fewer than ``max_failures_per_action`` failures),
    else it waits for the human (IDLE, rule "declined"), so a refusal never makes it ask in a loop.

    With a context source it also builds each ranked action's ExecutionContext from this tick's perception
    (`Keys.CONTEXTS`, the target's in `Keys.TARGET_CONTEXT`, stored with its outcome); a grounded κ̂ (is_grounded)
    predicts from the embeddings followed by those contexts, any other κ̂ from the embeddings alone.
    """

    READS = (
        Keys.RANKED,
        Keys.ACTION_EMBEDDINGS,
        Keys.INSTRUCTION,
        Keys.STEP,
        Keys.AFFORDANCES,
        Keys.DETECTIONS,
        Keys.TABLE_DETECTIONS,
        Keys.FRAMES,
    )
    WRITES = (
        Keys.CONFIDENCES,
        Keys.DECISION,
        Keys.TARGET,
        Keys.CONTEXTS,
        Keys.TARGET_CONTEXT,
        Keys.PLANNED,
        Keys.PLAN_VERDICT,
        Keys.MOTION_COMPUTING,
    )

    def __init__(
        self,
        name: str,
        kappa: Provider[SelfConfidence],
        gate: GateOptions,
        max_failures_per_action: int,
        history: AttemptHistory,
        events: EventSink,
        clock: Clock,
        human: HumanChannel,
        steps_total: int,
        contexts: ContextSource | None = None,
        budget: BudgetOptions | None = None,
        seed: int = 0,
        robot: Robot | None = None,
        seeds: PlannerSeeds | None = None,
        opening_m: float | None = None,
        probe: ProbeOptions | None = None,
    ) -> None:
        """``human`` is read only for the human's current step in the recipe-blind setting (no tracked step).

        ``contexts`` builds execution contexts from the tick's detections and frames (None: none are built; a
        grounded κ̂ then sees every context value as missing).
        """
        super().__init__(name)
        self.contexts = contexts
        self._kappa = kappa
        self.gate_options = gate
        self.limit = max_failures_per_action
        self.history = history
        self.events = events
        self.clock = clock
        self.human = human
        self.steps_total = steps_total
        self.budget = budget
        self.seed = seed
        self._asked_missing: set[str] = set()
        self.robot = robot  # None: no planning before commitment (PickAndPlace plans when it starts)
        self.seeds = seeds
        self._pending: _Pending | None = None
        self._infeasible: dict[tuple[object, ...], Infeasible] = {}
        self.opening_m = opening_m  # None: no too-wide rule (the paper's gate)
        self.probe = probe  # None: no heft test (gate.probe)

    @classmethod
    def from_context(cls, name: str, context: EpisodeContext) -> ConfidenceGate:
        from scone_bt.gate import GateOptions
        from scone_bt.perception.context import ContextExtractor

        opts = context.options
        budget = (
            BudgetOptions(
                target_failure_rate=float(opts.target_failure_rate),
                excess_allowance=1.0 if opts.exploration_credit else None,
            )
            if opts.gate == "budget" and opts.use_self_confidence
            else None
        )
        return cls(
            name,
            context.kappa,
            GateOptions(
                confidence_threshold=opts.confidence_threshold,
                relevance_threshold=opts.relevance_threshold,
                use_self_confidence=opts.use_self_confidence,
                recipe_aware=opts.recipe_aware,
            ),
            int(opts.max_failures_per_action),
            context.history,
            context.events,
            context.robot.now,
            context.human,
            len(context.recipe.steps),
            ContextExtractor(context.scene, context.catalogue),
            budget=budget,
            seed=opts.seed,
            # planning before commitment and asking for unseen items come with the budget gate; the paper's gate
            # and its control condition stay as the paper ran them (Table I, the study's control)
            robot=context.robot if budget is not None else None,
            seeds=context.seeds,
            opening_m=context.gripper_opening_m if budget is not None else None,
            probe=ProbeOptions.of(opts.probe) if budget is not None and opts.probe is not None else None,
        )

    def setup(self, **kwargs: object) -> None:
        self.estimator = self._kappa()  # κ̂ rebuilt from the store on first use
        # the budget's exploration draws: their own seeded stream (κ̂'s draws are unchanged by them)
        self._rng = np.random.default_rng([self.seed, 0x6A7E])

    @property
    def rules(self) -> GateRules:
        """The gate's rules (scone_bt.gate.rules), as this behaviour was configured."""
        return GateRules(
            options=self.gate_options,
            budget=self.budget,
            exploration=self.budget,
            failure_limit=self.limit,
            opening_m=self.opening_m,
            probe=self.probe,
        )

    def _counts(self) -> BudgetCounts:
        """The attempts so far (folded from the events) and what κ̂ has learnt, as the budget reads them."""
        attempts, failures, explored_failures = self.history.budget_counts()
        return BudgetCounts(
            attempts, failures, explored_failures, int(getattr(self.estimator, "n_observations", 0))
        )

    def _seen(
        self, ranked: list[RankedAction], affordances: dict[str, Affordance]
    ) -> tuple[GateInput, dict[str, ExecutionContext]]:
        """What the gate sees this tick: κ̂ on the ranked actions, their contexts, the episode's counts."""
        vectors = self.read(Keys.ACTION_EMBEDDINGS, {})
        contexts = self._contexts([affordances[r.text] for r in ranked if r.text in affordances])
        if ranked:
            X = np.stack([vectors[r.text] for r in ranked])
            if is_grounded(self.estimator):
                X = grounded_features(X, [contexts.get(r.text) for r in ranked])
            confidences, explore = self._confidences(X)
        else:
            confidences, explore = [], []
        view = self.read(Keys.STEP)
        ambiguous = tuple(action_text(i) for i in view.selection.ambiguous) if view is not None else ()
        counts = self._counts() if self.budget is not None else BudgetCounts()
        seen = GateInput(
            ranked=ranked,
            confidences=confidences,
            kappa_explores=explore,
            ambiguous=ambiguous,
            objects={r.text: affordances[r.text].object_name for r in ranked if r.text in affordances},
            widths_m={t: c.detected_width_m for t, c in contexts.items()},
            counts=counts,
            failures={r.text: self.history.failures_of(r.text) for r in ranked},
            declined=self.human.declined,
            draw=self._rng.random,
            draw_every_decision=True,  # one draw per decision while exploring: seeded episodes repeat
            probe_reasons=self._probe_reasons(ranked) if self.probe is not None else {},
        )
        return seen, contexts

    def _probe_reasons(self, ranked: list[RankedAction]) -> dict[str, str]:
        """Why a heft test set each candidate's product back in this episode (only those it did)."""
        reason_of = getattr(
            self.history, "probe_reason", None
        )  # an EventLog's; a history without probes: none
        if reason_of is None:
            return {}
        reasons = {r.text: reason_of(r.text) for r in ranked}
        return {text: why for text, why in reasons.items() if why is not None}

    def update(self) -> py_trees.common.Status:
        if self._pending is not None:  # planning before commitment: poll, never block
            return self._poll_plan()
        ranked = self.read(Keys.RANKED, [])
        affordances = {a.text: a for a in self.read(Keys.AFFORDANCES, [])}
        seen, contexts = self._seen(ranked, affordances)
        decision = gate_decision(self.rules, seen).decision
        target = affordances.get(decision.action) if decision.action is not None else None
        view = self.read(Keys.STEP)
        self.write(Keys.CONFIDENCES, dict(zip([r.text for r in ranked], seen.confidences, strict=True)))
        self.write(Keys.CONTEXTS, contexts)
        self.write(Keys.PLANNED, None)
        self.write(Keys.PLAN_VERDICT, None)
        pending = _Pending(decision, target, contexts, None if view is None else view.index)
        if decision.kind is DecisionKind.ACT and target is not None and self.robot is not None:
            request = pick_request(
                target.detection,
                self.read(Keys.DETECTIONS, []),
                self.read(Keys.TABLE_DETECTIONS, None),
                self.seeds.next_seed(),
            )
            if decision.probe and self.probe is not None:
                from scone_bt.motion.probe import ProbeSettings

                request = replace(request, probe=ProbeSettings.of(self.probe))
            key = scene_key(request)
            known = self._infeasible.get(key)
            if known is not None:  # the same request in an unchanged scene: no plan exists, ask again at once
                return self._finish(pending, self._infeasible_decision(decision, known, again=True))
            self._pending = replace(
                pending, key=key, planned=self.robot.plan_pick_and_place(request), started=time.perf_counter()
            )
            self.write(Keys.MOTION_COMPUTING, True)  # the episode holds simulated time while the arm plans
            return self._poll_plan()
        return self._finish(pending, decision)

    def _poll_plan(self) -> py_trees.common.Status:
        pending = self._pending
        assert pending is not None and pending.planned is not None
        if not pending.planned.ready():
            self.feedback_message = f"planning {pending.decision.action} before committing"
            return py_trees.common.Status.RUNNING
        self._pending = None
        self.write(Keys.MOTION_COMPUTING, False)
        planning_s = time.perf_counter() - pending.started
        infeasible = pending.planned.infeasible()
        if infeasible is None:
            self.write(Keys.PLANNED, pending.planned)
            return self._finish(pending, pending.decision, planning_s)
        self._infeasible[pending.key] = infeasible
        self.write(Keys.PLAN_VERDICT, infeasible)
        return self._finish(pending, self._infeasible_decision(pending.decision, infeasible), planning_s)

    def _infeasible_decision(
        self, decision: Decision, infeasible: Infeasible, again: bool = False
    ) -> Decision:
        """ASK-HELP instead of ACT: no plan exists in this scene, known before the arm moved (IDLE, waiting for
        the human, when the human already declined to fetch it)."""
        declined = self.human.declined(str(decision.object_name))
        return infeasible_decision(decision, infeasible, declined, again)

    def _finish(
        self, pending: _Pending, decision: Decision, planning_s: float | None = None
    ) -> py_trees.common.Status:
        target = pending.target
        view = self.read(Keys.STEP)
        if decision.kind is DecisionKind.IDLE and view is not None and view.missing:
            if self.budget is not None:
                decision = ask_for_missing(decision, view.missing, self._asked_missing)
            else:  # the paper's robot does not ask for what it cannot see: it says what it waits for
                decision = waiting(view.missing, "", "")
        if decision.kind is not DecisionKind.ACT:
            target = target if decision.kind is DecisionKind.ASK and decision.rule != "missing" else None
        self.write(Keys.DECISION, decision)
        self.write(Keys.TARGET, target)
        target_context = pending.contexts.get(target.text) if target is not None else None
        self.write(Keys.TARGET_CONTEXT, target_context)
        self.events(self._event(decision, pending.step_index, target_context, planning_s))
        self.feedback_message = decision.reason
        return py_trees.common.Status.SUCCESS

    def terminate(self, new_status: py_trees.common.Status) -> None:
        if new_status is py_trees.common.Status.INVALID and self._pending is not None:
            self._pending = None  # interrupted while planning: nothing was committed
            self.write(Keys.MOTION_COMPUTING, False)

    def _contexts(self, candidates: list[Affordance]) -> dict[str, ExecutionContext]:
        """Each candidate affordance's execution context by action text, from this tick's perception."""
        if self.contexts is None or not candidates:
            return {}
        by_name = self.contexts(
            [a.detection for a in candidates], self.read(Keys.DETECTIONS, []), self.read(Keys.FRAMES, {})
        )
        return {a.text: by_name[a.object_name] for a in candidates if a.object_name in by_name}

    def _confidences(self, X: np.ndarray) -> tuple[list[float], list[bool]]:
        """κ̂'s belief per action, and the ε-greedy exploration draws (empty for estimators that do not explore).

        The belief is what the gate compares, prints and logs; an exploration draw only lets the gate act despite
        it (gate rule 4), so a user never reads a draw as a confidence.
        """
        belief, explores = getattr(self.estimator, "belief", None), getattr(self.estimator, "explores", None)
        if belief is None or explores is None:
            return [float(c) for c in self.estimator.predict(X)], []
        return [float(c) for c in belief(X)], [bool(e) for e in explores(X)]

    def _past_the_end(self) -> str:
        """What a decision past the recipe's last step is about: nothing left, or the card's leftover items."""
        view = self.read(Keys.STEP)
        return CARD_ITEMS_LEFT if view is not None and view.selection.later else EVERY_STEP_SERVED

    def _event(
        self,
        decision: Decision,
        step_index: int | None,
        context: ExecutionContext | None,
        planning_s: float | None = None,
    ) -> DecisionMade:
        """``step_index``: the robot's own place in the recipe (None: the human's step, the recipe-blind setting)."""
        index = self.human.step_index if step_index is None else step_index
        return DecisionMade(
            sim_time=self.clock(),
            step=min(self.steps_total, index + 1),
            instruction=self.read(Keys.INSTRUCTION) or self._past_the_end(),
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


class DecisionIs(StageBehaviour):
    """Condition: SUCCESS if the gate's decision is of the given kind."""

    READS = (Keys.DECISION,)

    def __init__(self, name: str, kind: DecisionKind | str) -> None:
        super().__init__(name)
        self.kind = DecisionKind(kind)

    @classmethod
    def from_context(cls, name: str, context: EpisodeContext, kind: str) -> DecisionIs:
        return cls(name, kind)

    def update(self) -> py_trees.common.Status:
        decision = self.read(Keys.DECISION)
        ok = decision is not None and decision.kind is self.kind
        return py_trees.common.Status.SUCCESS if ok else py_trees.common.Status.FAILURE
