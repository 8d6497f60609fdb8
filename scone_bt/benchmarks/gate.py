"""``scone-bench gate``: does the gate keep its promise on products it never saw, and how much does it ask for it?

The online robot is replayed over self-confidence datasets (``--datasets DIR``, any folder that
``scone-bench sc generate`` wrote; default tools/data/sc: 11 streams of 100 real physical executions). Each
stream starts cold (no fleet prior): for each execution in order κ̂ predicts from the action's embedding and the
context the robot perceived, the gate acts or asks, and **only an attempt is labelled** (censoring: an asked
action teaches nothing, as on the robot). All decisions are made by the gate from the first one on; the first
``--warmup`` decisions of each stream are not scored (the promise is about the robot after it has had a chance to
learn), and the same figures over every decision are reported beside them.

Per method and per target failure rate α (0.05 … 0.40), pooled over the streams after their warm-up:
``success_rate`` (acted and succeeded / decisions), ``help_rate`` (asked / decisions), ``over_ask_rate`` (asked,
would have succeeded), ``over_step_rate`` (acted, failed), ``attempt_failure_rate`` (failed attempts / attempts),
its split into ``attempt_failure_rate_novel`` (products κ̂ had no outcome of in the stream) and ``_seen``,
``wide_attempts_after_first_wide_failure`` (attempts of products perceived wider than the gripper's opening after a
stream's first failed one, summed and the largest per stream), the realised rate per stream, and
``max_excess_failures``: the largest F − α · A reached at any point of any stream, warm-up included, and
``max_excess_failures_where_confident_held``: the same over only the streams in which no confident attempt failed
(null if there is none; ``streams_where_confident_held`` says how many). An attempt is *confident* when κ̂ at its
final decision was at or above the threshold τ (the gate's κ̂ for an action that was not probed, κ̂ on the
context after the probe, what the fingers felt, for one that was), or when it carried on by feel (the probe felt
the product held fast, on that rule's own record: ``by_feel_attempts``, ``by_feel_failures``). With the strict
promise on (``--exploration-credit``: gate.budget.has_credit, gate.after_probe) that key is ≤ 1 but for a probe
that failed before the fingers felt anything (a probe needs no credit; ``probe_failures_before_feeling`` counts
them).

The replay decides as the tree does where the robot knows before its arm moves that it cannot act (`foreseen`):
a target the camera did not detect is asked for (the tree has no affordance for it), and where no plan exists
the gate's ACT becomes an ask before the arm moves, learnt by κ̂ as a failure at planning (RecordInfeasible), not
an attempt. The datasets record both as failed executions: the generator attempts every row. Methods:

- ``budget:<κ̂>``: the failure-budget gate (scone_bt.gate.budget) over κ̂ (the tree's default: ``physical``);
- ``fixed:<κ̂>``: the same κ̂ and exploration with a threshold fixed at τ₀ (1 − 3α) (no online calibration);
- ``conformal``: the full conformal KNN gate at α (KnowNo-style; acts when 1 − p-value ≥ 1 − α), with the same
  exploration (without it a cold conformal gate never acts);
- ``paper``: the paper's ε-KNN at its fixed 0.5 threshold (one point: it states no rate);
- ``oracle``: the budget gate over κ̂ given the true width, height, mass and glass (the ceiling).

The tree's default (``default.*``) is ``budget:<the tree's estimator>`` at the tree's ``target_failure_rate``, cold
and fleet-warm (κ̂ first learns every execution of the other streams: a fleet's shared store).

``--prior DIR`` (the move to another body): before each stream, every κ̂ first learns the outcomes of the
same-named dataset in DIR (the same robot's executions on another engine; ``default.*`` is then the taught robot),
and the report adds ``cross_engine`` (`scone_bt.benchmarks.cross_engine`): per profile the success rates of the
same executions on both engines, the executions whose outcome flips, and per α in 0.10, 0.15, 0.20 the default
gate taught and cold, with the decisions its budget needs before the realised rate is back within α + 0.02.

    scone-bench gate --datasets tools/data/sc_mujoco --prior tools/data/sc --json docs/results/gate_mujoco.json

    scone-bench gate --json docs/results/gate.json --plot docs/results/gate.png

``--unseen`` adds the ``unseen`` section (`scone_bt.benchmarks.gate_unseen`): on decisions about products κ̂ has
no outcome of (leave-products-out), the default gate cold, after the fleet prior and after the robot's own store.

    scone-bench gate --no-sweep --unseen --json docs/results/unseen.json
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from scone_bt.benchmarks.self_confidence.dataset import PROBE_COLUMNS
from scone_bt.experience.types import CONTEXT_FIELDS
from scone_bt.files import write_via
from scone_bt.reporting import emit_report

if TYPE_CHECKING:
    from scone_bt.gate.budget import BudgetCounts
    from scone_bt.gate.probe import ProbeOptions
    from scone_bt.gate.rules import GateInput, GateResult, GateRules
    from scone_bt.gate.types import Decision
    from scone_bt.motion.probe import ProbeSettings

__all__ = ["register", "StreamResult", "help_floor", "replay_stream", "replay_rules", "TARGETS"]

TARGETS: tuple[float, ...] = (0.05, 0.10, 0.15, 0.20, 0.25, 0.30, 0.40)
"""Target failure rates the report sweeps."""

_CONTEXT = CONTEXT_FIELDS
"""The context columns in replay order (decision_time_context's)."""
_WIDTH = _CONTEXT.index("detected_width_m")
"""The column of the perceived width (what the too-wide rule reads)."""


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


def replay_rules(
    gate: str,
    alpha: float,
    opening_m: float,
    probe: ProbeOptions | None = None,
    excess_allowance: float | None = None,
) -> GateRules:
    """The gate's rules for a replayed method (see `replay_stream`'s ``gate``); ``probe``: the budget gate's heft
    test (None: none); ``excess_allowance``: exploration spends only credit (gate.budget.has_credit; None: the
    budget's exploration rule alone).

    The per-action failure limit is not among them: it counts failures within one episode, and a stream's
    executions are each from another.
    """
    from scone_bt.gate import GateOptions
    from scone_bt.gate.budget import BudgetOptions
    from scone_bt.gate.rules import GateRules

    budget = BudgetOptions(target_failure_rate=alpha, excess_allowance=excess_allowance)
    # one candidate of relevance 1 a decision: the relevance threshold never idles it
    if gate == "budget":
        return GateRules(budget=budget, exploration=budget, opening_m=opening_m, probe=probe)
    if gate == "fixed":
        return GateRules(
            budget=BudgetOptions(target_failure_rate=alpha, step=0.0, excess_allowance=excess_allowance),
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


def _features(vectors: np.ndarray, context: np.ndarray, grounded: bool) -> np.ndarray:
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
        probe: The heft test's motion settings, or None (no probe, or a stream without probe readings).
        readings: (n, 5) what the recorded probe felt (PROBE_COLUMNS), or None.
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
) -> _Replay:
    """κ̂ (fitted on the fleet prior), its rows, the method's rules and the draws (`replay_stream`'s arguments)."""
    from scone_bt.confidence import make_estimator
    from scone_bt.confidence.grounded import is_grounded
    from scone_bt.motion.probe import ProbeSettings

    settings = ProbeSettings.of(probe) if probe is not None and readings is not None else None
    if readings is None:  # no readings, no probe: a stream recorded without the heft test cannot replay one
        probe = None
    options = {"gripper_opening_m": opening_m} if estimator == "physical" else {}
    est = make_estimator(estimator, seed=seed, **options)
    grounded = is_grounded(est)
    X = _features(vectors, context, grounded)
    if fleet is not None:
        est.fit(fleet[0] if grounded else fleet[0][:, : vectors.shape[1]], fleet[1])
    widths = context[:, _WIDTH]
    return _Replay(
        estimator=est,
        rows=X,
        rules=replay_rules(gate, alpha, opening_m, probe, excess_allowance),
        draw=draw or np.random.default_rng(seed).random,
        belief=getattr(est, "belief", est.predict),
        explore_fn=getattr(est, "explores", None) if gate == "paper" else None,
        widths=widths,
        wide=np.nan_to_num(widths, nan=0.0) > opening_m,
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

    from scone_bt.experience.felt import felt_row
    from scone_bt.gate.after_probe import after_probe
    from scone_bt.motion.probe import ProbeReading, judge_probe

    assert replay.readings is not None and replay.probe is not None  # a probe decision needs both
    out.probes += scored
    held, load, first, grip, seconds = replay.readings[t]
    if np.isnan(held):  # the arm never held it up: it failed before the probe, as recorded
        return _Probed(False, replace(before, unfelt=True))
    if scored:
        out.probe_s += seconds
        out.probes_felt += 1
    reading = ProbeReading(bool(held), float(load), float(first), float(grip), float(seconds))
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
    )
    return _Probed(not verdict.carry, attempt, verdict.carry or verdict.felt_unsafe)


def _committed(
    replay: _Replay,
    walk: _Walk,
    out: StreamResult,
    t: int,
    product: str,
    ok: bool,
    result: GateResult,
    scored: bool,
) -> tuple[bool, _Act]:
    """What decision ``t`` commits to: (set back, the attempt as κ̂ at the final decision saw it). A probe is
    judged by gate.after_probe; a set-back is tallied here (κ̂ learns it when the fingers said so)."""
    decision = result.decision
    attempt = _Act(ok, decision.explored, decision.confidence >= result.threshold, replay.rows[t])
    if not decision.probe:
        return False, attempt
    probed = _after_probe(replay, out, t, product, walk.counts, scored, attempt)
    if probed.aborted:
        walk.counts = _set_back(replay, probed.attempt.row, product, walk.counts, walk.learnt, probed.label)
    return probed.aborted, probed.attempt


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
    from scone_bt.gate.budget import BudgetCounts

    est, counts, ok = replay.estimator, walk.counts, act.ok
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
        held_fast_attempts=counts.held_fast_attempts + act.held_fast,
        held_fast_failures=counts.held_fast_failures + (act.held_fast and not ok),
    )
    out.max_excess = max(out.max_excess, walk.counts.failures - alpha * walk.counts.attempts)


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
    aborted, attempt = _committed(replay, walk, out, t, product, ok, result, scored)
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
) -> StreamResult:
    """The online robot over one stream; see the module docstring.

    Args:
        vectors: (n, d) the actions' embeddings, in stream order.
        context: (n, len(CONTEXT_FIELDS)) the perceived context (CONTEXT_FIELDS order, NaN unknown).
        success: (n,) whether each execution succeeded (revealed only if attempted).
        products: (n,) product names (novel = κ̂ has no outcome of it yet in this stream).
        estimator: κ̂ registry name.
        gate: "budget" (the tree's gate: it also asks about a product perceived wider than ``opening_m``),
            "fixed" (τ₀ = 1 − 3α, no calibration), "conformal" (act at 1 − α) or "paper" (0.5).
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
    )
    walk = _Walk(BudgetCounts(learnt=replay.estimator.n_observations))
    out = StreamResult()
    for t in range(len(success)):  # one decision a row, in stream order
        rule = str(foreseen[t]) if foreseen is not None else ""
        _step(replay, walk, out, _Row(t, products[t], bool(success[t]), t >= warmup, rule), alpha, trace)
    return out


def _stream_successes(r: StreamResult) -> int:
    """Scored decisions of one stream that would have succeeded, whatever the gate did with them."""
    return r.attempts - r.failures + r.asked_ok + r.aborted_would_succeed


def _rates(results: Sequence[StreamResult]) -> dict[str, Any]:
    tot = {
        k: sum(getattr(r, k) for r in results)
        for k in StreamResult.__dataclass_fields__
        if k not in ("thresholds", "trace", "max_excess", "probe_s")
    }
    probe_s = sum(r.probe_s for r in results)
    held = [r.max_excess for r in results if r.confident_failures == 0]
    n = max(tot["decisions"], 1)
    att = tot["attempts"]
    seen_att = att - tot["novel_attempts"]
    seen_fail = tot["failures"] - tot["novel_failures"]

    def ratio(a: int, b: int) -> float | None:
        return round(a / b, 4) if b else None

    successes = sum(_stream_successes(r) for r in results)
    return {
        "decisions": tot["decisions"],
        "attempts": att,
        "success_rate": round((att - tot["failures"]) / n, 4),
        # an aborted probe is an ask for the person: counted in the help rate (and apart, aborted_rate)
        "help_rate": round((tot["asked_ok"] + tot["asked_fail"] + tot["aborted"]) / n, 4),
        "aborted_rate": round(tot["aborted"] / n, 4),
        "help_rate_floor": help_floor(successes, tot["decisions"], ratio(tot["failures"], att)),
        # a clairvoyant that never fails: it attempts exactly what would succeed (help below it needs failures)
        "help_rate_floor_without_failures": help_floor(successes, tot["decisions"], 0.0),
        "probes": tot["probes"],
        "probe_s_mean": round(probe_s / tot["probes_felt"], 3) if tot["probes_felt"] else None,
        "aborted_would_have_succeeded": tot["aborted_would_succeed"],
        "aborted_would_have_failed": tot["probe_caught"],
        "over_ask_rate": round(tot["asked_ok"] / n, 4),
        "over_step_rate": round(tot["failures"] / n, 4),
        "attempt_failure_rate": ratio(tot["failures"], att),
        "attempt_success_rate": ratio(att - tot["failures"], att),
        "attempt_failure_rate_novel": ratio(tot["novel_failures"], tot["novel_attempts"]),
        "attempt_failure_rate_seen": ratio(seen_fail, seen_att),
        "novel_attempts": tot["novel_attempts"],
        "seen_attempts": seen_att,
        "exploration_attempts": tot["explored"],
        "wide_attempts_after_first_wide_failure": tot["wide_after_failure"],
        "wide_attempts_after_first_wide_failure_max_per_stream": max(r.wide_after_failure for r in results),
        "attempt_failure_rate_per_stream": [ratio(r.failures, r.attempts) for r in results],
        "help_rate_per_stream": [ratio(r.asked_ok + r.asked_fail + r.aborted, r.decisions) for r in results],
        # each stream's clairvoyant at that stream's own realised rate: where the help goes beyond what any gate needs
        "help_rate_floor_per_stream": [
            help_floor(_stream_successes(r), r.decisions, ratio(r.failures, r.attempts)) for r in results
        ],
        "by_feel_attempts": tot["by_feel"],
        "by_feel_failures": tot["by_feel_failures"],
        "probe_failures_before_feeling": tot["unfelt_probe_failures"],
        "max_excess_failures": round(max(r.max_excess for r in results), 4),
        # the promise's condition: streams where every failed attempt had κ̂ < τ at its final decision
        "max_excess_failures_where_confident_held": round(max(held), 4) if held else None,
        "streams_where_confident_held": len(held),
        "all_decisions": {
            "attempt_failure_rate": ratio(tot["all_failures"], tot["all_attempts"]),
            "help_rate": round(tot["all_asked"] / max(tot["all_decisions"], 1), 4),
        },
    }


@dataclass(frozen=True)
class _Streams:
    names: list[str]
    vectors: list[np.ndarray]
    context: list[np.ndarray]
    success: list[np.ndarray]
    products: list[tuple[str, ...]]
    readings: list[np.ndarray | None] = field(default_factory=list)
    foreseen: list[np.ndarray] = field(default_factory=list)


def _datasets_folder(args: argparse.Namespace) -> Path:
    from scone_bt.resources import repo_root

    return Path(args.datasets) if args.datasets else (repo_root() or Path(".")) / "tools" / "data" / "sc"


def _load(args: argparse.Namespace, oracle: bool, folder: Path | None = None) -> _Streams:
    from scone_bt.benchmarks.self_confidence.dataset import load_datasets
    from scone_bt.benchmarks.self_confidence.evaldata import decision_time_context
    from scone_bt.embedding import load_embedder

    if folder is None:
        folder = _datasets_folder(args)
    datasets = load_datasets(folder)

    def column(d: Any, name: str) -> np.ndarray:
        return d.context.get(name, np.full(len(d), np.nan))

    # The context the robot perceived, as the self-confidence evaluation reads it (one function for both).
    context = [decision_time_context(d) for d in datasets]
    if (
        oracle
    ):  # the true size where the robot has a perceived one, always "detected"; mass and glass stand for ζ
        vectors = [np.column_stack([column(d, "mass_kg"), _glass(d)]) for d in datasets]
        for d, c in zip(datasets, context, strict=True):
            c[:, _CONTEXT.index("detected")] = 1.0
            c[:, _CONTEXT.index("detected_width_m")] = column(d, "width_m")
            c[:, _CONTEXT.index("detected_height_m")] = column(d, "height_m")
    else:
        emb = load_embedder(args.embedder)
        actions = sorted({a for d in datasets for a in d.actions})
        table = dict(zip(actions, np.asarray(emb.embed(actions), dtype=np.float32), strict=True))
        vectors = [np.stack([table[a] for a in d.actions]) for d in datasets]
    return _Streams(
        [d.name for d in datasets],
        vectors,
        context,
        [np.asarray(d.success) for d in datasets],
        [tuple(d.objects) for d in datasets],
        [_readings(d) for d in datasets],
        [foreseen(d) for d in datasets],
    )


FORESEEN_STAGES: tuple[str, ...] = ("ik", "planning")
"""Failure stages at which no plan was made (motion.pick_place.Diagnosis.stage)."""

_TIMED_OUT: tuple[str, ...] = ("no path", "injected: no plan")
"""How a planning failure's detail begins when the planner only ran out of time (PlanFailureReason.NO_PATH, or the
generator's injected planning failure): the tree still attempts those (robot.sim: not `infeasible`), so they
stay failed attempts."""


PROBE_DATASETS: tuple[str, ...] = ("tools/data/sc_probe", "tools/data/sc_heldout_probe")
"""The committed datasets that record the heft test's readings (the others were generated without it)."""


