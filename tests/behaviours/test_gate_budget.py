"""ConfidenceGate with the failure budget, with fakes: the threshold rises with the failures folded from the
events, the budget explores only while κ̂ is cold (seeded, marked ``explored``), and a step's item the robot sees
nowhere is asked for once (rule "missing") and then waited for; AskForHelp asks the human for it."""

from __future__ import annotations

import numpy as np
import py_trees
import pytest

from scone_bt.behaviours import AskForHelp, ConfidenceGate, GatePorts, GateSettings, Keys
from scone_bt.events import ActOutcome, DecisionMade, EventLog, HelpRequested
from scone_bt.gate import GateOptions
from scone_bt.gate.budget import BudgetOptions
from scone_bt.gate.types import Decision, DecisionKind
from scone_bt.relevance.recipe_aware import StepSelection
from scone_bt.relevance.tracker import StepView
from tests.behaviours.fakes import FakeHuman, FakeRobot, affordance, blackboard

SALT = "Put salt on table"
SUGAR = "Put sugar on table"


class _Kappa:
    """κ̂ that says ``confidence`` for every action and has learnt ``n_observations`` outcomes."""

    def __init__(self, confidence: float, n_observations: int = 100) -> None:
        self.confidence = confidence
        self.n_observations = n_observations

    def predict(self, x: np.ndarray) -> np.ndarray:
        return np.full(len(x), self.confidence)

    def update(self, x, success) -> None:
        pass


def _gate(
    events: EventLog,
    kappa: _Kappa,
    budget: BudgetOptions | None,
    seed: int = 0,
    human: FakeHuman | None = None,
) -> ConfidenceGate:
    gate = ConfidenceGate(
        "gate",
        GatePorts(
            kappa=lambda: kappa,
            history=events,
            events=events,
            clock=FakeRobot(time=3.0).now,
            human=human or FakeHuman(),
        ),
        GateSettings(
            gate=GateOptions(confidence_threshold=0.6, relevance_threshold=0.3),
            # the paper's failure limit out of the way: only the budget may turn ACT into ASK here
            max_failures_per_action=99,
            steps_total=4,
            budget=budget,
            seed=seed,
        ),
    )
    gate.setup()
    return gate


def _salt_step() -> py_trees.blackboard.Client:
    return blackboard(
        RANKED=[_ranked(SALT)],
        ACTION_EMBEDDINGS={SALT: np.array([1.0, 0.0], dtype=np.float32)},
        INSTRUCTION="Add the salt.",
        AFFORDANCES=[affordance("salt")],
    )


def _ranked(text: str):
    from scone_bt.relevance.types import RankedAction

    return RankedAction(text, 0.7)


def _tick(gate: ConfidenceGate, bb: py_trees.blackboard.Client) -> Decision:
    gate.tick_once()
    return bb.get(Keys.DECISION)


@pytest.mark.parametrize("budgeted", [True, False])
def test_the_threshold_rises_after_failures_in_the_event_log(budgeted: bool) -> None:
    """τ₀ = 1 − 3 · 0.2 = 0.4; each failure adds 0.1 · 0.8, so κ̂'s 0.65 is enough for ACT until the fourth
    failure (τ = 0.72). The paper's gate (no budget, fixed 0.6) keeps acting on the same events."""
    events = EventLog()
    budget = (
        BudgetOptions(start_margin=3.0, target_failure_rate=0.2, step=0.1, explore_rate=0.0)
        if budgeted
        else None
    )
    gate, bb = _gate(events, _Kappa(0.65), budget), _salt_step()
    kinds = []
    for _ in range(5):
        decision = _tick(gate, bb)
        kinds.append(decision.kind)
        if decision.kind is DecisionKind.ACT:
            events(ActOutcome(3.5, SUGAR, "sugar", False, "grasp"))  # another action's failure counts too
    if budgeted:
        assert events.budget_counts() == (4, 4, 0)
        assert kinds == [DecisionKind.ACT] * 4 + [DecisionKind.ASK]
        assert decision.reason == "asking for help: confidence 0.65 < 0.72" and decision.rule == ""
    else:
        assert kinds == [DecisionKind.ACT] * 5


