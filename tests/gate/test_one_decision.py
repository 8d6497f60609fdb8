"""One gate decision: the tree's ConfidenceGate and ``scone-bench gate``'s replay, fed the same stream, decide the
same, because both call `scone_bt.gate.rules.gate_decision`."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import numpy as np
import pytest

from scone_bt.behaviours import (
    ConfidenceGate,
    GatePorts,
    GateSettings,
    Keys,
    ObserveOutcome,
    UpdateSelfConfidence,
)
from scone_bt.behaviours.context import OutcomeLabels
from scone_bt.benchmarks.replay import replay_stream
from scone_bt.benchmarks.replay_streams import missed_in_place, reading_of
from scone_bt.benchmarks.self_confidence.dataset import PROBE_READING_COLUMNS
from scone_bt.confidence import make_estimator
from scone_bt.events import EventLog, ProbeAborted
from scone_bt.experience.types import CONTEXT_FIELDS, FELT_FIELDS, ExecutionContext
from scone_bt.gate import GateOptions
from scone_bt.gate.after_probe import ProbeVerdict
from scone_bt.gate.budget import BudgetOptions
from scone_bt.gate.probe import ProbeOptions
from scone_bt.gate.rules import GateInput, GateRules, gate_decision
from scone_bt.gate.types import Decision, DecisionKind
from scone_bt.motion.probe import ProbeReading, ProbeSettings, judge_probe
from scone_bt.motion.types import FailureStage, MotionOutcome
from scone_bt.relevance.types import RankedAction
from tests.behaviours.fakes import FakeHuman, FakeRobot, affordance, blackboard

OPENING_M = 0.08
ALPHA = 0.1
SEED = 3
PROBE = ProbeOptions(below=0.5, above=0.2)
FULL_BAND = ProbeOptions(below=0.5, above=0.3, full_band_at=0.0)
"""A band that does not narrow at α = 0.1: more probes (some carried on confident, some explored on credit)."""
LABELS = OutcomeLabels(embedder="onehot", robot_id="r1", arm="panda", context={})


def _stream(n: int = 60, seed: int = 5) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[str]]:
    """Ten products (one embedding each) picked n times; the wide ones mostly fail."""
    rng = np.random.default_rng(seed)
    table = rng.normal(size=(10, 8)).astype(np.float32)
    widths = np.linspace(0.03, 0.12, 10)
    pick = rng.integers(0, 10, n)
    w = widths[pick]
    unfelt = np.full((n, len(FELT_FIELDS)), np.nan)  # nothing felt before a probe
    context = np.column_stack(
        [
            np.ones(n),
            np.full(n, 0.1),
            np.ones(n),
            np.ones(n),
            w,
            np.full(n, 0.1),
            w,
            np.full(n, 0.785),
            unfelt,
        ]
    )
    assert context.shape[1] == len(CONTEXT_FIELDS)
    success = (w < 0.075) ^ (rng.random(n) < 0.1)
    return table[pick], context, success, [f"product {i}" for i in pick]


def _readings(stream, seed: int = 7) -> np.ndarray:
    """What a recorded probe felt per execution (PROBE_READING_COLUMNS): the products that fail mostly slip in the
    fingers (their load changes during the hold, or it stays steady while the fingers rise past them: pressed), a few
    never were held up (NaN: failed before the probe; of those, the fingers closed beside some that stayed where
    they stood: in place)."""
    _, _, success, _ = stream
    rng = np.random.default_rng(seed)
    n = len(success)
    slips = ~success & (rng.random(n) < 0.7)
    # of the slips, these keep a steady load: only the sign tells (their own draws: the rest stays as it was)
    slides = slips & (np.random.default_rng(seed + 1).random(n) < 0.5)
    load = np.full(n, 2.0)
    first = np.where(slips & ~slides, 2.4, 2.0)
    drift = np.where(slips, 2.0, 0.1)
    rows = np.column_stack(
        [
            *(np.ones(n), load, first, np.full(n, 40.0), np.full(n, 1.2)),
            *(slides.astype(float), drift, np.where(slips, 1.5, 0.05), np.full(n, 2.0), np.full(n, 2.0)),
            np.full(n, np.nan),
        ]
    )
    missed = rng.random(n) < 0.05
    rows[missed] = np.nan
    rows[missed, 10] = np.arange(int(missed.sum())) == 0  # the first stood where it stood, the others did not
    assert rows.shape[1] == len(PROBE_READING_COLUMNS)
    return rows


class _Draws:
    """The same exploration draws for both paths, whenever each asks (a cycle of fixed numbers)."""

    def __init__(self) -> None:
        self.values = [0.3, 0.7, 0.1, 0.9, 0.4]
        self.i = 0

    def __call__(self) -> float:
        self.i += 1
        return self.values[self.i % len(self.values)]


class _ConstantDraw:
    def random(self) -> float:
        return 0.3  # below the explore rate: every draw explores (the timing of draws cannot matter)


def _replay(
    gate: str,
    stream,
    probe: ProbeOptions | None = None,
    readings=None,
    allowance: float | None = None,
    outcomes: list[int] | None = None,
) -> list[Decision]:
    vectors, context, success, products = stream
    trace: list[Decision] = []
    result = replay_stream(
        vectors,
        context,
        success,
        products,
        "physical",
        gate,
        ALPHA,
        SEED,
        0,
        OPENING_M,
        trace=trace,
        draw=_ConstantDraw().random,
        probe=probe,
        readings=readings,
        excess_allowance=allowance,
        budget=BudgetOptions(start_margin=3.0),  # the start these streams were written for: some explore
    )
    if outcomes is not None:
        outcomes.extend(result.trace)
    return trace


def _aborted(readings, t: int) -> bool:
    """Whether the probe of execution t set the product back (what the arm's ObserveOutcome would see)."""
    reading = reading_of(readings[t])
    if reading is None:
        return missed_in_place(readings[t])
    return not judge_probe(reading, ProbeSettings.of(PROBE))[0]


def _ending(judge, reading: ProbeReading | None, ok: bool, missed_in_place: bool = False) -> MotionOutcome:
    """How the arm's attempt ends: a probe's judge (`Keys.PROBE_JUDGE`, called with the reading as the probe
    controller calls it after the hold) carries on or sets back; a probe whose fingers closed on nothing beside a
    product that stayed where it stood is aborted (motion.probe); what carries on ends as the stream recorded."""
    if missed_in_place:
        reason = "the product is not in my fingers when they close"
        return MotionOutcome(False, None, reason, 1.0, aborted=True, probe_reason=reason)
    carry, reason = judge(reading) if reading is not None else (True, "")
    if not carry:
        return MotionOutcome(False, None, reason, 1.0, aborted=True, probe=reading, probe_reason=reason)
    return MotionOutcome(
        ok, None if ok else FailureStage.GRASP, "placed" if ok else "dropped", 1.0, probe=reading
    )


def _behaviour(
    gate_name: str,
    stream,
    probe: ProbeOptions | None = None,
    readings=None,
    allowance: float | None = None,
    outcomes: list[int] | None = None,
    verdicts: list[ProbeVerdict] | None = None,
) -> list[Decision]:
    """The tree's gate ticked on the same stream: one candidate per tick; an ACT ends as the stream recorded (after
    the probe's judge, when probed: its verdicts are appended to ``verdicts``), and ObserveOutcome and
    UpdateSelfConfidence label it, store nothing, fold it into the events and teach κ̂, as in the tree."""
    vectors, context, success, products = stream
    kappa = make_estimator("physical", seed=SEED, gripper_opening_m=OPENING_M)
    events = EventLog()
    robot = FakeRobot(time=1.0)
    now: dict[str, ExecutionContext] = {}
    budget = (
        BudgetOptions(start_margin=3.0, target_failure_rate=ALPHA, excess_allowance=allowance)
        if gate_name == "budget"
        else None
    )
    gate = ConfidenceGate(
        "gate",
        GatePorts(
            kappa=lambda: kappa,
            history=events,
            events=events,
            clock=robot.now,
            human=FakeHuman(),
            contexts=lambda detections, seen, frames: dict(now),
        ),
        GateSettings(
            gate=GateOptions(confidence_threshold=0.5, relevance_threshold=0.0),
            # the per-episode failure limit out of the way: a stream's executions are each from another episode
            max_failures_per_action=10_000,
            steps_total=1,
            budget=budget,
            seed=SEED,
            opening_m=OPENING_M if budget is not None else None,
            probe=probe,
        ),
    )
    # a set-back is not folded into the gate's history: the episode's memory of it asks next time (test_probe.py),
    # and a stream's executions are each from another episode
    observe = ObserveOutcome(
        "observe", robot, lambda: None, lambda e: None if isinstance(e, ProbeAborted) else events(e), LABELS
    )
    update = UpdateSelfConfidence("update", lambda: kappa)
    for behaviour in (gate, observe, update):
        behaviour.setup()
    gate._rng = _ConstantDraw()  # type: ignore[assignment]  # the replay's draws
    decisions = []
    for t, product in enumerate(products):
        aff = affordance(product)
        row = context[t]
        ctx = ExecutionContext(
            int(row[0]), float(row[1]), int(row[2]), bool(row[3]), *(float(v) for v in row[4:8])
        )
        now.clear()
        now[product] = ctx
        bb = blackboard(
            RANKED=[RankedAction(aff.text, 1.0)],
            ACTION_EMBEDDINGS={aff.text: vectors[t]},
            AFFORDANCES=[aff],
            INSTRUCTION="Fetch it.",
            DETECTIONS=[aff.detection],
            FRAMES={},
        )
        gate.tick_once()
        decision = bb.get(Keys.DECISION)
        decisions.append(decision)
        if decision.kind is not DecisionKind.ACT:
            if outcomes is not None:
                outcomes.append(-1)
            continue
        reading = reading_of(readings[t]) if decision.probe else None  # only a probe feels anything
        judge = bb.get(Keys.PROBE_JUDGE)
        missed = bool(decision.probe and missed_in_place(readings[t]))
        motion = _ending(judge, reading, bool(success[t]), missed)
        if verdicts is not None and judge is not None and judge.verdict is not None:
            verdicts.append(judge.verdict)
        robot.on_table = {product} if motion.success else set()
        bb.set(Keys.MOTION_OUTCOME, motion)
        for behaviour in (observe, update):
            behaviour.tick_once()
        if outcomes is not None:
            outcomes.append(-1 if motion.aborted else int(motion.success))
    return decisions


def _key(d: Decision) -> tuple[object, ...]:
    return (d.kind, d.explored, d.probe, d.rule, d.reason, round(d.confidence, 12), d.object_name)


@pytest.mark.parametrize(("gate", "allowance"), [("budget", None), ("budget", 1.0), ("paper", None)])
def test_the_tree_and_the_replay_decide_the_same_on_the_same_stream(
    gate: str, allowance: float | None
) -> None:
    """Allowance 1: the strict promise (exploration_credit) on in both."""
    stream = _stream()
    replayed = _replay(gate, stream, allowance=allowance)
    ticked = _behaviour(gate, stream, allowance=allowance)
    assert [_key(d) for d in ticked] == [_key(d) for d in replayed]
    kinds = {d.kind for d in replayed}
    assert {DecisionKind.ACT, DecisionKind.ASK} <= kinds  # both outcomes are exercised
    if gate == "budget":
        rules = {d.rule for d in replayed}
        assert "too-wide" in rules and any(d.explored for d in replayed)


@pytest.mark.parametrize("allowance", [None, 1.0])
def test_the_tree_and_the_replay_probe_the_same_on_a_stream_with_probe_readings(
    allowance: float | None,
) -> None:
    """The heft test is a step of the one decision (`probe_first`), and what follows it is one function
    (gate.after_probe: the tree's judge, the replay's): fed the same stream and the same probe readings, both
    probe the same executions, carry on and set back the same ones, and κ̂ learns the same (the context after the
    probe). Allowance 1: the strict promise, under which κ̂'s doubt after the probe can set a product back."""
    stream = _stream(n=100, seed=12)
    readings = _readings(stream)
    replay_outcomes: list[int] = []
    tree_outcomes: list[int] = []
    replayed = _replay("budget", stream, FULL_BAND, readings, allowance, outcomes=replay_outcomes)
    ticked = _behaviour("budget", stream, FULL_BAND, readings, allowance, outcomes=tree_outcomes)
    assert [_key(d) for d in ticked] == [_key(d) for d in replayed]
    assert tree_outcomes == replay_outcomes  # the same carried on (1/0) and set back or asked (-1)
    probed = [t for t, d in enumerate(replayed) if d.probe]
    assert probed and all(replayed[t].kind is DecisionKind.ACT for t in probed)
    assert any(_aborted(readings, t) for t in probed)  # some set back, some carried on
    assert not all(_aborted(readings, t) for t in probed)
    # some set back only because the fingers did not carry them up, and some missed but stood where they stood
    settings = ProbeSettings.of(PROBE)
    steady = [
        t
        for t in probed
        if (r := reading_of(readings[t])) is not None and r.unsteady <= settings.max_unsteady
    ]
    assert any(_aborted(readings, t) for t in steady)
    assert any(reading_of(readings[t]) is None and missed_in_place(readings[t]) for t in probed)
    assert any(reading_of(readings[t]) is None and not missed_in_place(readings[t]) for t in probed)
    assert all(not d.probe for d in replayed if d.rule == "too-wide")  # too wide: asked, never hefted
    assert "too-wide" in {d.rule for d in replayed}


def _agreeing_verdicts(
    grip_of: Callable[[np.ndarray], np.ndarray], band: ProbeOptions = FULL_BAND
) -> list[ProbeVerdict]:
    """The strict promise and the full band over seeded stream 9, every product held up with 2 N of load and the
    grip ``grip_of(success)``: the tree's verdicts after each probe, once the tree and the replay made the same
    decisions with the same outcomes."""
    stream = _stream(n=100, seed=9)
    _, _, success, _ = stream
    n = len(success)
    readings = np.column_stack(
        [np.ones(n), np.full(n, 2.0), np.full(n, 2.0), grip_of(success), np.full(n, 1.2)]
    )
    replay_outcomes: list[int] = []
    tree_outcomes: list[int] = []
    verdicts: list[ProbeVerdict] = []
    replayed = _replay("budget", stream, band, readings, 1.0, outcomes=replay_outcomes)
    ticked = _behaviour("budget", stream, band, readings, 1.0, outcomes=tree_outcomes, verdicts=verdicts)
    assert [_key(d) for d in ticked] == [_key(d) for d in replayed]
    assert tree_outcomes == replay_outcomes
    return verdicts


def test_the_tree_and_the_replay_agree_where_kappas_doubt_sets_back_and_credit_carries_on() -> None:
    """Products that fail hold in the fingers but strain them (7 N of grip for 2 N of load: traction 0.29, under
    the hard judge's 0.3), those that succeed are held well but not fast (15 N: 0.13, above sure_traction), so κ̂
    learns what high traction means: under the strict promise, with no credit left, a probe above τ can end below
    τ (set back on κ̂'s doubt, not learnt), and one with credit carries on explored."""
    verdicts = _agreeing_verdicts(lambda success: np.where(success, 15.0, 7.0))
    assert any(not v.carry and not v.felt_unsafe for v in verdicts)  # κ̂'s doubt set something back
    assert any(v.explored for v in verdicts) and any(v.confident for v in verdicts)
    assert not any(v.held_fast for v in verdicts)


def test_the_tree_and_the_replay_agree_where_a_product_held_fast_carries_on_by_feel() -> None:
    """The same stream, but every product is held fast, those that succeed at 40 N of grip for 2 N (0.05), those
    that fail at 25 N (0.08), so those that fail fall later, at the place: both keep the held-fast record alike,
    read it at each probe's load, carry on by feel while it has credit, and set back on κ̂'s doubt once it has
    none. Each allowance of the record (``feel_allowance``) reaches both alike: on this stream the record runs out
    with 1, not with the default 2."""
    for allowance, runs_out in ((1.0, True), (2.0, False)):
        band = replace(FULL_BAND, feel_allowance=allowance)
        verdicts = _agreeing_verdicts(lambda success: np.where(success, 40.0, 25.0), band)
        assert any(v.by_feel for v in verdicts)
        assert any(v.held_fast and not v.carry for v in verdicts) is runs_out


def test_the_probe_step_asks_about_what_a_probe_set_back_in_this_episode() -> None:
    budget = BudgetOptions(start_margin=3.0, target_failure_rate=0.2)
    band = ProbeOptions(below=0.3, above=0.0)  # κ̂ in [0.1, 0.4) against τ₀ = 0.4
    rules = GateRules(budget=budget, exploration=budget, opening_m=OPENING_M, probe=band)
    text = "Put jar on table"
    seen = GateInput(
        ranked=(RankedAction(text, 0.9),),
        confidences=(0.3,),  # τ₀ = 0.4: within the band below it
        objects={text: "jar"},
        widths_m={text: 0.05},
        draw=lambda: 0.99,  # no exploration draw
    )
    probed = gate_decision(rules, seen).decision
    assert (probed.kind, probed.probe, probed.explored) == (DecisionKind.ACT, True, False)
    assert probed.reason == "unsure (confidence 0.30, threshold 0.40): hefting the jar first"
    again = gate_decision(rules, GateInput(**{**seen.__dict__, "probe_reasons": {text: "the jar slips"}}))
    assert (again.decision.kind, again.decision.rule, again.decision.probe) == (
        DecisionKind.ASK,
        "probe",
        False,
    )
    assert again.decision.reason == "the jar slips: please bring it"
    sure = gate_decision(rules, GateInput(**{**seen.__dict__, "confidences": (0.05,)})).decision
    assert (sure.kind, sure.probe) == (DecisionKind.ASK, False)  # below the band: asked as before
    failed = gate_decision(rules, GateInput(**{**seen.__dict__, "failures": {text: 1}})).decision
    assert (failed.kind, failed.probe) == (DecisionKind.ASK, False)  # an action that failed is not probed


def test_steps_can_be_read_one_by_one() -> None:
    """The decision composes named steps: the budget's τ, its exploration, the too-wide rule."""
    budget = BudgetOptions(start_margin=3.0, target_failure_rate=0.2)
    rules = GateRules(budget=budget, exploration=budget, failure_limit=2, opening_m=OPENING_M)
    ranked = (RankedAction("Put pot on table", 0.9),)
    seen = GateInput(
        ranked=ranked,
        confidences=(0.3,),
        objects={"Put pot on table": "pot"},
        widths_m={"Put pot on table": 0.2},
        draw=lambda: 0.0,
    )
    result = gate_decision(rules, seen)
    assert result.threshold == pytest.approx(0.4) and result.exploring
    assert result.decision.kind is DecisionKind.ASK and result.decision.rule == "too-wide"
    assert not result.decision.explored
    narrow = gate_decision(rules, GateInput(**{**seen.__dict__, "widths_m": {"Put pot on table": 0.05}}))
    assert narrow.decision.kind is DecisionKind.ACT and narrow.decision.explored
    failed = gate_decision(rules, GateInput(**{**seen.__dict__, "failures": {"Put pot on table": 1}}))
    assert failed.decision.kind is DecisionKind.ASK and not failed.decision.explored  # never re-explored