def check_probe_readings(args: argparse.Namespace, streams: _Streams) -> None:
    """ConfigError (one line) when ``--probe`` asks to replay the heft test on datasets none of which recorded it:
    without readings every stream would be replayed without the probe, and the report would say so only in its
    ``default.probe`` key. The tree's own ``probe.enabled`` (no ``--probe``) is not checked: it falls back quietly."""
    from scone_bt.errors import ConfigError

    if getattr(args, "probe", None) is True and not any(r is not None for r in streams.readings):
        raise ConfigError(
            f"--probe: no dataset in {_datasets_folder(args)} records the heft test's readings "
            f"({', '.join(PROBE_COLUMNS)}); datasets that do: {', '.join(PROBE_DATASETS)} (--datasets)"
        )


def foreseen(d: Any) -> np.ndarray:
    """(n,) str: for each execution of a dataset, the rule by which the robot would ask instead of attempting it:
    "missing" where its target was not detected (the tree asks for what it sees nowhere, gate.rules.ask_for_missing),
    "infeasible" where the scene's geometry left no plan (it asks before the arm moves,
    gate.rules.infeasible_decision), else "". The generator attempts every one and records these as failed
    executions; a file without a ``detail`` column cannot tell a planner that ran out of time, so none of its
    planning failures is foreseen."""
    detected = np.nan_to_num(d.context.get("detected", np.ones(len(d))), nan=1.0)
    details = d.details or ("",) * len(d)
    geometric = [
        stage in FORESEEN_STAGES and bool(detail) and not detail.startswith(_TIMED_OUT)
        for stage, detail in zip(d.failure_stages, details, strict=True)
    ]
    rules = np.full(len(d), "", dtype=object)
    rules[np.array(geometric, dtype=bool)] = "infeasible"
    rules[detected == 0] = "missing"
    return rules


