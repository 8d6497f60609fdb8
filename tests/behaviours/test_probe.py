"""The heft test in the tree (gate.probe, motion.probe): an action κ̂ is unsure of is probed before carrying; a
probe that sets the product back is stored as an aborted attempt (not a failure, not counted by the budget), and the
robot then asks for the product, saying why."""

from __future__ import annotations

import numpy as np
import py_trees
import pytest

from scone_bt.behaviours import ConfidenceGate, GatePorts, GateSettings, Keys, ObserveOutcome
from scone_bt.behaviours.context import OutcomeLabels
from scone_bt.episode.seeds import PlannerSeedStream, SeedPlan
from scone_bt.errors import SconeError
from scone_bt.events import DecisionMade, EventLog, ProbeAborted
from scone_bt.gate import GateOptions
from scone_bt.gate.budget import BudgetOptions, FeltCarry
from scone_bt.gate.probe import ProbeOptions, in_band
from scone_bt.gate.types import DecisionKind
from scone_bt.motion.probe import ProbeReading, ProbeSettings, judge_probe
from scone_bt.motion.types import MotionOutcome
from scone_bt.relevance.types import RankedAction
from tests.behaviours.fakes import FakeHuman, FakeRobot, affordance, blackboard, det

JAM = "Put strawberry jam on table"
LABELS = OutcomeLabels(embedder="onehot", robot_id="r1", arm="panda", context={"robot": "panda"})


class _Kappa:
    def __init__(self, confidence: float) -> None:
        self.confidence = confidence
        self.n_observations = 100  # not exploring: only the probe can make it act below τ
        self.learnt: list[bool] = []

    def predict(self, x: np.ndarray) -> np.ndarray:
        return np.full(len(x), self.confidence)

    def update(self, x, success) -> None:
        self.learnt.append(bool(success))


class _Store:
    def __init__(self) -> None:
        self.stored: list = []

    def append(self, outcome) -> None:
        self.stored.append(outcome)


def _gate(robot: FakeRobot, events: EventLog, kappa: _Kappa, probe: ProbeOptions | None) -> ConfidenceGate:
    gate = ConfidenceGate(
        "gate",
        GatePorts(
            kappa=lambda: kappa,
            history=events,
            events=events,
            clock=robot.now,
            human=FakeHuman(),
            robot=robot,
            seeds=PlannerSeedStream(SeedPlan(0)),
        ),
        GateSettings(
            gate=GateOptions(),
            max_failures_per_action=3,
            steps_total=4,
            budget=BudgetOptions(start_margin=3.0, explore_rate=0.0),  # τ₀ = 0.55 at the default 0.15
            probe=probe,
        ),
    )
    gate.setup()
    return gate


def _scene() -> py_trees.blackboard.Client:
    return blackboard(
        RANKED=[RankedAction(JAM, 0.7)],
        ACTION_EMBEDDINGS={JAM: np.array([1.0, 0.0], dtype=np.float32)},
        INSTRUCTION="Spread the strawberry jam.",
        AFFORDANCES=[affordance("strawberry jam")],
        DETECTIONS=[det("strawberry jam")],
        TABLE_DETECTIONS=(),
    )


