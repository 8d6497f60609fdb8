"""Plan before commit (issue 26): a confident decision is planned first; a plan the scene's geometry makes impossible
is asked about in words, stored as experience, and never planned again in an unchanged scene."""

from __future__ import annotations

import numpy as np
import py_trees

from scone_bt.behaviours import ConfidenceGate, GatePorts, GateSettings, Keys, PickAndPlace, RecordInfeasible
from scone_bt.behaviours.context import OutcomeLabels
from scone_bt.episode.seeds import PlannerSeedStream, SeedPlan
from scone_bt.events import DecisionMade, EventLog, PlanInfeasible
from scone_bt.gate import GateOptions
from scone_bt.gate.budget import BudgetOptions
from scone_bt.gate.rules import say_infeasible
from scone_bt.gate.types import DecisionKind
from scone_bt.relevance.types import RankedAction
from scone_bt.robot.interface import Infeasible
from tests.behaviours.fakes import FakeHuman, FakeRobot, affordance, blackboard, det

PARMESAN = "Put parmesan on table"
BUDGET = BudgetOptions()
BLOCKED = Infeasible(
    "grasps_blocked", "every grasp of parmesan collides with cooking cream", ("cooking cream",)
)


class _Kappa:
    n_observations = 100

    def predict(self, x: np.ndarray) -> np.ndarray:
        return np.full(len(x), 0.9)

    def update(self, x, success) -> None:
        pass


class _Store:
    def __init__(self) -> None:
        self.outcomes: list = []

    def append(self, outcome) -> None:
        self.outcomes.append(outcome)


def _gate(robot: FakeRobot, events: EventLog, budget: BudgetOptions | None = BUDGET) -> ConfidenceGate:
    gate = ConfidenceGate(
        "gate",
        GatePorts(
            kappa=lambda: _Kappa(),
            history=events,
            events=events,
            clock=robot.now,
            human=FakeHuman(),
            robot=robot if budget is not None else None,
            seeds=PlannerSeedStream(SeedPlan(0)),
        ),
        GateSettings(
            gate=GateOptions(confidence_threshold=0.5),
            max_failures_per_action=3,
            steps_total=4,
            budget=budget,
        ),
    )
    gate.setup()
    return gate


def _scene(cream_at: tuple[float, float, float] = (0.5, 0.36, 0.1)) -> py_trees.blackboard.Client:
    return blackboard(
        RANKED=[RankedAction(PARMESAN, 0.7)],
        ACTION_EMBEDDINGS={PARMESAN: np.array([1.0, 0.0], dtype=np.float32)},
        INSTRUCTION="Grate the parmesan.",
        AFFORDANCES=[affordance("parmesan")],
        DETECTIONS=[det("parmesan"), det("cooking cream", cream_at, 1)],
        TABLE_DETECTIONS=(),
    )


def test_an_infeasible_plan_is_asked_about_in_words_not_attempted() -> None:
    robot, events = FakeRobot(infeasible={"parmesan": BLOCKED}), EventLog()
    bb = _scene()
    _gate(robot, events).tick_once()
    decision = bb.get(Keys.DECISION)
    assert decision.kind is DecisionKind.ASK and decision.rule == "infeasible"
    assert decision.reason == "I cannot grasp the parmesan: the cooking cream is in the way"
    assert robot.requests == [] and len(robot.plans) == 1  # planned, never started
    assert bb.get(Keys.PLAN_VERDICT) == BLOCKED and bb.get(Keys.PLANNED) is None
    (event,) = [e for e in events.events if isinstance(e, DecisionMade)]
    assert event.rule == "infeasible" and event.planning_s is not None


def test_the_same_request_in_an_unchanged_scene_is_not_planned_again_but_a_changed_one_is() -> None:
    robot, events = FakeRobot(infeasible={"parmesan": BLOCKED}), EventLog()
    gate = _gate(robot, events)
    bb = _scene()
    gate.tick_once()
    gate.tick_once()  # the same scene: asked again at once, from memory
    assert len(robot.plans) == 1
    again = bb.get(Keys.DECISION)
    assert again.kind is DecisionKind.ASK and again.reason.endswith(
        "(known: not planned again in this scene)"
    )
    assert bb.get(Keys.PLAN_VERDICT) is None  # nothing new to store
    bb.set(
        Keys.DETECTIONS, [det("parmesan"), det("cooking cream", (0.5, 0.6, 0.1), 1)]
    )  # the cream was moved
    gate.tick_once()
    assert len(robot.plans) == 2


def test_a_feasible_plan_is_what_pick_and_place_executes() -> None:
    robot, events = FakeRobot(), EventLog()
    bb = _scene()
    _gate(robot, events).tick_once()
    assert bb.get(Keys.DECISION).kind is DecisionKind.ACT
    bb.set(Keys.TARGET, affordance("parmesan"))
    pick = PickAndPlace("pick", robot, FakeHuman(), events, PlannerSeedStream(SeedPlan(0)))
    pick.setup()
    pick.tick_once()
    assert robot.requests == [robot.plans[0]]  # the planned request, not a second plan with a new seed
    assert bb.get(Keys.PLANNED) is None


def test_the_paper_gate_does_not_plan_before_committing() -> None:
    robot, events = FakeRobot(infeasible={"parmesan": BLOCKED}), EventLog()
    bb = _scene()
    _gate(robot, events, budget=None).tick_once()
    assert bb.get(Keys.DECISION).kind is DecisionKind.ACT and robot.plans == []


def test_an_infeasible_plan_is_stored_as_experience_not_as_an_attempt() -> None:
    robot, events, store = FakeRobot(infeasible={"parmesan": BLOCKED}), EventLog(), _Store()
    bb = _scene()
    _gate(robot, events).tick_once()
    record = RecordInfeasible(
        "record", robot.now, lambda: store, events, OutcomeLabels("onehot", "r1", "panda")
    )
    record.setup()
    record.tick_once()
    (outcome,) = store.outcomes
    assert (outcome.success, outcome.failure_stage, outcome.object_name) == (False, "planning", "parmesan")
    assert outcome.context["infeasible"] == "grasps_blocked"
    assert bb.get(Keys.OUTCOME) is outcome  # κ̂ learns it next (UpdateSelfConfidence)
    assert any(isinstance(e, PlanInfeasible) for e in events.events)
    assert events.stats.attempted == 0 and events.stats.failures == 0  # the human saw no failure


def test_the_robots_words_name_the_blocker() -> None:
    assert (
        say_infeasible("jam", Infeasible("no_table_space", "")) == "there is no room on the table for the jam"
    )
    assert say_infeasible("jam", Infeasible("placements_blocked", "", ("pan",))) == (
        "I cannot put the jam down: the pan is in the way"
    )