def _readings(d: Any) -> np.ndarray | None:
    """(n, 5) probe readings in PROBE_COLUMNS order, or None for a dataset recorded without the probe."""
    if any(c not in d.context for c in PROBE_COLUMNS):
        return None
    return np.column_stack([d.context[c] for c in PROBE_COLUMNS])


def _glass(d: Any) -> np.ndarray:
    return np.array([m == "glass" for m in d.materials], dtype=float) if d.materials else np.zeros(len(d))


def _rows(streams: _Streams, which: Sequence[int]) -> tuple[np.ndarray, np.ndarray]:
    """Streams' rows as κ̂ learns them (embedding then context) and their outcomes, as a store holds them
    (gate_unseen.stream_prior: no target that was not detected)."""
    from scone_bt.benchmarks.gate_unseen import stream_prior

    prior = stream_prior(streams, which)
    return prior.rows, prior.success


def _method(
    streams: _Streams,
    estimator: str,
    gate: str,
    alpha: float,
    args: argparse.Namespace,
    fleet: bool = False,
    taught: _Streams | None = None,
    probe: ProbeOptions | None = None,
) -> dict[str, Any]:
    """One method's pooled rates over every stream (`_stream_results`, then `_rates`)."""
    return _rates(_stream_results(streams, estimator, gate, alpha, args, fleet, taught, probe))


