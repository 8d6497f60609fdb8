"""ConfidenceGate (κ̂): predict success for the ranked actions and decide to act, ask or wait."""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, replace
from functools import partial
from typing import TypeVar

import numpy as np
import py_trees

from scone_bt.affordances.types import Affordance, action_text
from scone_bt.behaviours.base import Keys, StageBehaviour
from scone_bt.behaviours.context import EpisodeContext
from scone_bt.behaviours.gate_config import GatePorts, GateSettings
from scone_bt.behaviours.gate_steps import (
    candidate_contexts,
    confidences,
    decision_event,
    gate_counts,
    look_again_first,
    past_the_end,
    probe_reasons,
    settle_idle,
    shown_target,
)
from scone_bt.behaviours.pick_and_place import pick_request, scene_key
from scone_bt.behaviours.probe_judge import ProbeJudge, belief_of
from scone_bt.experience.types import ExecutionContext
from scone_bt.gate.budget import BudgetCounts, BudgetOptions
from scone_bt.gate.probe import ProbeOptions
from scone_bt.gate.rules import GateInput, GateRules, flat_on_lowest, gate_decision, infeasible_decision
from scone_bt.gate.types import Decision, DecisionKind
from scone_bt.motion.probe import ProbeSettings
from scone_bt.relevance.types import RankedAction
from scone_bt.robot.interface import Infeasible, PlannedPick

__all__ = ["ConfidenceGate", "DecisionIs", "GatePorts", "GateSettings"]


_T = TypeVar("_T")