def test_an_unsure_action_is_probed_then_set_back_and_asked_for_saying_why() -> None:
    robot, events, kappa = FakeRobot(time=3.0), EventLog(), _Kappa(0.45)
    bb = _scene()
    gate = _gate(robot, events, kappa, ProbeOptions(below=0.3, above=0.0))
    gate.tick_once()
    decision = bb.get(Keys.DECISION)
    # κ̂ 0.45 is below τ = 0.55 but inside the band: it acts, hefting first, instead of asking
    assert decision.kind is DecisionKind.ACT and decision.probe and not decision.explored
    assert "hefting the strawberry jam first" in decision.reason
    (request,) = robot.plans
    assert isinstance(request.probe, ProbeSettings) and request.probe.lift_m == 0.015
    assert isinstance(events.events[-1], DecisionMade) and events.events[-1].probe

    # The arm lifted it, felt it slip, and set it back where it stood: an aborted attempt.
    store = _Store()
    reading = ProbeReading(held=True, load_n=2.1, load_first_n=2.9, grip_n=16.0, seconds=2.4)
    motion = MotionOutcome(
        False,
        None,
        "set back after the probe: the strawberry jam slips in my fingers",
        7.5,
        aborted=True,
        probe=reading,
        probe_reason="the strawberry jam slips in my fingers",
    )
    bb.set(Keys.MOTION_OUTCOME, motion)
    observe = ObserveOutcome("observe", robot, lambda: store, events, LABELS)
    observe.setup()
    observe.tick_once()
    aborted = events.events[-1]
    assert isinstance(aborted, ProbeAborted)
    assert (aborted.reason, aborted.probe_s, aborted.load_n) == (
        "the strawberry jam slips in my fingers",
        2.4,
        2.1,
    )
    (stored,) = store.stored
    assert not stored.success and stored.failure_stage == "probe"  # κ̂ learns it could not carry it
    # neither a success nor a failure for the promise; counted apart
    assert events.budget_counts() == (0, 0, 0) and events.stats.aborted == 1

    # The next decision about it asks, in the probe's words, and does not probe again.
    gate.tick_once()
    asked = bb.get(Keys.DECISION)
    assert asked.kind is DecisionKind.ASK and asked.rule == "probe" and not asked.probe
    assert asked.reason == "the strawberry jam slips in my fingers: please bring it"
    assert len(robot.plans) == 1


def test_a_probe_whose_fingers_closed_on_nothing_and_left_it_standing_is_aborted_and_asked_for() -> None:
    """The issue's rule: a probe that ends with the product back in its place is an aborted attempt, even where the
    fingers never held it up (no reading): κ̂ learns it could not take it, the budget counts no failure."""
    robot, events, kappa = FakeRobot(time=3.0), EventLog(), _Kappa(0.45)
    bb = _scene()
    gate = _gate(robot, events, kappa, ProbeOptions(below=0.3, above=0.0))
    gate.tick_once()
    reason = "the strawberry jam is not in my fingers when they close"
    motion = MotionOutcome(
        False,
        None,
        f"the fingers closed without holding the object; it stands where it stood: {reason}",
        5.0,
        aborted=True,
        probe_reason=reason,
    )
    bb.set(Keys.MOTION_OUTCOME, motion)
    store = _Store()
    observe = ObserveOutcome("observe", robot, lambda: store, events, LABELS)
    observe.setup()
    observe.tick_once()
    aborted = events.events[-1]
    assert isinstance(aborted, ProbeAborted)
    assert (aborted.reason, aborted.probe_s, aborted.load_n) == (reason, 0.0, 0.0)
    (stored,) = store.stored
    assert not stored.success and stored.failure_stage == "probe"
    assert events.budget_counts() == (0, 0, 0) and events.stats.aborted == 1
    gate.tick_once()
    asked = bb.get(Keys.DECISION)
    assert asked.kind is DecisionKind.ASK and asked.rule == "probe"
    assert asked.reason == f"{reason}: please bring it"


@pytest.mark.parametrize(("confidence", "probed"), [(0.2, False), (0.31, True), (0.54, True), (0.6, False)])
def test_only_actions_inside_the_band_are_probed(confidence: float, probed: bool) -> None:
    robot, events = FakeRobot(time=3.0), EventLog()
    bb = _scene()
    _gate(robot, events, _Kappa(confidence), ProbeOptions(below=0.25, above=0.0)).tick_once()
    decision = bb.get(Keys.DECISION)
    assert decision.probe is probed
    assert decision.kind is (DecisionKind.ACT if confidence > 0.3 else DecisionKind.ASK)
    assert in_band(confidence, 0.55, ProbeOptions(below=0.25, above=0.0)) is probed