def _stream_results(
    streams: _Streams,
    estimator: str,
    gate: str,
    alpha: float,
    args: argparse.Namespace,
    fleet: bool = False,
    taught: _Streams | None = None,
    probe: ProbeOptions | None = None,
) -> list[StreamResult]:
    """Every stream replayed; ``taught`` (--prior): κ̂ first learns the same-named stream of it; ``probe``: the
    budget gate's heft test (None: none)."""
    results = []
    for j in range(len(streams.names)):
        parts = []
        if taught is not None:
            parts.append(_rows(taught, [taught.names.index(streams.names[j])]))
        others = [i for i in range(len(streams.names)) if i != j]
        if fleet and others:
            parts.append(_rows(streams, others))
        prior = (np.vstack([x for x, _ in parts]), np.concatenate([y for _, y in parts])) if parts else None
        results.append(
            replay_stream(
                streams.vectors[j],
                streams.context[j],
                streams.success[j],
                streams.products[j],
                estimator,
                gate,
                alpha,
                args.seed + j,
                args.warmup,
                args.opening,
                prior,
                probe=probe,
                readings=streams.readings[j] if streams.readings else None,
                excess_allowance=getattr(args, "excess_allowance", None),
                foreseen=streams.foreseen[j] if streams.foreseen else None,
            )
        )
    return results


def _tree_defaults(args: argparse.Namespace) -> tuple[str, float, ProbeOptions | None]:
    """The tree's κ̂, target failure rate and probe options (None: the probe is off; ``--probe``/``--no-probe``
    override the tree's ``probe.enabled``); sets ``args.excess_allowance`` from the tree's ``exploration_credit``
    (or ``--exploration-credit``/``--no-exploration-credit``): 1 when on, None when off."""
    from scone_bt.config.tree_parameters import TreeParameters
    from scone_bt.gate.probe import ProbeOptions
    from scone_bt.tree import load_tree_spec

    params = TreeParameters.model_validate(load_tree_spec("assistive_cooking").parameters)
    probing = params.probe.enabled if args.probe is None else args.probe
    credit = params.exploration_credit if args.exploration_credit is None else args.exploration_credit
    args.excess_allowance = 1.0 if credit else None
    args.probe_on = probing
    probe = ProbeOptions.of(params.probe.model_copy(update={"enabled": True})) if probing else None
    return params.estimator, params.target_failure_rate, probe