def test_successes_lower_the_threshold_again() -> None:
    events = EventLog()
    for ok in (False, False):
        events(ActOutcome(1.0, SUGAR, "sugar", ok, None if ok else "grasp"))
    budget = BudgetOptions(start_margin=3.0, target_failure_rate=0.2, step=0.1, explore_rate=0.0)
    gate, bb = _gate(events, _Kappa(0.5), budget), _salt_step()
    assert _tick(gate, bb).kind is DecisionKind.ASK  # τ = 0.4 + 0.1 · (2 − 0.2 · 2) = 0.56
    for _ in range(4):
        events(ActOutcome(1.0, SUGAR, "sugar", True, None))
    assert _tick(gate, bb).kind is DecisionKind.ACT  # τ = 0.56 − 4 · 0.02 = 0.48


@pytest.mark.parametrize(
    ("learnt", "kind", "explored"), [(4, DecisionKind.ACT, True), (5, DecisionKind.ASK, False)]
)
def test_the_budget_explores_only_while_kappa_has_learnt_fewer_than_explore_until(
    learnt, kind, explored
) -> None:
    events = EventLog()
    budget = BudgetOptions(start_margin=3.0, explore_rate=1.0, explore_until=5)
    gate, bb = _gate(events, _Kappa(0.3, n_observations=learnt), budget), _salt_step()
    decision = _tick(gate, bb)
    assert (decision.kind, decision.explored, decision.confidence) == (kind, explored, 0.3)
    (event,) = events.events
    assert isinstance(event, DecisionMade) and event.explored is explored


def test_an_action_that_already_failed_is_never_explored_again() -> None:
    events = EventLog()
    events(ActOutcome(1.0, SALT, "salt", False, "grasp"))
    budget = BudgetOptions(start_margin=3.0, explore_rate=1.0, explore_until=5)
    gate, bb = _gate(events, _Kappa(0.3, n_observations=1), budget), _salt_step()
    decision = _tick(gate, bb)
    assert (decision.kind, decision.explored) == (DecisionKind.ASK, False)


def test_the_budget_stops_exploring_after_explore_failures_and_they_count_against_it() -> None:
    events = EventLog()
    budget = BudgetOptions(start_margin=3.0, explore_rate=1.0, explore_until=100, explore_failures=1)
    gate, bb = _gate(events, _Kappa(0.3, n_observations=0), budget), _salt_step()
    first = _tick(gate, bb)
    assert first.kind is DecisionKind.ACT and first.explored
    events(ActOutcome(3.5, SALT, "salt", False, "grasp"))  # the exploratory attempt failed
    assert events.budget_counts() == (1, 1, 1)
    second = _tick(gate, bb)
    assert second.kind is DecisionKind.ASK and not second.explored
    # τ₀ = 0.55 of the default 0.15, raised by 0.05 · 0.85 for the exploratory failure
    assert second.reason == "asking for help: confidence 0.30 < 0.59"


def test_a_strict_promise_is_kept_from_the_first_attempt() -> None:
    """The tomato pasta with a weak gripper at α = 0.05: after one failed exploration (spaghetti) the robot asks
    about the crushed tomatoes instead of exploring again (2 failures in 2 attempts would break F ≤ α · A + 1)."""
    events = EventLog()
    budget = BudgetOptions(
        start_margin=3.0, target_failure_rate=0.05, explore_rate=1.0, explore_until=100, excess_allowance=1.0
    )
    gate, bb = _gate(events, _Kappa(0.3, n_observations=0), budget), _salt_step()
    assert _tick(gate, bb).explored
    events(ActOutcome(3.5, SUGAR, "sugar", False, "grasp"))  # another product's exploration failed
    second = _tick(gate, bb)
    assert (second.kind, second.explored) == (DecisionKind.ASK, False)


def test_the_gate_without_a_budget_never_explores_on_its_own() -> None:
    gate, bb = _gate(EventLog(), _Kappa(0.3, n_observations=0), None), _salt_step()
    assert _tick(gate, bb).kind is DecisionKind.ASK


def test_exploration_draws_are_seeded_and_at_the_stated_rate() -> None:
    budget = BudgetOptions(start_margin=3.0, explore_rate=0.5, explore_until=100)

    def explored(seed: int) -> list[bool]:
        gate, bb = _gate(EventLog(), _Kappa(0.3, n_observations=0), budget, seed=seed), _salt_step()
        return [_tick(gate, bb).explored for _ in range(40)]

    first = explored(7)
    assert explored(7) == first
    assert 8 <= sum(first) <= 32  # about half, neither always nor never
    assert explored(8) != first


