"""The gate's decision, one pure function for the robot and the benchmark: `gate_decision`.

The tree's `ConfidenceGate` and ``scone-bench gate``'s `replay_stream` both call it, so the benchmark of the
failure budget measures the very rules the robot runs. It composes named steps, in order:

1. `threshold_options`: the confidence an action needs now: the failure budget's τ (`gate.budget.threshold`)
   with ``rules.budget``, else the fixed threshold of ``rules.options``; and whether the budget may still explore.
2. `exploration_draws`: per candidate, whether an action below τ is tried to learn: κ̂'s own ε-greedy draw where
   κ̂ has one, else (while the budget may explore) the budget's seeded draw, never for an action that failed.
3. `decide` (`gate.gate`): relevance and recipe rules, κ̂ against τ, exploration (rule 4).
4. `OVERRULES`, each ``(decision, seen, rules) -> decision``: the failure limit, the object the action moves, the
   heft test (`probe_first`: ask about what a probe set back, probe what κ̂ is unsure of), a product wider than
   the gripper opens, and a help request the human declined. A new rule is one more function in that tuple.

Rules about planning (no plan exists: `infeasible_decision`) and about items the robot sees nowhere
(`waiting`, `ask_for_missing`) come after a plan or a look at the step; the behaviour calls them, and they are
here beside the others.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Protocol

from scone_bt.config.grasp import flat_pack
from scone_bt.gate.budget import BudgetCounts, BudgetOptions, may_explore, threshold, too_wide
from scone_bt.gate.gate import GateOptions, decide
from scone_bt.gate.probe import ProbeOptions, in_band, probe_credit
from scone_bt.gate.types import Decision, DecisionKind

if TYPE_CHECKING:
    from scone_bt.relevance.types import RankedAction
    from scone_bt.robot.interface import Infeasible

__all__ = [
    "GateRules",
    "GateInput",
    "GateResult",
    "GateStep",
    "OVERRULES",
    "gate_decision",
    "threshold_options",
    "exploration_draws",
    "apply_failure_limit",
    "name_object",
    "probe_first",
    "ask_if_too_wide",
    "flat_on_lowest",
    "after_decline",
    "overruled",
    "waiting",
    "ask_for_missing",
    "infeasible_decision",
    "say_infeasible",
]


def _never(_item: str) -> bool:
    return False


@dataclass(frozen=True)
class GateRules:
    """Which rules the gate applies (fixed for a run).

    Attributes:
        options: Relevance, recipe-aware ranking, self-confidence on/off and the fixed threshold (the paper's gate).
        budget: The failure budget whose τ replaces the fixed threshold (None: the fixed threshold decides).
        exploration: The budget whose exploration window lets an action below τ be tried (None: only κ̂'s own
            ε-greedy draws explore).
        failure_limit: After this many failures of the same action, ask whatever κ̂ says (None: no limit).
        opening_m: The gripper's opening, metres: a product perceived wider is asked about (None: no such rule).
        slide_pinch: The arm slides and pinches a flat pack on a lowest tier (`motion.slide`): such a product
            (`GateInput.flat_on_lowest`) is κ̂'s to decide, not asked about because it is too wide.
        probe: The heft test's band around τ (`probe_first`; None: no probe). The budget gate's only.
    """

    options: GateOptions = field(default_factory=GateOptions)
    budget: BudgetOptions | None = None
    exploration: BudgetOptions | None = None
    failure_limit: int | None = None
    opening_m: float | None = None
    probe: ProbeOptions | None = None
    slide_pinch: bool = False


@dataclass(frozen=True)
class GateInput:
    """What the gate sees at one decision.

    Attributes:
        ranked: Candidate actions with their relevance.
        confidences: κ̂'s belief for each, aligned with ``ranked``, in [0, 1].
        kappa_explores: κ̂'s own ε-greedy draw per candidate (empty: κ̂ does not explore). A sequence read only
            at the chosen candidate's index when it is below τ, so a caller may draw it lazily.
        ambiguous: Action texts the step could mean about equally (recipe-aware ranking).
        objects: Action text → the object it moves, for the affordances the robot sees.
        widths_m: Action text → its product's perceived width, metres (None or NaN: not measured).
        flat_on_lowest: Action texts whose product is perceived a flat pack (`config.grasp.flat_pack`) standing
            on a lowest tier: what an arm with `GateRules.slide_pinch` slides and pinches.
        counts: The attempts so far, as the budget reads them.
        failures: Action text → its failures so far.
        declined: Whether the human declined to fetch an item (by object name).
        draw: The budget's seeded uniform draw in [0, 1).
        draw_every_decision: Draw once per decision while the budget may explore (the robot: its seeded episodes
            repeat so), rather than only when a candidate below τ may be explored (the replay). The rule applied
            is the same; only how many numbers the generator gives differs.
        probe_reasons: Action text → why a heft test set its product back earlier in this episode (the robot's
            words, "the jar slips in my fingers"); empty in a replay, whose executions are each from another
            episode.
    """

    ranked: Sequence[RankedAction]
    confidences: Sequence[float]
    kappa_explores: Sequence[bool] = ()
    ambiguous: Sequence[str] = ()
    objects: Mapping[str, str] = field(default_factory=dict)
    widths_m: Mapping[str, float | None] = field(default_factory=dict)
    flat_on_lowest: frozenset[str] = frozenset()
    counts: BudgetCounts = field(default_factory=BudgetCounts)
    failures: Mapping[str, int] = field(default_factory=dict)
    declined: Callable[[str], bool] = _never
    draw: Callable[[], float] | None = None
    draw_every_decision: bool = False
    probe_reasons: Mapping[str, str] = field(default_factory=dict)


@dataclass(frozen=True)
class GateResult:
    """The decision, the threshold it was made against, and whether the budget could explore."""

    decision: Decision
    threshold: float
    exploring: bool


GateStep = Callable[[Decision, GateInput, GateRules], Decision]
"""A rule applied after κ̂'s decision: it keeps the decision or overrules it."""


def threshold_options(rules: GateRules, counts: BudgetCounts) -> tuple[GateOptions, bool]:
    """Step 1: the options with the threshold for this decision, and whether the budget may explore now."""
    options = rules.options
    if rules.budget is not None:
        tau = threshold(rules.budget, counts)
        options = replace(options, confidence_threshold=tau, target_error_rate=None)
    exploring = rules.exploration is not None and may_explore(rules.exploration, counts)
    return options, exploring


class _BudgetDraws(Sequence[bool]):
    """The budget's exploration flag per candidate: one seeded draw, taken when first read (or at once)."""

    def __init__(self, seen: GateInput, rate: float, eager: bool) -> None:
        self._seen = seen
        self._rate = rate
        self._hit: bool | None = None
        if eager:
            self._draw()

    def _draw(self) -> bool:
        if self._hit is None:
            assert self._seen.draw is not None
            self._hit = bool(self._seen.draw() < self._rate)
        return self._hit

    def __len__(self) -> int:
        return len(self._seen.ranked)

    def __getitem__(self, i):
        if isinstance(i, slice):
            return [self[j] for j in range(len(self))[i]]
        # never explore an action that already failed: its failure is the lesson
        return self._draw() and self._seen.failures.get(self._seen.ranked[i].text, 0) == 0


def exploration_draws(rules: GateRules, seen: GateInput, exploring: bool) -> Sequence[bool]:
    """Step 2: whether each candidate below τ is tried to learn (see the module docstring)."""
    if len(seen.kappa_explores):
        return seen.kappa_explores
    if not exploring or not seen.ranked or seen.draw is None:
        return ()
    assert rules.exploration is not None
    return _BudgetDraws(seen, rules.exploration.explore_rate, seen.draw_every_decision)


def overruled(decision: Decision, kind: DecisionKind, reason: str, rule: str) -> Decision:
    """The decision as a rule made it rather than κ̂ against the threshold (never an exploration draw, never a
    probe)."""
    return replace(decision, kind=kind, reason=reason, rule=rule, explored=False, probe=False)


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


def _failure_limit(decision: Decision, seen: GateInput, rules: GateRules) -> Decision:
    if rules.failure_limit is None:
        return decision
    return apply_failure_limit(decision, seen.failures.get(decision.action or "", 0), rules.failure_limit)


def name_object(decision: Decision, seen: GateInput, rules: GateRules) -> Decision:
    """The object the chosen action moves, where the robot sees it."""
    if decision.action is None or decision.action not in seen.objects:
        return decision
    return replace(decision, object_name=seen.objects[decision.action])


def probe_first(decision: Decision, seen: GateInput, rules: GateRules) -> Decision:
    """The heft test (gate.probe): ask about what a probe already set back in this episode, saying why; else
    ACT with a probe first when κ̂ is unsure (within the probe band around τ, whether κ̂'s decision was to act,
    explore or ask; below τ only where `probe_credit` allows, by default always), unless the action already failed. A
    decision a rule made is left alone."""
    if rules.probe is None or decision.action not in seen.objects or decision.rule != "":
        return decision
    if decision.kind not in (DecisionKind.ACT, DecisionKind.ASK):
        return decision
    reason = seen.probe_reasons.get(str(decision.action))
    if reason is not None:
        return overruled(decision, DecisionKind.ASK, f"{reason}: please bring it", "probe")
    if seen.failures.get(str(decision.action), 0) > 0:
        return decision  # as with exploration: an action that failed is not tried again on a probe's word
    options, _ = threshold_options(rules, seen.counts)
    tau = options.act_threshold
    credit = probe_credit(rules.probe, rules.budget, seen.counts) if rules.budget is not None else True
    alpha = rules.budget.target_failure_rate if rules.budget is not None else None
    if not in_band(decision.confidence, tau, rules.probe, credit, alpha):
        return decision
    why = (
        f"unsure (confidence {decision.confidence:.2f}, threshold {tau:.2f}): "
        f"hefting the {decision.object_name} first"
    )
    # not an explored decision: a probe is not an exploration; whether the attempt that carries on is explored
    # (on the strict rule's credit) is decided after the probe, from what it felt (gate.after_probe)
    return replace(decision, kind=DecisionKind.ACT, reason=why, explored=False, probe=True)


class _Perceived(Protocol):
    """What `flat_on_lowest` reads of a perceived context (`experience.types.ExecutionContext`)."""

    @property
    def shelf_tier(self) -> int | None: ...
    @property
    def detected_width_m(self) -> float | None: ...
    @property
    def detected_height_m(self) -> float | None: ...


def flat_on_lowest(contexts: Mapping[str, _Perceived], opening_m: float | None) -> frozenset[str]:
    """The actions whose product is perceived a flat pack wider than ``opening_m`` (`config.grasp.flat_pack`) on
    a lowest tier (`GateInput.flat_on_lowest`)."""
    return frozenset(
        t
        for t, c in contexts.items()
        if c.shelf_tier == 0 and flat_pack(c.detected_width_m, c.detected_height_m, opening_m)
    )


def ask_if_too_wide(decision: Decision, seen: GateInput, rules: GateRules) -> Decision:
    """ASK-HELP instead of ACT (or exploring) for a product measured wider than the gripper opens, but for a flat
    pack on a lowest tier when the arm slides and pinches those (κ̂ decides on it)."""
    if (
        decision.kind is not DecisionKind.ACT
        or decision.action is None
        or decision.action not in seen.objects
        or (rules.slide_pinch and decision.action in seen.flat_on_lowest)
    ):
        return decision
    width = seen.widths_m.get(decision.action)
    if not too_wide(width, rules.opening_m):
        return decision
    assert width is not None and rules.opening_m is not None
    reason = (
        f"the {decision.object_name} measures {width * 100:.1f} cm across and my gripper opens "
        f"{rules.opening_m * 100:.1f} cm: please fetch it"
    )
    return overruled(decision, DecisionKind.ASK, reason, "too-wide")


def after_decline(decision: Decision, seen: GateInput, rules: GateRules) -> Decision:
    """A help request the human declined is not made again: the robot attempts the item itself if it may (it
    sees it, fewer failures than the limit), else it waits for the human, so a refusal never makes it ask in a
    loop; a product too wide for the gripper is waited for."""
    item = decision.object_name
    if decision.kind is not DecisionKind.ASK or item is None or not seen.declined(str(item)):
        return decision
    failures = seen.failures.get(decision.action or "", 0)
    if decision.rule == "too-wide":
        return overruled(
            decision,
            DecisionKind.IDLE,
            f"the human declined to fetch the {item}, too wide for my gripper: waiting",
            "declined",
        )
    visible = decision.action in seen.objects
    if visible and failures < max(rules.failure_limit or 0, 1):
        reason = f"the human declined to fetch the {item}: trying it myself"
        return overruled(decision, DecisionKind.ACT, reason, "declined")
    why = "I cannot see it" if not visible else f"it failed {failures} times"
    return overruled(
        decision,
        DecisionKind.IDLE,
        f"the human declined to fetch the {item} and {why}: waiting",
        "declined",
    )


OVERRULES: tuple[GateStep, ...] = (_failure_limit, name_object, probe_first, ask_if_too_wide, after_decline)
"""Step 4: the rules after κ̂'s decision, in the order they apply."""


def gate_decision(rules: GateRules, seen: GateInput) -> GateResult:
    """The gate's decision for what it sees now (module docstring: steps 1-4)."""
    options, exploring = threshold_options(rules, seen.counts)
    explore = exploration_draws(rules, seen, exploring)
    texts = {r.text for r in seen.ranked}
    ambiguous = tuple(a for a in seen.ambiguous if a in texts)
    decision = decide(seen.ranked, seen.confidences, options, ambiguous, explore)
    for step in OVERRULES:
        decision = step(decision, seen, rules)
    return GateResult(decision, options.act_threshold, exploring)


def waiting(missing: tuple[str, ...], note: str, rule: str) -> Decision:
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


def ask_for_missing(decision: Decision, missing: tuple[str, ...], asked: set[str]) -> Decision:
    """Idle, but the step needs items the robot sees nowhere and did not place: ask for the first one not asked
    for yet (once each: it is added to ``asked``); when every one was asked for, say what it waits for."""
    if not missing:
        return decision
    new = [i for i in missing if i not in asked]
    if not new:
        return waiting(missing, " (asked for)", "missing")
    from scone_bt.affordances.types import action_text

    item = new[0]
    asked.add(item)
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


def infeasible_decision(
    decision: Decision, infeasible: Infeasible, declined: bool, again: bool = False
) -> Decision:
    """ASK-HELP instead of ACT: no plan exists in this scene, known before the arm moved (IDLE, waiting for the
    human, when the human already declined to fetch it; ``again``: the same request in an unchanged scene)."""
    why = say_infeasible(str(decision.object_name), infeasible)
    if declined:
        return overruled(
            decision, DecisionKind.IDLE, f"{why}, and the human declined to fetch it: waiting", "declined"
        )
    known = " (known: not planned again in this scene)" if again else ""
    return overruled(decision, DecisionKind.ASK, why + known, "infeasible")
