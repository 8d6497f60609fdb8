"""The failure-budget gate replayed on one recorded stream of decisions (`replay_stream`).

For each execution of a self-confidence dataset in order, κ̂ predicts from the action's embedding and the context
the robot perceived, the gate acts, asks or (with the heft test) probes, and only an attempt is labelled: an asked
action teaches nothing, as on the robot. The gate's rules are the tree's (`replay_rules`, gate.rules), so the
replay and the robot decide alike (tests/gate/test_one_decision.py). `StreamResult` counts what happened;
benchmarks.replay_rates pools the counts, benchmarks.gate drives the whole report.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from functools import partial
from typing import TYPE_CHECKING, Any

import numpy as np

from scone_bt.experience.types import CONTEXT_FIELDS, ExecutionContext

if TYPE_CHECKING:
    from scone_bt.gate.budget import BudgetCounts, BudgetOptions
    from scone_bt.gate.probe import ProbeOptions
    from scone_bt.gate.rules import GateInput, GateResult, GateRules
    from scone_bt.gate.types import Decision
    from scone_bt.motion.probe import ProbeSettings

__all__ = [
    "SET_BACK_CAUSES",
    "SET_BACK_FELT",
    "SET_BACK_MISSED",
    "SET_BACK_UNSURE",
    "UNSURE",
    "HelpTally",
    "StreamResult",
    "feature_rows",
    "replay_rules",
    "replay_stream",
]

_CONTEXT = CONTEXT_FIELDS
"""The context columns in replay order (decision_time_context's)."""
_WIDTH = _CONTEXT.index("detected_width_m")
"""The column of the perceived width (what the too-wide rule reads)."""
_TIER = _CONTEXT.index("shelf_tier")
_HEIGHT = _CONTEXT.index("detected_height_m")
"""The columns `gate.rules.flat_on_lowest` reads besides the width."""


def _perceived(row: np.ndarray) -> ExecutionContext:
    """A row's perceived tier and size (CONTEXT_FIELDS order; NaN: unknown), as `gate.rules.flat_on_lowest` reads
    them from the robot's own contexts."""
    tier = float(row[_TIER])
    return ExecutionContext(
        shelf_tier=None if np.isnan(tier) else int(tier),
        detected_width_m=float(row[_WIDTH]),
        detected_height_m=float(row[_HEIGHT]),
    )


UNSURE = "unsure"
"""The help cause of an ask κ̂ decided (below τ, not explored, not probed): no rule (`Decision.rule` "")."""
SET_BACK_FELT = "set-back-felt"
"""A probe the fingers felt slip or strain set the product back (motion.probe.judge_probe)."""
SET_BACK_UNSURE = "set-back-unsure"
"""A probe that held set the product back on κ̂'s doubt after it, with no credit to carry on (gate.after_probe)."""
SET_BACK_MISSED = "set-back-missed"
"""A probe whose fingers closed on nothing left the product where it stood."""
SET_BACK_CAUSES = (SET_BACK_FELT, SET_BACK_UNSURE, SET_BACK_MISSED)
"""Why a heft test ended with the product back in its place (an aborted attempt: the person fetches it). Every
other help cause is the rule that made the ask (`gate.types.DECISION_RULES`: "too-wide", "missing", …) or
`UNSURE`."""


@dataclass
class HelpTally:
    """Scored decisions the person fetched for, of one cause: how many, how many would have succeeded, and how many
    were of a product perceived wider than the gripper."""

    decisions: int = 0
    would_have_succeeded: int = 0
    wider_than_gripper: int = 0

    def add(self, other: HelpTally) -> None:
        """Pool ``other``'s counts into these."""
        self.decisions += other.decisions
        self.would_have_succeeded += other.would_have_succeeded
        self.wider_than_gripper += other.wider_than_gripper


@dataclass
class StreamResult:
    """What the gate did over one stream (counts; ``scored`` marks decisions after the warm-up)."""

    decisions: int = 0
    attempts: int = 0
    failures: int = 0
    asked_ok: int = 0
    asked_fail: int = 0
    novel_attempts: int = 0
    novel_failures: int = 0
    explored: int = 0
    wide_after_failure: int = 0
    all_decisions: int = 0
    all_attempts: int = 0
    all_failures: int = 0
    all_asked: int = 0
    max_excess: float = 0.0
    probes: int = 0
    aborted: int = 0
    aborted_would_succeed: int = 0
    probe_caught: int = 0
    probe_s: float = 0.0
    probes_felt: int = 0
    confident_failures: int = 0
    """Failed attempts, warm-up included, whose κ̂ at the final decision (after the probe, if probed) was ≥ τ, or
    that carried on by feel."""
    by_feel: int = 0
    """Attempts, warm-up included, carried on because the probe felt the product held fast, κ̂ below τ."""
    by_feel_failures: int = 0
    """Failures among them."""
    unfelt_probe_failures: int = 0
    """Probes, warm-up included, that failed before the fingers felt anything (a probe needs no credit: the one way
    an attempt that is neither confident nor explored can fail)."""
    thresholds: list[float] = field(default_factory=list)
    trace: list[int] = field(default_factory=list)
    """Every decision in order: 1 acted and succeeded, 0 acted and failed, -1 asked."""
    help_causes: dict[str, HelpTally] = field(default_factory=dict)
    """Scored decisions the person fetched for, by cause (`SET_BACK_CAUSES`, the rule that asked, or `UNSURE`)."""


def replay_rules(
    gate: str,
    alpha: float,
    opening_m: float,
    probe: ProbeOptions | None = None,
    excess_allowance: float | None = None,
    budget: BudgetOptions | None = None,
    slide_pinch: bool = False,
) -> GateRules:
    """The gate's rules for a replayed method (see `replay_stream`'s ``gate``); ``probe``: the budget gate's heft
    test (None: none); ``excess_allowance``: exploration spends only credit (gate.budget.has_credit; None: the
    budget's exploration rule alone); ``budget``: the failure budget's other settings (its start and step; None:
    the shipped ones), its target failure rate and allowance replaced by ``alpha`` and ``excess_allowance``;
    ``slide_pinch``: the stream's arm slid and pinched flat packs (the budget gate leaves them to κ̂).

    The per-action failure limit is not among them: it counts failures within one episode, and a stream's
    executions are each from another.
    """
    from dataclasses import replace

    from scone_bt.gate import GateOptions
    from scone_bt.gate.budget import BudgetOptions
    from scone_bt.gate.rules import GateRules

    budget = replace(budget or BudgetOptions(), target_failure_rate=alpha, excess_allowance=excess_allowance)
    # one candidate of relevance 1 a decision: the relevance threshold never idles it
    if gate == "budget":
        return GateRules(
            budget=budget, exploration=budget, opening_m=opening_m, probe=probe, slide_pinch=slide_pinch
        )
    if gate == "fixed":
        return GateRules(
            budget=replace(budget, step=0.0),
            exploration=budget,
        )
    if gate == "conformal":
        return GateRules(GateOptions(confidence_threshold=1.0 - alpha), exploration=budget)
    return GateRules(GateOptions(confidence_threshold=0.5))


def _explores(explore_fn: Callable[[np.ndarray], np.ndarray], row: np.ndarray) -> bool:
    """The paper's ε-greedy κ̂'s draw for one row."""
    return bool(explore_fn(row)[0])


class _LazyDraw(Sequence[bool]):
    """One candidate's exploration draw, taken when the gate reads it (only below τ)."""

    def __init__(self, draw: Callable[[], bool]) -> None:
        self._draw = draw

    def __len__(self) -> int:
        return 1

    def __getitem__(self, i):
        return self._draw()


def feature_rows(vectors: np.ndarray, context: np.ndarray, grounded: bool) -> np.ndarray:
    """κ̂'s input rows: ζ followed by the perceived context for a grounded κ̂, ζ alone otherwise."""
    return np.hstack([vectors, context]) if grounded else vectors


@dataclass(frozen=True)
class _Replay:
    """What one stream's replay decides with.

    Attributes:
        estimator: κ̂, learning online (fitted on the fleet prior first, if any).
        rows: (n, d) κ̂'s input rows: the embeddings, then the context when κ̂ is grounded.
        rules: The replayed method's gate rules.
        draw: The exploration draws, uniform in [0, 1).
        belief: κ̂'s belief for a row (its prediction when it has no separate belief).
        explore_fn: The paper's ε-greedy κ̂'s own draw (``paper`` gate only), else None.
        widths: (n,) the perceived widths, m (NaN unknown).
        wide: (n,) whether each product was perceived wider than the gripper's opening.
        flat_low: (n,) whether each was perceived a flat pack on a lowest tier (`gate.rules.flat_on_lowest`).
        probe: The heft test's motion settings, or None (no probe, or a stream without probe readings).
        readings: (n, 11) what the recorded probe felt (dataset.PROBE_READING_COLUMNS; (n, 5), PROBE_COLUMNS
            alone, reads as nothing more measured), or None.
        context: (n, len(CONTEXT_FIELDS)) the perceived context, as at each decision.
        grounded: Whether κ̂ reads the context (its rows end with it).
    """

    estimator: Any
    rows: np.ndarray
    rules: GateRules
    draw: Callable[[], float]
    belief: Callable[[np.ndarray], np.ndarray]
    explore_fn: Callable[[np.ndarray], np.ndarray] | None
    widths: np.ndarray
    wide: np.ndarray
    flat_low: np.ndarray
    probe: ProbeSettings | None
    readings: np.ndarray | None
    context: np.ndarray
    grounded: bool


def _start_replay(
    vectors: np.ndarray,
    context: np.ndarray,
    estimator: str,
    gate: str,
    alpha: float,
    seed: int,
    opening_m: float,
    fleet: tuple[np.ndarray, np.ndarray] | None,
    draw: Callable[[], float] | None,
    probe: ProbeOptions | None,
    readings: np.ndarray | None,
    excess_allowance: float | None,
    budget: BudgetOptions | None = None,
    slide_pinch: bool = False,
) -> _Replay:
    """κ̂ (fitted on the fleet prior), its rows, the method's rules and the draws (`replay_stream`'s arguments)."""
    from scone_bt.confidence import make_estimator
    from scone_bt.confidence.grounded import is_grounded
    from scone_bt.gate.rules import flat_on_lowest
    from scone_bt.motion.probe import ProbeSettings

    settings = ProbeSettings.of(probe) if probe is not None and readings is not None else None
    if readings is None:  # no readings, no probe: a stream recorded without the heft test cannot replay one
        probe = None
    options = {"gripper_opening_m": opening_m} if estimator == "physical" else {}
    est = make_estimator(estimator, seed=seed, **options)
    grounded = is_grounded(est)
    X = feature_rows(vectors, context, grounded)
    if fleet is not None:
        est.fit(fleet[0] if grounded else fleet[0][:, : vectors.shape[1]], fleet[1])
    widths = context[:, _WIDTH]
    return _Replay(
        estimator=est,
        rows=X,
        rules=replay_rules(gate, alpha, opening_m, probe, excess_allowance, budget, slide_pinch),
        draw=draw or np.random.default_rng(seed).random,
        belief=getattr(est, "belief", est.predict),
        explore_fn=getattr(est, "explores", None) if gate == "paper" else None,
        widths=widths,
        wide=np.nan_to_num(widths, nan=0.0) > opening_m,
        flat_low=np.array(
            [bool(flat_on_lowest({"": _perceived(c)}, opening_m)) for c in context],
            dtype=bool,
        ),
        probe=settings,
        readings=readings if settings is not None else None,
        context=context,
        grounded=grounded,
    )


def _gate_input(
    replay: _Replay, t: int, product: str, counts: BudgetCounts, failed: dict[str, int]
) -> GateInput:
    """The gate's view of decision ``t``: the stream's one action, κ̂'s belief, the width and the counts."""
    from scone_bt.gate.rules import GateInput
    from scone_bt.relevance.types import RankedAction

    row = replay.rows[t : t + 1]
    explore_fn = replay.explore_fn
    return GateInput(
        # one candidate, relevant by construction: the stream is of actions the robot was asked to take
        ranked=(RankedAction(product, 1.0),),
        confidences=(float(replay.belief(row)[0]),),
        # the paper's ε-greedy κ̂ draws only when asked (below τ), as it did before the gate was shared
        kappa_explores=_LazyDraw(partial(_explores, explore_fn, row)) if explore_fn is not None else (),
        objects={product: product},
        widths_m={product: float(replay.widths[t])},
        flat_on_lowest=frozenset({product}) if replay.flat_low[t] else frozenset(),
        counts=counts,
        failures=failed,
        draw=replay.draw,
    )


@dataclass(frozen=True)
class _Probed:
    """How decision ``t``'s heft test ended: set back or not, the attempt as κ̂ at its final decision saw it
    (`_Act`: explored, confident by κ̂ or by feel, held fast, unfelt; its row the context after the probe, the
    decision's row if the arm never held the product up), and whether a set-back is a label κ̂ learns (the
    fingers' word)."""

    aborted: bool
    attempt: _Act
    label: bool = True
    cause: str = ""
    """Why it was set back (`SET_BACK_CAUSES`), "" if it carried on."""


def _after_probe(
    replay: _Replay,
    out: StreamResult,
    t: int,
    product: str,
    counts: BudgetCounts,
    scored: bool,
    before: _Act,
) -> _Probed:
    """What the recorded probe of decision ``t`` felt, judged by the gate's one post-probe decision
    (gate.after_probe: the hard judge, then κ̂ on the context after the probe, a product held fast, then the
    strict rule's credit). ``before``: the attempt as the decision to probe saw it."""
    from dataclasses import replace

    from scone_bt.benchmarks.replay_streams import missed_in_place, reading_of
    from scone_bt.experience.felt import felt_row
    from scone_bt.gate.after_probe import after_probe
    from scone_bt.motion.probe import judge_probe

    assert replay.readings is not None and replay.probe is not None  # a probe decision needs both
    out.probes += scored
    values = replay.readings[t]
    reading = reading_of(values)
    if reading is None:  # the arm never held it up: it failed before the probe, as recorded
        if missed_in_place(values):
            # The fingers closed on nothing and the product stood where it stood: aborted, as the tree ends it
            # (motion.probe.ProbeController._after_miss), and κ̂ learns it could not take it.
            return _Probed(True, before, cause=SET_BACK_MISSED)
        return _Probed(False, replace(before, unfelt=True))
    if scored:
        out.probe_s += reading.seconds
        out.probes_felt += 1
    row = replay.rows[t]
    if replay.grounded:  # κ̂ reads the context: the one it has after the probe
        context = felt_row(replay.context[t], reading)
        row = np.concatenate([row[: len(row) - len(context)], context]).astype(row.dtype)
    confidence = float(replay.belief(row[None])[0])
    felt = judge_probe(reading, replay.probe)
    verdict = after_probe(replay.rules, counts, product, felt, confidence, reading.lift_traction)
    attempt = replace(
        before,
        explored=verdict.explored,
        confident=verdict.confident,
        row=row,
        held_fast=verdict.held_fast,
        by_feel=verdict.by_feel,
        traction=verdict.traction,
    )
    cause = "" if verdict.carry else SET_BACK_FELT if verdict.felt_unsafe else SET_BACK_UNSURE
    return _Probed(not verdict.carry, attempt, verdict.carry or verdict.felt_unsafe, cause)


def _committed(
    replay: _Replay,
    walk: _Walk,
    out: StreamResult,
    t: int,
    product: str,
    ok: bool,
    result: GateResult,
    scored: bool,
) -> _Probed:
    """What decision ``t`` commits to: set back or not (and why), and the attempt as κ̂ at the final decision saw
    it. A probe is judged by gate.after_probe; a set-back is tallied here (κ̂ learns it when the fingers said so)."""
    decision = result.decision
    attempt = _Act(ok, decision.explored, decision.confidence >= result.threshold, replay.rows[t])
    if not decision.probe:
        return _Probed(False, attempt)
    probed = _after_probe(replay, out, t, product, walk.counts, scored, attempt)
    if probed.aborted:
        walk.counts = _set_back(replay, probed.attempt.row, product, walk.counts, walk.learnt, probed.label)
    return probed


def _asks_anyway(result: GateResult, rule: str) -> GateResult:
    """What the robot does with an execution it knows before its arm moves it cannot do (`foreseen`'s ``rule``):
    where the gate decided to act, it asks for the product instead, as the tree does: for a target it sees
    nowhere (gate.rules.ask_for_missing), for one no plan reaches (gate.rules.infeasible_decision)."""
    from dataclasses import replace

    from scone_bt.gate.rules import overruled
    from scone_bt.gate.types import DecisionKind

    decision = result.decision
    if decision.kind is not DecisionKind.ACT:
        return result
    item = decision.object_name
    why = (
        f"I cannot see the {item} the step needs: please bring it"
        if rule == "missing"
        else f"I cannot plan to fetch the {item}"
    )
    return replace(result, decision=overruled(decision, DecisionKind.ASK, why, rule))


def _decided(replay: _Replay, walk: _Walk, t: int, product: str, rule: str) -> GateResult:
    """Decision ``t`` as the tree makes it: the gate's (gate.rules.gate_decision), then, where the robot knows
    before its arm moves that it cannot act (`foreseen`'s ``rule``, "" if not), an ask instead of an ACT; an
    infeasible plan is learnt as a failure at planning (`_infeasible`)."""
    from scone_bt.gate.rules import gate_decision
    from scone_bt.gate.types import DecisionKind

    result = gate_decision(replay.rules, _gate_input(replay, t, product, walk.counts, walk.failed))
    if rule and result.decision.kind is DecisionKind.ACT:
        result = _asks_anyway(result, rule)
        if rule == "infeasible":
            _infeasible(replay, walk, t, product)
    return result


def _infeasible(replay: _Replay, walk: _Walk, t: int, product: str) -> None:
    """A plan found infeasible before committing is experience, not an attempt (behaviours.outcome.RecordInfeasible):
    κ̂ learns a failure at planning; the budget's attempts and failures do not move."""
    from dataclasses import replace

    replay.estimator.update(replay.rows[t], False)
    walk.learnt.add(product)
    walk.counts = replace(walk.counts, learnt=replay.estimator.n_observations)


def _set_back(
    replay: _Replay, row: np.ndarray, product: str, counts: BudgetCounts, learnt: set[str], label: bool
) -> BudgetCounts:
    """An aborted probe: no attempt and no failure, the person fetches it; κ̂ learns it could not carry it (from
    the context after the probe) when the fingers said so (``label``), nothing when its own doubt set it back."""
    from dataclasses import replace

    est = replay.estimator
    if label:
        est.update(row, False)
        learnt.add(product)
    return replace(counts, learnt=est.n_observations)


@dataclass
class _Walk:
    """The replay's running state: the budget's counts, the products κ̂ has an outcome of, failures per product,
    and whether a product wider than the gripper has failed yet."""

    counts: BudgetCounts
    learnt: set[str] = field(default_factory=set)
    failed: dict[str, int] = field(default_factory=dict)
    wide_failed: bool = False


@dataclass(frozen=True)
class _Act:
    """One attempt: its outcome, whether it was explored (below τ on the budget's draw or its credit), whether κ̂
    at the final decision was at or above τ or it carried on by feel (confident), the row κ̂ learns from, whether
    a probe before it felt the product held fast, whether it carried on for that alone (by feel), and whether it
    was a probe that failed before the fingers felt anything (unfelt)."""

    ok: bool
    explored: bool
    confident: bool
    row: np.ndarray
    held_fast: bool = False
    by_feel: bool = False
    unfelt: bool = False
    traction: float | None = None
    """The load over the grip its probe felt (None: no probe; NaN or inf where not measured, then not held fast)."""


def _attempted(
    replay: _Replay,
    walk: _Walk,
    out: StreamResult,
    t: int,
    product: str,
    act: _Act,
    scored: bool,
    alpha: float,
) -> None:
    """Attempt ``t`` happened: tally it, κ̂ learns its outcome (an attempt is the only labelled kind), and the
    budget's counts move on."""
    from scone_bt.gate.budget import BudgetCounts, FeltCarry

    est, counts, ok = replay.estimator, walk.counts, act.ok
    carry = FeltCarry.of(act.held_fast, act.traction, ok, act.by_feel)
    out.all_attempts += 1
    out.all_failures += not ok
    out.confident_failures += act.confident and not ok
    out.by_feel += act.by_feel
    out.by_feel_failures += act.by_feel and not ok
    out.unfelt_probe_failures += act.unfelt and not ok
    if replay.wide[t] and walk.wide_failed and scored:
        out.wide_after_failure += 1
    if replay.wide[t] and not ok:
        walk.wide_failed = True
    est.update(act.row, ok)
    walk.learnt.add(product)
    if not ok:
        walk.failed[product] = walk.failed.get(product, 0) + 1
    walk.counts = BudgetCounts(
        attempts=counts.attempts + 1,
        failures=counts.failures + (not ok),
        explored_failures=counts.explored_failures + (act.explored and not ok),
        learnt=est.n_observations,
        held_fast=(*counts.held_fast, carry) if carry is not None else counts.held_fast,
    )
    out.max_excess = max(out.max_excess, walk.counts.failures - alpha * walk.counts.attempts)


def _tally_help(out: StreamResult, cause: str, ok: bool, wide: bool) -> None:
    """One scored decision the person fetched for (`StreamResult.help_causes`)."""
    out.help_causes.setdefault(cause, HelpTally()).add(HelpTally(1, int(ok), int(wide)))


def _score(out: StreamResult, act: bool, ok: bool, explored: bool, novel: bool, aborted: bool) -> None:
    """Tally one decision after the warm-up."""
    out.decisions += 1
    out.explored += explored
    if aborted:
        out.aborted += 1
        out.aborted_would_succeed += ok
        out.probe_caught += not ok
    elif act:
        out.attempts += 1
        out.failures += not ok
        out.novel_attempts += novel
        out.novel_failures += novel and not ok
    elif ok:
        out.asked_ok += 1
    else:
        out.asked_fail += 1


@dataclass(frozen=True)
class _Row:
    """One execution of the stream as the replay decides it: its index, product, outcome (revealed only if
    attempted), whether it is scored (after the warm-up) and `foreseen`'s rule for it ("" if none)."""

    t: int
    product: str
    ok: bool
    scored: bool
    rule: str


def _step(
    replay: _Replay, walk: _Walk, out: StreamResult, row: _Row, alpha: float, trace: list[Decision] | None
) -> None:
    """One decision: made (`_decided`), committed to (`_committed`: a probe may set it back), learnt and tallied."""
    from scone_bt.gate.types import DecisionKind

    t, product, ok, scored = row.t, row.product, row.ok, row.scored
    result = _decided(replay, walk, t, product, row.rule)
    if trace is not None:
        trace.append(result.decision)
    decision = result.decision
    act = decision.kind is DecisionKind.ACT
    probed = _committed(replay, walk, out, t, product, ok, result, scored)
    aborted, attempt = probed.aborted, probed.attempt
    if aborted:
        act = False
    novel = product not in walk.learnt
    out.all_decisions += 1
    out.thresholds.append(result.threshold)
    out.trace.append(int(ok) if act else -1)
    if act:
        _attempted(replay, walk, out, t, product, attempt, scored, alpha)
    out.all_asked += not act
    if scored:
        _score(out, act, ok, attempt.explored if act else decision.explored, novel, aborted)
        if not act:
            _tally_help(out, probed.cause or decision.rule or UNSURE, ok, bool(replay.wide[t]))


def replay_stream(
    vectors: np.ndarray,
    context: np.ndarray,
    success: np.ndarray,
    products: Sequence[str],
    estimator: str,
    gate: str,
    alpha: float,
    seed: int,
    warmup: int,
    opening_m: float,
    fleet: tuple[np.ndarray, np.ndarray] | None = None,
    trace: list[Decision] | None = None,
    draw: Callable[[], float] | None = None,
    probe: ProbeOptions | None = None,
    readings: np.ndarray | None = None,
    excess_allowance: float | None = None,
    foreseen: np.ndarray | None = None,
    budget: BudgetOptions | None = None,
    slide_pinch: bool = False,
) -> StreamResult:
    """The online robot over one stream; see the module docstring.

    Args:
        vectors: (n, d) the actions' embeddings, in stream order.
        context: (n, len(CONTEXT_FIELDS)) the perceived context (CONTEXT_FIELDS order, NaN unknown).
        success: (n,) whether each execution succeeded (revealed only if attempted).
        products: (n,) product names (novel = κ̂ has no outcome of it yet in this stream).
        estimator: κ̂ registry name.
        gate: "budget" (the tree's gate: it also asks about a product perceived wider than ``opening_m``),
            "fixed" (τ₀ = 1 − 5α, the budget's start, no calibration), "conformal" (act at 1 − α) or "paper" (0.5).
        alpha: Target failure rate.
        seed: Seeds κ̂ and the exploration draws.
        warmup: Decisions not scored.
        opening_m: The gripper's opening (what "wide" means).
        fleet: Rows and labels κ̂ learns before the stream (a fleet prior), or None (cold).
        trace: If given, each decision is appended to it (the same `gate_decision` the tree's gate makes).
        draw: The exploration draws, uniform in [0, 1) (default: a generator seeded with ``seed``).
        probe: The budget gate's heft test (gate.probe, the rules' `probe_first`), or None.
        readings: (n, 5) what the recorded probe felt (PROBE_COLUMNS; NaN: never held up), or None (no probe).
        excess_allowance: Explore only while one more failure keeps F ≤ α · A + this (gate.budget.has_credit);
            None: no such limit (the tree's ``exploration_credit: false``).
        foreseen: (n,) for each execution, the rule by which the robot knows before its arm moves that it cannot
            do it (`foreseen`: "missing", the target not detected; "infeasible", no plan; "" neither): where the
            gate decides to act, the robot asks, as the tree does (no attempt, no probe; κ̂ learns a failure at
            planning from an infeasible plan, nothing from a missing target); None: none.
        budget: The failure budget's start and step (`replay_rules`; None: the shipped ones).
        slide_pinch: The stream's arm slid and pinched flat packs on a lowest tier (`Streams.slide_pinch`).
    """
    from scone_bt.gate.budget import BudgetCounts

    replay = _start_replay(
        vectors,
        context,
        estimator,
        gate,
        alpha,
        seed,
        opening_m,
        fleet,
        draw,
        probe,
        readings,
        excess_allowance,
        budget,
        slide_pinch,
    )
    walk = _Walk(BudgetCounts(learnt=replay.estimator.n_observations))
    out = StreamResult()
    for t in range(len(success)):  # one decision a row, in stream order
        rule = str(foreseen[t]) if foreseen is not None else ""
        _step(replay, walk, out, _Row(t, products[t], bool(success[t]), t >= warmup, rule), alpha, trace)
    return out