def _missing_step(*missing: str) -> py_trees.blackboard.Client:
    instruction = "Boil the spaghetti with basil."
    selection = StepSelection(
        now=(), later=(), ambiguous=(), named=missing, done=False, reason="nothing in sight"
    )
    return blackboard(
        RANKED=[],
        ACTION_EMBEDDINGS={},
        INSTRUCTION=instruction,
        AFFORDANCES=[],
        STEP=StepView(0, instruction, selection, missing=missing),
    )


def test_a_missing_item_is_asked_for_once_then_waited_for() -> None:
    events, human = EventLog(), FakeHuman()
    bb = _missing_step("spaghetti")
    gate = _gate(events, _Kappa(0.9), BudgetOptions(start_margin=3.0), human=human)
    look = _tick(gate, bb)  # first a longer look (averaged frames), then the ask
    assert (look.kind, look.rule) == (DecisionKind.IDLE, "missing")
    assert look.reason == "waiting: spaghetti not in sight (looking again)"
    assert bb.get(Keys.LOOK_AGAIN) == ("spaghetti",) and human.helped == []
    events.events.clear()
    ask = _tick(gate, bb)
    assert bb.get(Keys.LOOK_AGAIN) == ()  # looked again once: not again
    assert (ask.kind, ask.rule, ask.object_name, ask.action) == (
        DecisionKind.ASK,
        "missing",
        "spaghetti",
        "Put spaghetti on table",
    )
    assert "spaghetti" in ask.reason and bb.get(Keys.TARGET) is None
    (event,) = events.events
    assert isinstance(event, DecisionMade) and event.rule == "missing" and event.object_name == "spaghetti"

    helper = AskForHelp("ask", human, events, FakeRobot(time=4.0).now)
    helper.tick_once()
    assert helper.status is py_trees.common.Status.RUNNING and human.helped == ["spaghetti"]
    assert events.events[-1] == HelpRequested(4.0, "Put spaghetti on table", "spaghetti")

    wait = _tick(gate, bb)
    assert wait.kind is DecisionKind.IDLE and wait.reason.endswith("(asked for)")
    assert wait.reason == "waiting: spaghetti not in sight (asked for)"
    assert human.helped == ["spaghetti"]  # asked once


@pytest.mark.parametrize("budgeted", [True, False])
def test_waiting_for_a_missing_item_carries_no_other_products_numbers(budgeted: bool) -> None:
    """The idle decision the wait replaces was about another product (the parmesan, needed later, declined): the
    waiting line must not show its relevance, κ̂, need or rule as if they were the spaghetti's."""
    import math

    from scone_bt.behaviours.gate import _Pending

    events = EventLog()
    bb = _missing_step("spaghetti")
    gate = _gate(events, _Kappa(0.9), BudgetOptions(start_margin=3.0) if budgeted else None)
    gate._looked_again.add("spaghetti")  # looked for again and
    gate._asked_missing.add("spaghetti")  # asked for already: now it is waited for
    parmesan = Decision(
        DecisionKind.IDLE, "Put parmesan on table", 0.12, 0.33, "declined: waiting", "later", rule="declined"
    )
    gate._finish(_Pending(parmesan, None, {}, 1), parmesan)
    wait = bb.get(Keys.DECISION)
    assert wait.kind is DecisionKind.IDLE and wait.action is None and wait.object_name is None
    assert math.isnan(wait.relevance) and math.isnan(wait.confidence) and wait.need == "now"
    assert wait.rule == ("missing" if budgeted else "")
    assert wait.reason == "waiting: spaghetti not in sight" + (" (asked for)" if budgeted else "")
    (event,) = events.events
    assert isinstance(event, DecisionMade) and event.action is None and event.need == "now"


def test_each_missing_item_is_asked_for_in_turn() -> None:
    bb = _missing_step("spaghetti", "basil")
    gate = _gate(EventLog(), _Kappa(0.9), BudgetOptions(start_margin=3.0))
    decisions = [_tick(gate, bb) for _ in range(4)]
    assert decisions[0].reason == "waiting: spaghetti, basil not in sight (looking again)"
    assert [(d.kind, d.object_name) for d in decisions] == [
        (DecisionKind.IDLE, None),
        (DecisionKind.ASK, "spaghetti"),
        (DecisionKind.ASK, "basil"),
        (DecisionKind.IDLE, None),
    ]
    assert decisions[-1].reason == "waiting: spaghetti, basil not in sight (asked for)"