def _plot(report: dict[str, Any], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2))
    for name, per_target in report["methods"].items():
        pts = sorted(per_target.items(), key=lambda kv: float(kv[0]))
        helps = [m["help_rate"] for _, m in pts]
        succ = [m["attempt_success_rate"] or 0.0 for _, m in pts]
        left.plot(helps, succ, "o-" if len(pts) > 1 else "s", label=name)
        if len(pts) > 1:
            right.plot(
                [float(k) for k, _ in pts],
                [m["attempt_failure_rate"] or 0.0 for _, m in pts],
                "o-",
                label=name,
            )
    left.set_xlabel("help rate (asked / decisions)")
    left.set_ylabel("attempts that succeed")
    left.set_title("attempt success against asking (after warm-up)")
    left.grid(alpha=0.3)
    if report["methods"]:  # a report with no method has nothing to label
        left.legend(fontsize=7)
    lim = max(TARGETS) + 0.05
    right.plot([0, lim], [0, lim], "k--", lw=1, label="promise: realised = target")
    right.plot([0, lim], [0.02, lim + 0.02], "k:", lw=1, label="target + 0.02")
    right.set_xlabel("target failure rate α")
    right.set_ylabel("realised failure rate among attempts")
    right.set_title("the promise, on products never seen and seen")
    right.grid(alpha=0.3)
    right.legend(fontsize=7)
    fig.tight_layout()
    try:  # an existing figure stays whole until the new one is complete
        write_via(path, lambda tmp: fig.savefig(tmp, dpi=110))
    finally:
        plt.close(fig)


PLOT_SUFFIXES = (".png", ".svg", ".pdf")
"""The figure formats --plot writes, by the file's suffix."""


def check_plot_path(path: Path, inputs: dict[str, list[Path]], force: bool) -> None:
    """--plot before any work: a file of a known figure format, not an input, nothing else overwritten."""
    from scone_bt.checks import check_output_file
    from scone_bt.errors import SconeError

    if path.suffix.lower() not in PLOT_SUFFIXES and not path.is_dir():
        raise SconeError(
            f"--plot {path}: unknown figure format {path.suffix or '(no suffix)'!r}; "
            f"give a file ending in one of {', '.join(PLOT_SUFFIXES)}"
        )
    check_output_file(path, "--plot", kind="image", inputs=inputs, force=force)


def _episode_counts(events: Sequence[Any]) -> dict[str, Any]:
    """What one episode showed the human: failed attempts, help requests, interventions, and infeasible plans
    of an action planned again (a PlanInfeasible, or a failure at planning, after the first for that action)."""
    from scone_bt.events import (
        ActOutcome,
        DecisionMade,
        HelpRequested,
        Intervention,
        PlanInfeasible,
        ProbeAborted,
    )
    from scone_bt.motion.types import FailureStage

    out = {
        "failures": 0,
        "help": 0,
        "interventions": 0,
        "attempts": 0,
        "repeated_infeasible_plans": 0,
        "aborted": 0,
        "probed": 0,
        "act_s": 0.0,
        "aborted_s": 0.0,
    }
    infeasible: set[str] = set()
    planning: list[float] = []
    for e in events:
        if isinstance(e, ActOutcome):
            out["attempts"] += 1
            out["act_s"] += e.duration_s
            out["failures"] += not e.success
            if e.stage == FailureStage.PLANNING:
                out["repeated_infeasible_plans"] += e.action in infeasible
                infeasible.add(e.action)
        elif isinstance(e, PlanInfeasible):
            out["repeated_infeasible_plans"] += e.action in infeasible
            infeasible.add(e.action)
        elif isinstance(e, HelpRequested):
            out["help"] += 1
        elif isinstance(e, Intervention):
            out["interventions"] += 1
        elif isinstance(e, ProbeAborted):
            out["aborted"] += 1
            out["aborted_s"] += e.duration_s
        elif isinstance(e, DecisionMade):
            out["probed"] += e.probe
            if e.planning_s is not None:
                planning.append(e.planning_s)
    return {**out, "planning_s": planning}