def test_without_the_probe_the_unsure_action_is_asked_about() -> None:
    robot, events = FakeRobot(time=3.0), EventLog()
    bb = _scene()
    _gate(robot, events, _Kappa(0.45), None).tick_once()
    assert bb.get(Keys.DECISION).kind is DecisionKind.ASK and not robot.plans


def test_the_judge_carries_a_steady_load_and_sets_back_a_sliding_one() -> None:
    settings = ProbeSettings()
    steady = ProbeReading(held=True, load_n=4.905, load_first_n=4.907, grip_n=80.0)
    assert judge_probe(steady, settings) == (True, "")
    assert judge_probe(ProbeReading(True, 2.2, 2.5, 16.0), settings) == (False, "slips in my fingers")
    assert judge_probe(ProbeReading(False, 0.0, 1.0, 0.0), settings) == (False, "slips out of my fingers")
    heavy = ProbeSettings(max_traction=0.2)
    assert judge_probe(ProbeReading(True, 4.4, 4.4, 16.0), heavy)[1].startswith("is too heavy for my grip")


@pytest.mark.parametrize(
    ("key", "value", "message"),
    [
        ("lift_m", 0.2, "probe.lift_m must be in [0.005, 0.05] (metres), got 0.2"),
        ("hold_s", 0.0, "probe.hold_s must be in [0.1, 3] (seconds), got 0.0"),
        ("below", 1.5, "probe.below must be in [0, 1], got 1.5"),
        ("above", "x", "probe.above must be a number, got 'x'"),
    ],
)
def test_bad_probe_settings_are_refused_in_one_line(key: str, value: object, message: str) -> None:
    with pytest.raises(SconeError) as err:
        ProbeOptions(**{key: value})  # type: ignore[arg-type]
    assert str(err.value) == message


def test_bad_probe_settings_in_the_tree_file_name_key_and_range() -> None:
    import pydantic

    from scone_bt.config.schema import format_validation_error
    from scone_bt.config.tree_parameters import TreeParameters

    with pytest.raises(pydantic.ValidationError) as err:
        TreeParameters(probe={"lift_m": 0.2})
    line = format_validation_error(err.value, "parameters", TreeParameters)
    assert "\n" not in line and "probe.lift_m" in line and "0.05" in line


class _FeelingKappa:
    """A grounded κ̂ that is sure before the probe (0.6, τ₀ = 0.55) and unsure once it has felt the product."""

    grounded = True
    n_observations = 100

    def __init__(self) -> None:
        self.seen: list[np.ndarray] = []

    def predict(self, x: np.ndarray) -> np.ndarray:
        from scone_bt.experience.types import CONTEXT_FIELDS

        self.seen.extend(np.atleast_2d(x))
        felt = np.atleast_2d(x)[:, -len(CONTEXT_FIELDS) + CONTEXT_FIELDS.index("felt_traction")]
        return np.where(np.isfinite(felt), 0.3, 0.6)

    def update(self, x, success) -> None:
        pass


def _strict_gate(robot: FakeRobot, events: EventLog, kappa: object) -> ConfidenceGate:
    gate = _gate(robot, events, kappa, ProbeOptions(below=0.3, above=0.45))  # type: ignore[arg-type]
    budget = BudgetOptions(start_margin=3.0, explore_rate=0.0, excess_allowance=1.0)  # the strict promise
    from dataclasses import replace

    gate.settings = replace(gate.settings, budget=budget)
    return gate


HELD = ProbeReading(held=True, load_n=4.0, load_first_n=4.001, grip_n=20.0, seconds=0.9)
"""Held steady, but not fast: the load is 0.2 of the grip, above `ProbeOptions.sure_traction` (0.1)."""
HELD_FAST = ProbeReading(held=True, load_n=1.0, load_first_n=1.0002, grip_n=20.0, seconds=0.9)
"""Held fast: the load is 0.05 of the grip."""