def test_nothing_missing_stays_idle() -> None:
    bb = _missing_step()
    decision = _tick(_gate(EventLog(), _Kappa(0.9), BudgetOptions(start_margin=3.0)), bb)
    assert (
        decision.kind is DecisionKind.IDLE
        and decision.rule == ""
        and decision.reason == "no actions are available"
    )


def _declining_gate(limit: int = 99) -> tuple[ConfidenceGate, EventLog]:
    events = EventLog()
    human = FakeHuman(declines={"salt"})
    gate = ConfidenceGate(
        "gate",
        GatePorts(
            kappa=lambda: _Kappa(0.3),
            history=events,
            events=events,
            clock=FakeRobot(time=3.0).now,
            human=human,
        ),
        GateSettings(
            gate=GateOptions(confidence_threshold=0.6, relevance_threshold=0.3),
            max_failures_per_action=limit,
            steps_total=4,
            budget=BudgetOptions(start_margin=3.0, explore_rate=0.0),
        ),
    )
    gate.setup()
    return gate, events


def test_after_the_human_declined_the_robot_tries_itself_instead_of_asking_again() -> None:
    gate, _ = _declining_gate()
    decision = _tick(gate, _salt_step())
    assert (decision.kind, decision.rule) == (DecisionKind.ACT, "declined")
    assert decision.reason == "the human declined to fetch the salt: trying it myself"


def test_after_the_human_declined_an_item_that_failed_too_often_is_waited_for() -> None:
    gate, events = _declining_gate(limit=2)
    for _ in range(2):
        events(ActOutcome(1.0, SALT, "salt", False, "grasp"))
    decision = _tick(gate, _salt_step())
    assert (decision.kind, decision.rule) == (DecisionKind.IDLE, "declined")
    assert "failed 2 times: waiting" in decision.reason


def test_an_undeclined_item_is_still_asked_for() -> None:
    gate, _ = _declining_gate()
    gate.ports.human.declines.clear()  # type: ignore[attr-defined]
    assert _tick(gate, _salt_step()).kind is DecisionKind.ASK


def _wide_gate(
    opening_m: float | None, slide_pinch: bool = False, tier: int | None = None, height: float | None = None
) -> ConfidenceGate:
    from scone_bt.experience.types import ExecutionContext

    events = EventLog()
    budget = BudgetOptions(
        start_margin=3.0, explore_rate=1.0, explore_until=100
    )  # it would explore: the width still wins
    gate = ConfidenceGate(
        "gate",
        GatePorts(
            kappa=lambda: _Kappa(0.9, n_observations=0),
            history=events,
            events=events,
            clock=FakeRobot(time=3.0).now,
            human=FakeHuman(),
            contexts=lambda targets, seen, frames: {
                t.name: ExecutionContext(
                    shelf_tier=tier, detected=True, detected_width_m=0.095, detected_height_m=height
                )
                for t in targets
            },
        ),
        GateSettings(
            gate=GateOptions(confidence_threshold=0.6, relevance_threshold=0.3),
            max_failures_per_action=99,
            steps_total=4,
            budget=budget,
            opening_m=opening_m,
            slide_pinch=slide_pinch,
        ),
    )
    gate.setup()
    return gate


def test_a_product_measured_wider_than_the_gripper_is_asked_about_not_attempted() -> None:
    decision = _tick(_wide_gate(0.08), _salt_step())
    assert (decision.kind, decision.rule, decision.explored) == (DecisionKind.ASK, "too-wide", False)
    assert decision.reason == "the salt measures 9.5 cm across and my gripper opens 8.0 cm: please fetch it"
    assert _tick(_wide_gate(0.10), _salt_step()).kind is DecisionKind.ACT  # a wider gripper takes it
    assert _tick(_wide_gate(None), _salt_step()).kind is DecisionKind.ACT  # the paper's gate: no such rule


def test_an_arm_that_slides_flat_packs_leaves_one_on_a_lowest_tier_to_kappa() -> None:
    flat_low = _tick(_wide_gate(0.08, slide_pinch=True, tier=0, height=0.04), _salt_step())
    assert flat_low.kind is DecisionKind.ACT and flat_low.rule != "too-wide"
    # the same arm asks for it on a higher tier, or for a tall one; an arm without the skill asks for it anywhere
    for gate in (
        _wide_gate(0.08, slide_pinch=True, tier=1, height=0.04),
        _wide_gate(0.08, slide_pinch=True, tier=0, height=0.12),
        _wide_gate(0.08, slide_pinch=False, tier=0, height=0.04),
    ):
        assert _tick(gate, _salt_step()).rule == "too-wide"