def _episodes(args: argparse.Namespace) -> dict[str, Any]:
    """Seeded episodes over corpus recipes, self-confidence on (the tree's defaults) and the paper's control."""
    from scone_bt.behaviours import BehaviourOptions
    from scone_bt.benchmarks.decisions import pick_recipes
    from scone_bt.config import load_kitchen
    from scone_bt.episode import EpisodeOptions, ModelPool, run_episode

    models = ModelPool()
    slots = len(load_kitchen().scene.shelf_slots())
    recipes = pick_recipes(args.recipes, args.seed, slots - args.distractors)
    out: dict[str, Any] = {"episodes": args.episodes, "recipes": len(set(recipes[: args.episodes]))}
    conditions: dict[str, dict[str, Any]] = {
        "self_confidence_on": {},
        "control": {"use_self_confidence": False, "gate": "paper"},
    }
    if getattr(args, "probe_on", False):  # --probe: the heft test beside the tree's default
        credit = getattr(args, "excess_allowance", None) is not None
        conditions["self_confidence_on_probe"] = {"probe": {"enabled": True}, "exploration_credit": credit}
    for label, extra in conditions.items():
        totals: dict[str, float] = {}
        planning: list[float] = []
        completed = 0
        sim_s = 0.0
        t0 = time.perf_counter()
        for i in range(args.episodes):
            events: list[Any] = []
            seed = args.seed + i
            summary = run_episode(
                EpisodeOptions(
                    robot=args.arm,
                    backend=args.robot,
                    recipe=recipes[i % len(recipes)],
                    seed=seed,
                    distractors=args.distractors,
                    behaviour=BehaviourOptions(seed=seed, **extra),
                ),
                printer=lambda _line: None,
                on_event=events.append,
                models=models,
            )
            counts = _episode_counts(events)
            planning += counts.pop("planning_s")
            for k, v in counts.items():
                totals[k] = totals.get(k, 0) + v
            completed += bool(summary.completed)
            sim_s += summary.sim_time
            if not args.quiet:
                print(
                    f"{label} episode {i + 1}/{args.episodes}: {counts} sim_s={summary.sim_time:.2f}",
                    file=sys.stderr,
                )
        n = max(args.episodes, 1)
        out[label] = {
            "failures_per_episode": round(totals.get("failures", 0) / n, 3),
            "help_per_episode": round(totals.get("help", 0) / n, 3),
            "interventions_per_episode": round(totals.get("interventions", 0) / n, 3),
            "aborted_per_episode": round(totals.get("aborted", 0) / n, 3),
            "probed_per_episode": round(totals.get("probed", 0) / n, 3),
            "act_s_per_episode": round(totals.get("act_s", 0) / n, 2),
            "aborted_s_per_episode": round(totals.get("aborted_s", 0) / n, 2),
            "sim_s_per_episode": round(sim_s / n, 2),
            "repeated_infeasible_plans": int(totals.get("repeated_infeasible_plans", 0)),
            "attempts": int(totals.get("attempts", 0)),
            "attempt_success_rate": round(
                1 - totals.get("failures", 0) / max(totals.get("attempts", 0), 1), 4
            ),
            "completed": completed,
            "planning_before_commit_ms": _percentiles_ms(planning),
            "wall_s": round(time.perf_counter() - t0, 1),
        }
    return out


def _percentiles_ms(seconds: Sequence[float]) -> dict[str, float | int | None]:
    if not seconds:
        return {"p50": None, "p95": None, "n": 0}
    ms = np.asarray(seconds) * 1000.0
    return {
        "p50": round(float(np.percentile(ms, 50)), 2),
        "p95": round(float(np.percentile(ms, 95)), 2),
        "n": len(ms),
    }