def test_unsure_after_the_probe_and_without_credit_it_sets_back_and_asks() -> None:
    from scone_bt.events import ActOutcome

    robot, events, kappa = FakeRobot(time=3.0), EventLog(), _FeelingKappa()
    events(ActOutcome(1.0, "Put honey on table", "honey", False, "grasp"))  # 1 failure in 1: no credit left
    bb = _scene()
    bb.set(Keys.CONTEXTS, {})
    gate = _strict_gate(robot, events, kappa)
    gate.tick_once()
    decision = bb.get(Keys.DECISION)
    assert decision.kind is DecisionKind.ACT and decision.probe  # 0.6 ≥ τ but inside the band above it
    (request,) = robot.plans
    carry, reason = request.judge(HELD)  # what the probe's controller calls after the hold
    assert (carry, reason) == (False, "I am not sure I can carry the strawberry jam")
    assert bb.get(Keys.PROBE_JUDGE).verdict.felt_unsafe is False

    store = _Store()
    bb.set(
        Keys.MOTION_OUTCOME,
        MotionOutcome(False, None, reason, 6.0, aborted=True, probe=HELD, probe_reason=reason),
    )
    observe = ObserveOutcome("observe", robot, lambda: store, events, LABELS)
    observe.setup()
    observe.tick_once()
    assert isinstance(events.events[-1], ProbeAborted) and store.stored == []  # κ̂'s doubt teaches nothing
    assert bb.get(Keys.OUTCOME) is None
    gate.tick_once()
    asked = bb.get(Keys.DECISION)
    assert (asked.kind, asked.rule) == (DecisionKind.ASK, "probe")
    assert asked.reason == "I am not sure I can carry the strawberry jam: please bring it"


def test_unsure_after_the_probe_with_credit_it_carries_on_as_an_explored_attempt() -> None:
    robot, events, kappa = FakeRobot(time=3.0), EventLog(), _FeelingKappa()
    bb = _scene()
    gate = _strict_gate(robot, events, kappa)
    gate.tick_once()
    (request,) = robot.plans
    assert request.judge(HELD) == (True, "")
    assert bb.get(Keys.PROBE_JUDGE).verdict.explored

    store = _Store()
    robot.on_table = set()  # it fell on the way: a failure
    bb.set(Keys.MOTION_OUTCOME, MotionOutcome(False, None, "dropped", 9.0, probe=HELD))
    observe = ObserveOutcome("observe", robot, lambda: store, events, LABELS)
    observe.setup()
    observe.tick_once()
    (stored,) = store.stored
    # stored with the context it committed in: what the fingers felt included
    assert stored.execution.felt_held is True and stored.execution.felt_traction == pytest.approx(0.2)
    assert events.budget_counts() == (1, 1, 1)  # an explored failure


class _LearningFeel(_FeelingKappa):
    """_FeelingKappa that remembers what it learnt: (the context's felt traction, success)."""

    def __init__(self) -> None:
        super().__init__()
        self.learnt: list[tuple[float, bool]] = []

    def update(self, x, success) -> None:
        from scone_bt.experience.types import CONTEXT_FIELDS

        traction = np.asarray(x)[-len(CONTEXT_FIELDS) + CONTEXT_FIELDS.index("felt_traction")]
        self.learnt.append((float(traction), bool(success)))


SLIPS = ProbeReading(held=True, load_n=2.1, load_first_n=2.9, grip_n=16.0, seconds=2.4)