def _resolved(value: _T | None) -> _T:
    """A tree parameter of a context's options: resolved (BehaviourOptions.resolve), so never None."""
    assert value is not None, "BehaviourOptions not resolved"
    return value


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
    judge: ProbeJudge | None = None


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

    Built from two bundles (behaviours.gate_config): ``ports`` (κ̂, history, events, clock, human, contexts, robot,
    planner seeds) and ``settings`` (gate, budget and probe options, failure limit, opening, seed, step count). Each
    tick runs named steps: see (κ̂ and contexts, gate_steps), decide (gate.rules.gate_decision), plan before
    committing when a robot is given (polled, never blocking), settle and report (gate_steps).
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
        Keys.PROBE_JUDGE,
        Keys.LOOK_AGAIN,
    )

    def __init__(self, name: str, ports: GatePorts, settings: GateSettings) -> None:
        super().__init__(name)
        self.ports = ports
        self.settings = settings
        self._asked_missing: set[str] = set()
        self._looked_again: set[str] = set()  # items already looked for again with averaged frames
        self._pending: _Pending | None = None
        self._infeasible: dict[tuple[object, ...], Infeasible] = {}

    @classmethod
    def from_context(cls, name: str, context: EpisodeContext) -> ConfidenceGate:
        from scone_bt.gate import GateOptions
        from scone_bt.perception.context import ContextExtractor

        opts = context.options
        budget = (
            BudgetOptions(
                target_failure_rate=float(_resolved(opts.target_failure_rate)),
                excess_allowance=1.0 if opts.exploration_credit else None,
            )
            if opts.gate == "budget" and opts.use_self_confidence
            else None
        )
        ports = GatePorts(
            kappa=context.kappa,
            history=context.history,
            events=context.events,
            clock=context.robot.now,
            human=context.human,
            contexts=ContextExtractor(context.scene, context.catalogue),
            # planning before commitment and asking for unseen items come with the budget gate; the paper's gate
            # and its control condition stay as the paper ran them (Table I, the study's control)
            robot=context.robot if budget is not None else None,
            seeds=context.seeds,
        )
        settings = GateSettings(
            gate=GateOptions(
                confidence_threshold=_resolved(opts.confidence_threshold),
                relevance_threshold=_resolved(opts.relevance_threshold),
                use_self_confidence=opts.use_self_confidence,
                recipe_aware=_resolved(opts.recipe_aware),
            ),
            max_failures_per_action=int(_resolved(opts.max_failures_per_action)),
            steps_total=len(context.recipe.steps),
            budget=budget,
            seed=opts.seed,
            opening_m=context.gripper_opening_m if budget is not None else None,
            slide_pinch=context.slide_pinch and budget is not None,
            probe=ProbeOptions.of(opts.probe) if budget is not None and opts.probe is not None else None,
        )
        return cls(name, ports, settings)

    def setup(self, **kwargs: object) -> None:
        self.estimator = self.ports.kappa()  # κ̂ rebuilt from the store on first use
        # the budget's exploration draws: their own seeded stream (κ̂'s draws are unchanged by them)
        self._rng = np.random.default_rng([self.settings.seed, 0x6A7E])

    @property
    def rules(self) -> GateRules:
        """The gate's rules (scone_bt.gate.rules), as this behaviour was configured."""
        return self.settings.rules

    def update(self) -> py_trees.common.Status:
        if self._pending is not None:  # planning before commitment: poll, never block
            return self._poll_plan()
        ranked = self.read(Keys.RANKED, [])
        affordances = {a.text: a for a in self.read(Keys.AFFORDANCES, [])}
        seen, contexts = self._seen(ranked, affordances)
        decision = gate_decision(self.rules, seen).decision
        target = affordances.get(decision.action) if decision.action is not None else None
        self._write_seen(ranked, seen.confidences, contexts)
        view = self.read(Keys.STEP)
        pending = _Pending(
            decision,
            target,
            contexts,
            None if view is None else view.index,
            judge=self._judge(decision, seen, contexts),
        )
        if decision.kind is DecisionKind.ACT and target is not None and self.ports.robot is not None:
            return self._plan_first(pending, target)
        return self._finish(pending, decision)

    def _seen(
        self, ranked: Sequence[RankedAction], affordances: dict[str, Affordance]
    ) -> tuple[GateInput, dict[str, ExecutionContext]]:
        """What the gate sees this tick: κ̂ on the ranked actions, their contexts, the episode's counts."""
        history, budget, probe = self.ports.history, self.settings.budget, self.settings.probe
        contexts = candidate_contexts(
            self.ports.contexts,
            [affordances[r.text] for r in ranked if r.text in affordances],
            self.read(Keys.DETECTIONS, []),
            self.read(Keys.FRAMES, {}),
        )
        beliefs, explore = confidences(
            self.estimator, ranked, self.read(Keys.ACTION_EMBEDDINGS, {}), contexts
        )
        view = self.read(Keys.STEP)
        seen = GateInput(
            ranked=ranked,
            confidences=beliefs,
            kappa_explores=explore,
            ambiguous=tuple(action_text(i) for i in view.selection.ambiguous) if view is not None else (),
            objects={r.text: affordances[r.text].object_name for r in ranked if r.text in affordances},
            widths_m={t: c.detected_width_m for t, c in contexts.items()},
            flat_on_lowest=flat_on_lowest(contexts, self.settings.opening_m),
            counts=gate_counts(history, self.estimator) if budget is not None else BudgetCounts(),
            failures={r.text: history.failures_of(r.text) for r in ranked},
            declined=self.ports.human.declined,
            draw=self._rng.random,
            draw_every_decision=True,  # one draw per decision while exploring: seeded episodes repeat
            probe_reasons=probe_reasons(history, ranked) if probe is not None else {},
        )
        return seen, contexts

    def _judge(
        self, decision: Decision, seen: GateInput, contexts: dict[str, ExecutionContext]
    ) -> ProbeJudge | None:
        """The judge after the heft test when the decision probes (gate.after_probe, behaviours.probe_judge)."""
        probe = self.settings.probe
        if not decision.probe or probe is None or decision.action is None:
            return None
        vector = self.read(Keys.ACTION_EMBEDDINGS, {})[decision.action]
        return ProbeJudge(
            self.rules,
            seen.counts,
            str(decision.object_name),
            ProbeSettings.of(probe),
            partial(belief_of, self.estimator, vector),
            contexts.get(decision.action),
        )

    def _write_seen(
        self, ranked: Sequence[RankedAction], beliefs: Sequence[float], contexts: dict[str, ExecutionContext]
    ) -> None:
        """This tick's κ̂ and contexts on the blackboard; no plan and no verdict yet."""
        self.write(Keys.CONFIDENCES, dict(zip([r.text for r in ranked], beliefs, strict=True)))
        self.write(Keys.CONTEXTS, contexts)
        self.write(Keys.PLANNED, None)
        self.write(Keys.PLAN_VERDICT, None)

    def _plan_first(self, pending: _Pending, target: Affordance) -> py_trees.common.Status:
        """Planning before commitment: request the plan (or reuse a known verdict) and poll it."""
        robot, seeds, probe = self.ports.robot, self.ports.seeds, self.settings.probe
        assert robot is not None and seeds is not None
        request = pick_request(
            target.detection,
            self.read(Keys.DETECTIONS, []),
            self.read(Keys.TABLE_DETECTIONS, None),
            seeds.next_seed(),
        )
        if pending.decision.probe and probe is not None:
            request = replace(request, probe=ProbeSettings.of(probe), judge=pending.judge)
        key = scene_key(request)
        known = self._infeasible.get(key)
        if known is not None:  # the same request in an unchanged scene: no plan exists, ask again at once
            return self._finish(pending, self._infeasible_decision(pending.decision, known, again=True))
        self._pending = replace(
            pending, key=key, planned=robot.plan_pick_and_place(request), started=time.perf_counter()
        )
        self.write(Keys.MOTION_COMPUTING, True)  # the episode holds simulated time while the arm plans
        return self._poll_plan()

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
        declined = self.ports.human.declined(str(decision.object_name))
        return infeasible_decision(decision, infeasible, declined, again)

    def _finish(
        self, pending: _Pending, decision: Decision, planning_s: float | None = None
    ) -> py_trees.common.Status:
        view = self.read(Keys.STEP)
        look_again: tuple[str, ...] = ()
        if view is not None:
            decision, look_again = look_again_first(decision, view.missing, self._looked_again)
            if not look_again:  # asked for, or waited for, only once a longer look missed it too
                decision = settle_idle(
                    decision, view.missing, self.settings.budget is not None, self._asked_missing
                )
        self.write(Keys.LOOK_AGAIN, look_again)
        target = shown_target(decision, pending.target)
        target_context = pending.contexts.get(target.text) if target is not None else None
        self.write(Keys.DECISION, decision)
        self.write(Keys.TARGET, target)
        self.write(Keys.TARGET_CONTEXT, target_context)
        self.write(Keys.PROBE_JUDGE, pending.judge if decision.probe else None)
        # the robot's own place in the recipe; None: the human's step (the recipe-blind setting)
        index = self.ports.human.step_index if pending.step_index is None else pending.step_index
        instruction = self.read(Keys.INSTRUCTION) or past_the_end(
            view is not None and bool(view.selection.later)
        )
        self.ports.events(
            decision_event(
                decision,
                sim_time=self.ports.clock(),
                step=min(self.settings.steps_total, index + 1),
                instruction=instruction,
                context=target_context,
                planning_s=planning_s,
            )
        )
        self.feedback_message = decision.reason
        return py_trees.common.Status.SUCCESS

    def terminate(self, new_status: py_trees.common.Status) -> None:
        if new_status is py_trees.common.Status.INVALID and self._pending is not None:
            self._pending = None  # interrupted while planning: nothing was committed
            self.write(Keys.MOTION_COMPUTING, False)


class DecisionIs(StageBehaviour):
    """Condition: SUCCESS if the gate's decision is of the given kind."""

    READS = (Keys.DECISION,)

    def __init__(self, name: str, kind: DecisionKind | str) -> None:
        super().__init__(name)
        self.kind = DecisionKind(kind)

    @classmethod
    def from_context(cls, name: str, context: EpisodeContext, kind: str | None = None) -> DecisionIs:
        # optional only to match StageBehaviour.from_context; the tree builder requires it (_DecisionIsArgs)
        if kind is None:
            options = ", ".join(k.value for k in DecisionKind)
            raise ValueError(f"DecisionIs {name!r}: args.kind is required, one of: {options}")
        return cls(name, kind)

    def update(self) -> py_trees.common.Status:
        decision = self.read(Keys.DECISION)
        ok = decision is not None and decision.kind is self.kind
        return py_trees.common.Status.SUCCESS if ok else py_trees.common.Status.FAILURE
