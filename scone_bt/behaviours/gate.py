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
from scone_bt.gate.budget import BudgetCounts, BudgetOptions, may_explore, threshold, too_wide
from scone_bt.gate.probe import ProbeOptions, in_band
from scone_bt.gate.types import Decision, DecisionKind
from scone_bt.robot.interface import Infeasible, PlannedPick, Robot

if TYPE_CHECKING:
    from scone_bt.gate import GateOptions

__all__ = ["ConfidenceGate", "DecisionIs", "apply_failure_limit", "say_infeasible"]

EVERY_STEP_SERVED = "(every step is served)"
"""The instruction a decision reports past the recipe's last step, with nothing of the card left to fetch."""
CARD_ITEMS_LEFT = "(past the last step: items on the card)"
"""The instruction a decision reports past the recipe's last step while items of the card that no open step names
are still on the shelf (fetched as needed later; e.g. after the human answered "none of those" to a question)."""


_SAY: dict[str, str] = {
    "no_grasp_ik": "I cannot reach the {item} to grasp it",
    "grasps_blocked": "I cannot grasp the {item}: the {blocker} is in the way",
    "no_table_space": "there is no room on the table for the {item}",
    "no_placement_ik": "I cannot reach a free spot on the table with the {item}",
    "placements_blocked": "I cannot put the {item} down: the {blocker} is in the way",
}


def say_infeasible(item: str, infeasible: Infeasible) -> str:
    """The robot's words for a pick-and-place that cannot be planned, e.g. "I cannot grasp the parmesan: the
    cooking cream is in the way"."""
    blocker = infeasible.blockers[0] if infeasible.blockers else "shelf"
    template = _SAY.get(infeasible.reason, "I cannot plan to fetch the {item}")
    return template.format(item=item, blocker=blocker)


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


def _overruled(decision: Decision, kind: DecisionKind, reason: str, rule: str) -> Decision:
    """The decision as a rule made it rather than κ̂ against the threshold (never an exploration draw)."""
    return replace(decision, kind=kind, reason=reason, rule=rule, explored=False)


def _waiting(missing: tuple[str, ...], note: str, rule: str) -> Decision:
    """IDLE, waiting for items the step needs now and the robot sees nowhere: about those items alone.

    Not the idle decision it replaces with a new reason: that one's action, relevance, κ̂, need and rule belong to
    another product (a line read "waiting: spaghetti not in sight … conf 0.33 (needed later) (help declined)"
    with the parmesan's numbers).
    """
    nan = float("nan")
    return Decision(
        DecisionKind.IDLE,
        None,
        nan,
        nan,
        f"waiting: {', '.join(missing)} not in sight{note}",
        "now",
        rule=rule,
    )