def _decision_path(
    streams: _Streams, estimator: str, args: argparse.Namespace, reps: int = 40
) -> dict[str, Any]:
    """κ̂ on 21 objects (the kitchen's shelf: grounded rows) plus the gate's rule, right after an update (nothing
    memoised), the way the tree decides each cycle; planning before commitment is timed apart (episodes)."""
    from scone_bt.confidence import make_estimator
    from scone_bt.confidence.grounded import is_grounded
    from scone_bt.gate import GateOptions, decide
    from scone_bt.relevance import RankedAction

    est = make_estimator(estimator, seed=args.seed)
    V, C, y = streams.vectors[0], streams.context[0], streams.success[0]
    X = _features(V, C, is_grounded(est))
    n = len(X)
    for t in range(n // 2):
        est.update(X[t], bool(y[t]))
    ranked = [RankedAction(f"a{i}", 1.0 - i / 100) for i in range(21)]
    samples = []
    for r in range(reps):
        i = n // 2 + r % max(n - n // 2, 1)
        est.update(X[i % n], bool(y[i % n]))  # empties the memo, as after an outcome
        rows = X[(np.arange(21) + r) % len(X)]
        t0 = time.perf_counter()
        conf = est.predict(rows)
        decide(ranked, [float(c) for c in conf], GateOptions(confidence_threshold=0.7))
        samples.append(time.perf_counter() - t0)
    return {"objects": 21, "estimator": estimator, **_percentiles_ms(samples), "target_p50_ms": 10.0}


def _replay(
    args: argparse.Namespace,
    streams: _Streams,
    estimators: list[str],
    default_estimator: str,
    default_target: float,
    probe: ProbeOptions | None = None,
) -> dict[str, Any]:
    """The online replay of every method over the datasets (the report's replay part)."""
    taught, taught_oracle = _taught(args, streams)
    methods = {} if args.no_sweep else _sweep(args, streams, estimators, taught, taught_oracle)
    default = methods.get(f"budget:{default_estimator}")
    if default is None or f"{default_target:g}" not in default:
        plain = _method(streams, default_estimator, "budget", default_target, args, taught=taught)
    else:
        plain = default[f"{default_target:g}"]
    probing = probe is not None and any(r is not None for r in streams.readings)
    if (
        probing
    ):  # the tree's gate hefts what it is unsure of (gate.probe): its own sweep beside the plain budget
        methods[f"budget+probe:{default_estimator}"] = {
            f"{a:g}": _method(streams, default_estimator, "budget", a, args, taught=taught, probe=probe)
            for a in TARGETS
        }
        cold = methods[f"budget+probe:{default_estimator}"][f"{default_target:g}"]
    else:
        cold = plain
    # The fleet-warm variant relearns the other streams' 1,000 rows at every update: --no-sweep leaves it out.
    warm = (
        None
        if args.no_sweep
        else _method(
            streams, default_estimator, "budget", default_target, args, fleet=True, taught=taught, probe=probe
        )
    )
    extra: dict[str, Any] = {}
    if taught is not None:
        extra["cross_engine"] = _cross_engine(args, streams, taught, default_estimator)
    return {
        "datasets": streams.names,
        **({"prior": str(args.prior), "prior_datasets": taught.names} if taught is not None else {}),
        "targets": list(TARGETS),
        "default": {
            "estimator": default_estimator,
            "target_failure_rate": default_target,
            "attempt_failure_rate": cold["attempt_failure_rate"],
            "attempt_failure_rate_novel": cold["attempt_failure_rate_novel"],
            "attempt_failure_rate_seen": cold["attempt_failure_rate_seen"],
            "attempt_success_rate": cold["attempt_success_rate"],
            "help_rate": cold["help_rate"],
            "help_rate_floor": cold["help_rate_floor"],
            "help_rate_floor_without_failures": cold["help_rate_floor_without_failures"],
            "max_excess_failures": cold["max_excess_failures"],
            "max_excess_failures_where_confident_held": cold["max_excess_failures_where_confident_held"],
            "streams_where_confident_held": cold["streams_where_confident_held"],
            "exploration_credit": getattr(args, "excess_allowance", None) is not None,
            **_probe_keys(cold, plain, probing),
            "fleet_warm": None
            if warm is None
            else {
                k: warm[k]
                for k in (
                    "attempt_failure_rate",
                    "attempt_failure_rate_novel",
                    "attempt_success_rate",
                    "help_rate",
                    "aborted_rate",
                )
            },
        },
        "methods": methods,
        **extra,
        "decision_path_ms": _decision_path(streams, default_estimator, args),
    }


def _sweep(
    args: argparse.Namespace,
    streams: _Streams,
    estimators: list[str],
    taught: _Streams | None,
    taught_oracle: _Streams | None,
) -> dict[str, dict[str, Any]]:
    """Every method at every target (the report's ``methods``)."""
    methods: dict[str, dict[str, Any]] = {}
    for est in estimators:
        for gate in ("budget", "fixed"):
            methods[f"{gate}:{est}"] = {
                f"{a:g}": _method(streams, est, gate, a, args, taught=taught) for a in TARGETS
            }
    methods["conformal"] = {
        f"{a:g}": _method(streams, "conformal", "conformal", a, args, taught=taught) for a in TARGETS
    }
    methods["paper"] = {"0.5": _method(streams, "eps-knn", "paper", 0.5, args, taught=taught)}
    oracle = _load(args, oracle=True)
    methods["oracle"] = {
        f"{a:g}": _method(oracle, "physical", "budget", a, args, taught=taught_oracle) for a in TARGETS
    }
    return methods


def help_floor(successes: int, decisions: int, failure_rate: float | None) -> float | None:
    """The least help rate any gate could reach on these decisions at this attempt failure rate: a clairvoyant
    attempts every decision that would succeed and as many that would fail as the rate allows, A = S / (1 − f),
    and asks for the rest. None without decisions or attempts."""
    if not decisions or failure_rate is None or failure_rate >= 1.0:
        return None
    return round(1.0 - min(decisions, successes / (1.0 - failure_rate)) / decisions, 4)


def _probe_keys(cold: dict[str, Any], plain: dict[str, Any], probing: bool) -> dict[str, Any]:
    """The heft test's ``default.*`` keys: what it cost and caught, and the same gate without it."""
    return {
        "probe": probing,
        "aborted_rate": cold["aborted_rate"],
        "probe_s_mean": cold["probe_s_mean"],
        "probes": cold["probes"],
        "aborted_would_have_succeeded": cold["aborted_would_have_succeeded"],
        "aborted_would_have_failed": cold["aborted_would_have_failed"],
        "by_feel_attempts": cold["by_feel_attempts"],
        "by_feel_failures": cold["by_feel_failures"],
        "probe_failures_before_feeling": cold["probe_failures_before_feeling"],
        "help_rate_per_stream": cold["help_rate_per_stream"],
        "help_rate_floor_per_stream": cold["help_rate_floor_per_stream"],
        "without_probe": {
            k: plain[k]
            for k in ("attempt_failure_rate", "attempt_success_rate", "help_rate", "max_excess_failures")
        },
    }


def _taught(args: argparse.Namespace, streams: _Streams) -> tuple[_Streams | None, _Streams | None]:
    """--prior's datasets (κ̂ learns the same-named one before each stream) and their oracle view, or None."""
    from scone_bt.errors import SconeError

    if args.prior is None:
        return None, None
    taught = _load(args, oracle=False, folder=Path(args.prior))
    taught_oracle = None if args.no_sweep else _load(args, oracle=True, folder=Path(args.prior))
    missing = [n for n in streams.names if n not in taught.names]
    if missing:
        raise SconeError(
            f"--prior {args.prior}: no dataset {missing[0]!r} (it holds {', '.join(taught.names)}); "
            "κ̂ learns the same-named dataset before each stream"
        )
    return taught, taught_oracle


def _cross_engine(
    args: argparse.Namespace, streams: _Streams, taught: _Streams, estimator: str
) -> dict[str, Any]:
    """The gap between the engines per profile, and the default gate taught (--prior) and cold after the move."""
    from dataclasses import asdict

    from scone_bt.benchmarks.cross_engine import (
        CROSS_ENGINE_TARGETS,
        TOLERANCE,
        engine_gap,
        recovery_decisions,
    )

    gaps = engine_gap(Path(args.prior), _datasets_folder(args), streams.names)
    by_target: dict[str, Any] = {}
    for alpha in CROSS_ENGINE_TARGETS:
        row: dict[str, Any] = {}
        for label, prior in (("prior", taught), ("cold", None)):
            results = _stream_results(streams, estimator, "budget", alpha, args, taught=prior)
            rates = _rates(results)
            recovery = {
                n: recovery_decisions(r.trace, alpha) for n, r in zip(streams.names, results, strict=True)
            }
            row[label] = {
                "attempt_failure_rate": rates["attempt_failure_rate"],
                "help_rate": rates["help_rate"],
                "attempt_success_rate": rates["attempt_success_rate"],
                "attempt_failure_rate_per_stream": dict(
                    zip(streams.names, rates["attempt_failure_rate_per_stream"], strict=True)
                ),
                "meets_target": rates["attempt_failure_rate"] is not None
                and rates["attempt_failure_rate"] <= alpha + TOLERANCE + 1e-12
                and rates["help_rate"] <= 0.50,
                "all_decisions": rates["all_decisions"],
                "recovery_decisions": recovery,
                "recovered_streams": sum(v is not None for v in recovery.values()),
            }
        by_target[f"{alpha:g}"] = row
    return {
        "prior": str(args.prior),
        "tolerance": TOLERANCE,
        "help_rate_limit": 0.50,
        "recovery_definition": (
            "decisions on this engine (warm-up included) before the budget's realised attempt failure rate, "
            "counted from the move, is within alpha + tolerance and stays there to the end of the stream; "
            "0: never above; null: ends above"
        ),
        "default": by_target,
        "profiles": {
            n: {
                **{k: v for k, v in asdict(g).items() if k != "flips"},
                "flipped": [asdict(f) for f in g.flips],
            }
            for n, g in gaps.items()
        },
        "pooled": {
            "matched": sum(g.matched for g in gaps.values()),
            "to_failure": sum(g.to_failure for g in gaps.values()),
            "to_success": sum(g.to_success for g in gaps.values()),
        },
    }


def _run(args: argparse.Namespace) -> int:
    from scone_bt.errors import SconeError

    if args.warmup < 0:
        raise SconeError(f"--warmup {args.warmup}: must be 0 or more")
    if args.episodes < 0 or args.recipes < 1:
        raise SconeError("--episodes must be ≥ 0 and --recipes ≥ 1")
    started = time.perf_counter()
    default_estimator, default_target, probe = _tree_defaults(args)
    estimators = [e for e in args.estimators.split(",") if e] or [default_estimator]
    from scone_bt.cli.run import _check_estimator  # one check of registry names, before any work

    for e in estimators:
        _check_estimator(e)
    if args.plot is not None:
        from scone_bt.cli.bench import _inputs

        check_plot_path(args.plot, _inputs(args, ("plot", "json")), bool(getattr(args, "force", False)))
    report: dict[str, Any] = {
        "benchmark": "gate",
        "seed": args.seed,
        "embedder": args.embedder,
        "warmup": args.warmup,
        "gripper_opening_m": args.opening,
    }
    # the datasets, loaded and embedded once for the replay and the unseen section
    streams = _load(args, oracle=False) if not args.no_replay or args.unseen else None
    if streams is not None:
        check_probe_readings(args, streams)
    if streams is not None and not args.no_replay:
        report.update(_replay(args, streams, estimators, default_estimator, default_target, probe))
    if streams is not None and args.unseen:  # products κ̂ has no outcome of: cold, the fleet, its own store
        from scone_bt.benchmarks.gate_unseen import unseen_report

        report["unseen"] = unseen_report(
            streams,
            replay_stream,
            default_estimator,
            default_target,
            args.seed,
            args.warmup,
            args.opening,
            probe,
            args.excess_allowance,
        )
    if args.episodes:
        report["episodes"] = _episodes(args)
    report["wall_s"] = round(time.perf_counter() - started, 1)
    emit_report(report, args.json)  # the report first: a figure that cannot be drawn loses no numbers
    if args.plot is not None:
        _plot(report, args.plot)
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``gate`` to ``scone-bench``."""
    from scone_bt.confidence.physical import DEFAULT_OPENING_M
    from scone_bt.robot.flags import add_robot_options

    p = sub.add_parser(
        "gate", help="does the gate keep its failure budget on new products, and at what help rate"
    )
    p.add_argument("--datasets", help="self-confidence datasets folder (default tools/data/sc)")
    p.add_argument(
        "--prior",
        type=Path,
        default=None,
        metavar="DIR",
        help="datasets κ̂ learns before each same-named stream (the robot's outcomes on another engine)",
    )
    p.add_argument("--embedder", default="minilm", help="ζ (default: %(default)s)")
    p.add_argument(
        "--estimators",
        default="",
        help="comma-separated κ̂ names for the budget and fixed gates (default: the tree's)",
    )
    p.add_argument(
        "--warmup", type=int, default=20, help="decisions per stream not scored (default: %(default)s)"
    )
    p.add_argument(
        "--opening",
        type=float,
        default=DEFAULT_OPENING_M,
        help="gripper opening, metres (default: the Panda's)",
    )
    p.add_argument(
        "--episodes",
        type=int,
        default=0,
        help="seeded episodes per condition, on and control (default: 0, none)",
    )
    p.add_argument("--recipes", type=int, default=20, help="corpus recipes the episodes cycle through")
    p.add_argument("--distractors", type=int, default=4, help="distractor products per episode")
    add_robot_options(p, arm_help="robot file of the episodes (--episodes): a name in robots/ or a YAML path")
    p.add_argument("--no-replay", action="store_true", help="episodes only (skip the dataset replay)")
    p.add_argument(
        "--no-sweep",
        action="store_true",
        help="replay only the tree's default gate, cold (and --prior's cross-engine figures): no method sweep, "
        "no fleet-warm variant",
    )
    p.add_argument(
        "--unseen",
        action="store_true",
        help="also measure what the fleet prior and the robot's own store add on products κ̂ has no outcome of "
        "(leave-products-out; the report's unseen section)",
    )
    p.add_argument(
        "--probe",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="replay the heft test too (datasets with probe readings, e.g. tools/data/sc_probe; default: the "
        "tree's probe.enabled)",
    )
    p.add_argument(
        "--exploration-credit",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="the strict promise: explore only while one more failure keeps F ≤ α·A + 1 (default: the tree's "
        "exploration_credit)",
    )
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--quiet", action="store_true", help="no progress lines on stderr")
    p.add_argument("--json", type=Path, help="also write the JSON report to this file")
    p.add_argument("--plot", type=Path, help="write the curves as a figure (.png, .svg or .pdf)")
    p.add_argument(
        "--force", action="store_true", help="let --json or --plot replace an existing file of another kind"
    )
    p.set_defaults(func=_run)