@pytest.mark.parametrize(
    ("spent", "reading", "on_table", "learnt", "counts", "explored"),
    [
        # sure of it before the probe (0.6 ≥ τ₀) and unsure after (0.3): with credit, an explored carry-on
        (False, HELD, True, [(0.2, True)], (1, 0, 0), True),
        (False, HELD, False, [(0.2, False)], (1, 1, 1), True),
        # the fingers felt it slip: set back, and κ̂ learns it could not carry it, from what it felt
        (False, SLIPS, False, [(0.13125, False)], (0, 0, 0), None),
        (True, SLIPS, False, [(0.13125, False)], (1, 1, 0), None),
        # no credit left and unsure after feeling it: set back on κ̂'s doubt, which teaches κ̂ nothing
        (True, HELD, False, [], (1, 1, 0), None),
    ],
)
def test_what_kappa_learns_after_each_ending_of_a_probe(
    spent: bool, reading: ProbeReading, on_table: bool, learnt: list, counts: tuple, explored: bool | None
) -> None:
    """The judge after the probe, then ObserveOutcome and UpdateSelfConfidence as the tree runs them: κ̂ learns from
    the context after the probe (what the fingers felt), except where its own doubt set the product back."""
    from scone_bt.behaviours import UpdateSelfConfidence
    from scone_bt.events import ActOutcome

    robot, events, kappa = FakeRobot(time=3.0), EventLog(), _LearningFeel()
    if spent:  # 1 failure in 1: no credit left
        events(ActOutcome(1.0, "Put honey on table", "honey", False, "grasp"))
    bb = _scene()
    gate = _strict_gate(robot, events, kappa)
    gate.tick_once()
    (request,) = robot.plans
    carry, reason = request.judge(reading)
    robot.on_table = {"strawberry jam"} if on_table else set()
    motion = (
        MotionOutcome(True, None, "placed", 9.0, probe=reading)
        if carry and on_table
        else MotionOutcome(False, None, "dropped", 9.0, probe=reading)
        if carry
        else MotionOutcome(False, None, reason, 6.0, aborted=True, probe=reading, probe_reason=reason)
    )
    bb.set(Keys.MOTION_OUTCOME, motion)
    observe = ObserveOutcome("observe", robot, lambda: None, events, LABELS)
    update = UpdateSelfConfidence("update", lambda: kappa)
    for behaviour in (observe, update):
        behaviour.setup()
        behaviour.tick_once()
    assert kappa.learnt == [(pytest.approx(t), ok) for t, ok in learnt]
    assert events.budget_counts() == counts
    last = events.events[-1]
    if explored is None:
        assert isinstance(last, ProbeAborted) and last.reason == reason
    else:
        assert isinstance(last, ActOutcome) and last.explored is explored


def test_held_fast_without_credit_it_carries_on_by_feel_on_that_rule_s_own_record() -> None:
    """No credit left (1 failure in 1) and κ̂ unsure after the probe (0.3 < τ), but the fingers held the jam fast
    (load 0.05 of the grip): it carries on, confident by feel, and the attempt counts in the held-fast record
    (gate.after_probe's tests: a record without credit sets back)."""
    from scone_bt.events import ActOutcome

    robot, events, kappa = FakeRobot(time=3.0), EventLog(), _FeelingKappa()
    events(ActOutcome(1.0, "Put honey on table", "honey", False, "grasp"))  # no credit left
    bb = _scene()
    gate = _strict_gate(robot, events, kappa)
    gate.tick_once()
    (request,) = robot.plans
    assert request.judge(HELD) == (False, "I am not sure I can carry the strawberry jam")
    assert request.judge(HELD_FAST) == (True, "")
    verdict = bb.get(Keys.PROBE_JUDGE).verdict
    assert (verdict.by_feel, verdict.held_fast, verdict.confident, verdict.explored) == (
        True,
        True,
        True,
        False,
    )

    store = _Store()
    robot.on_table = set()  # it fell at the place: a failure, counted in the held-fast record
    bb.set(Keys.MOTION_OUTCOME, MotionOutcome(False, None, "dropped", 9.0, probe=HELD_FAST))
    observe = ObserveOutcome("observe", robot, lambda: store, events, LABELS)
    observe.setup()
    observe.tick_once()
    last = events.events[-1]
    assert isinstance(last, ActOutcome) and last.held_fast and not last.explored
    assert last.traction == HELD_FAST.lift_traction
    assert events.held_fast_carries() == (FeltCarry(HELD_FAST.lift_traction, False, by_feel=True),)
    assert events.budget_counts() == (2, 2, 0)