def apply_failure_limit(decision: Decision, failures: int, limit: int) -> Decision:
    """The paper's rule: after ``limit`` failures on the same action, ask for help whatever κ̂ says."""
    if decision.kind is DecisionKind.ACT and decision.action is not None and failures >= limit:
        return replace(
            decision,
            kind=DecisionKind.ASK,
            reason=f"failed {limit} times on this action",
            rule="failure-limit",
        )
    return decision


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
            BudgetOptions(target_failure_rate=float(opts.target_failure_rate))
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

    def _options(self) -> tuple[GateOptions, bool]:
        """The gate options for this decision, and whether the budget may explore now."""
        if self.budget is None:
            return self.gate_options, False
        attempts, failures, explored_failures = self.history.budget_counts()
        counts = BudgetCounts(
            attempts, failures, explored_failures, int(getattr(self.estimator, "n_observations", 0))
        )
        tau = threshold(self.budget, counts)
        return replace(self.gate_options, confidence_threshold=tau, target_error_rate=None), may_explore(
            self.budget, counts
        )

    def update(self) -> py_trees.common.Status:
        if self._pending is not None:  # planning before commitment: poll, never block
            return self._poll_plan()
        from scone_bt.gate import decide

        ranked = self.read(Keys.RANKED, [])
        vectors = self.read(Keys.ACTION_EMBEDDINGS, {})
        affordances = {a.text: a for a in self.read(Keys.AFFORDANCES, [])}
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
        by_text = {r.text for r in ranked}
        options, exploring = self._options()
        if exploring and ranked and not explore:
            draw = bool(self._rng.random() < self.budget.explore_rate)  # type: ignore[union-attr]
            # never explore an action that already failed in this episode: its failure is the lesson
            explore = [draw and self.history.failures_of(r.text) == 0 for r in ranked]
        decision = decide(ranked, confidences, options, tuple(a for a in ambiguous if a in by_text), explore)
        decision = apply_failure_limit(decision, self.history.failures_of(decision.action or ""), self.limit)
        target = affordances.get(decision.action) if decision.action is not None else None
        if target is not None:
            decision = replace(decision, object_name=target.object_name)
            decision = self._probe_first(decision, options.confidence_threshold)
            decision = self._too_wide(decision, contexts.get(target.text))
        decision = self._after_decline(decision, target is not None)
        self.write(Keys.CONFIDENCES, dict(zip([r.text for r in ranked], confidences, strict=True)))
        self.write(Keys.CONTEXTS, contexts)
        self.write(Keys.PLANNED, None)
        self.write(Keys.PLAN_VERDICT, None)
        pending = _Pending(decision, target, contexts, None if view is None else view.index)
        if decision.kind is DecisionKind.ACT and target is not None and self.robot is not None:
            request = pick_request(
                target.detection,
                self.read(Keys.DETECTIONS, []),
                self.read(Keys.TABLE_DETECTIONS, None),
                self.seeds.next_seed(),  # type: ignore[union-attr]
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
        why = say_infeasible(str(decision.object_name), infeasible)
        if self.human.declined(str(decision.object_name)):
            return _overruled(
                decision, DecisionKind.IDLE, f"{why}, and the human declined to fetch it: waiting", "declined"
            )
        known = " (known: not planned again in this scene)" if again else ""
        return _overruled(decision, DecisionKind.ASK, why + known, "infeasible")

    def _finish(
        self, pending: _Pending, decision: Decision, planning_s: float | None = None
    ) -> py_trees.common.Status:
        target = pending.target
        view = self.read(Keys.STEP)
        if decision.kind is DecisionKind.IDLE and view is not None and view.missing:
            if self.budget is not None:
                decision = self._ask_for_missing(decision, view.missing)
            else:  # the paper's robot does not ask for what it cannot see: it says what it waits for
                decision = _waiting(view.missing, "", "")
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

    def _probe_first(self, decision: Decision, tau: float) -> Decision:
        """Heft first what κ̂ is unsure of (within the probe band around τ; gate.probe), and ask about what a
        probe already set back in this episode, saying why."""
        if self.probe is None or decision.action is None or decision.rule != "":
            return decision
        if decision.kind not in (DecisionKind.ACT, DecisionKind.ASK):
            return decision
        probe_reason = getattr(self.history, "probe_reason", None)
        reason = probe_reason(decision.action) if probe_reason is not None else None
        if reason is not None:
            return _overruled(decision, DecisionKind.ASK, f"{reason}: please bring it", "probe")
        if self.history.failures_of(decision.action) > 0:
            return decision  # as with exploration: an action that failed is not tried again on a probe's word
        if not in_band(decision.confidence, tau, self.probe):
            return decision
        why = f"unsure (confidence {decision.confidence:.2f}, threshold {tau:.2f}): hefting the {decision.object_name} first"
        return replace(decision, kind=DecisionKind.ACT, reason=why, explored=False, probe=True)

    def _too_wide(self, decision: Decision, context: ExecutionContext | None) -> Decision:
        """ASK-HELP instead of ACT (or exploring) for a product measured wider than the gripper opens."""
        if decision.kind is not DecisionKind.ACT or context is None:
            return decision
        width = context.detected_width_m
        if not too_wide(width, self.opening_m):
            return decision
        assert width is not None and self.opening_m is not None
        reason = (
            f"the {decision.object_name} measures {width * 100:.1f} cm across and my gripper opens "
            f"{self.opening_m * 100:.1f} cm: please fetch it"
        )
        return _overruled(decision, DecisionKind.ASK, reason, "too-wide")

    def _after_decline(self, decision: Decision, visible: bool) -> Decision:
        """A help request the human declined is not made again: attempt instead, or wait (see the class)."""
        item = decision.object_name
        if decision.kind is not DecisionKind.ASK or item is None or not self.human.declined(str(item)):
            return decision
        failures = self.history.failures_of(decision.action or "")
        if decision.rule == "too-wide":
            why = "too wide for my gripper"
            return _overruled(
                decision,
                DecisionKind.IDLE,
                f"the human declined to fetch the {item}, {why}: waiting",
                "declined",
            )
        if visible and failures < max(self.limit, 1):
            reason = f"the human declined to fetch the {item}: trying it myself"
            return _overruled(decision, DecisionKind.ACT, reason, "declined")
        why = "I cannot see it" if not visible else f"it failed {failures} times"
        return _overruled(
            decision,
            DecisionKind.IDLE,
            f"the human declined to fetch the {item} and {why}: waiting",
            "declined",
        )

    def _ask_for_missing(self, decision: Decision, missing: tuple[str, ...]) -> Decision:
        """Idle, but the step needs items the robot sees nowhere and did not place: ask for the first one not
        asked for yet (once each); when every one was asked for, say what it waits for."""
        if not missing:
            return decision
        new = [i for i in missing if i not in self._asked_missing]
        if not new:
            return _waiting(missing, " (asked for)", "missing")
        item = new[0]
        self._asked_missing.add(item)
        return Decision(
            DecisionKind.ASK,
            action_text(item),
            float("nan"),
            float("nan"),
            f"I cannot see the {item} the step needs: please bring it",
            "now",
            object_name=item,
            rule="missing",
        )

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
    def from_context(cls, name: str, context: EpisodeContext, kind: str) -> DecisionIs:  # type: ignore[override]
        return cls(name, kind)

    def update(self) -> py_trees.common.Status:
        decision = self.read(Keys.DECISION)
        ok = decision is not None and decision.kind is self.kind
        return py_trees.common.Status.SUCCESS if ok else py_trees.common.Status.FAILURE
