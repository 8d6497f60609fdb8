"""RankByRelevance, ConfidenceGate and AskToClarify ticked with fakes (no simulator): the robot's own step,
never-used items, items needed later, and the clarification round trip."""

from __future__ import annotations

import numpy as np
import py_trees

from scone_bt.affordances.types import Affordance, action_text
from scone_bt.behaviours import (
    AskToClarify,
    BehaviourOptions,
    ConfidenceGate,
    GatePorts,
    GateSettings,
    Keys,
    RankByRelevance,
)
from scone_bt.embedding import load_embedder
from scone_bt.events import ClarificationAsked, DecisionMade, EventLog
from scone_bt.gate.types import DecisionKind
from scone_bt.perception.types import Detection
from tests.behaviours.fakes import FakeHuman, FakeRobot


class _Confident:
    def predict(self, x: np.ndarray) -> np.ndarray:
        return np.full(len(x), 0.9)

    def update(self, x, success) -> None:
        pass


class _Episode:
    """The collaborators of one test: a recipe, a fake robot and human, an event log."""

    def __init__(self, tmp_path, steps, needed, human=None, aliases=None) -> None:
        aliases = aliases or {}
        self.steps = tuple(steps)
        self.needed = tuple(needed)
        self.aliases = aliases
        self.options = BehaviourOptions(relevance_threshold=0.5).resolve()
        self.human = human or FakeHuman()
        self.robot = FakeRobot()
        self.events = EventLog()
        self.embedder = load_embedder("onehot", tmp_path)

    def rank(self) -> RankByRelevance:
        from scone_bt.relevance.recipe_aware import SelectionOptions

        wordings = {n: tuple(self.aliases.get(n, ())) for n in self.needed}
        selection = SelectionOptions(rho=self.options.relevance_threshold, margin=self.options.clarify_margin)
        return RankByRelevance(
            "rank", lambda: self.embedder, self.steps, wordings, selection, True, self.human
        )

    def gate(self) -> ConfidenceGate:
        from scone_bt.gate import GateOptions

        gate = GateOptions(confidence_threshold=0.5, relevance_threshold=0.5, recipe_aware=True)
        return ConfidenceGate(
            "gate",
            GatePorts(
                kappa=_Confident,
                history=self.events,
                events=self.events,
                clock=self.robot.now,
                human=self.human,
            ),
            GateSettings(
                gate=gate,
                max_failures_per_action=3,
                steps_total=len(self.steps),
            ),
        )


def _shelf(*names: str) -> list[Affordance]:
    return [
        Affordance(n, action_text(n), Detection(n, i, (0.5, 0.3, 0.1), 0.0, 1.0, (0, 0, 1, 1)))
        for i, n in enumerate(names)
    ]


def _tick(services, shelf, table=()):
    writer = py_trees.blackboard.Client(name="test")
    for key in (Keys.AFFORDANCES, Keys.TABLE_DETECTIONS):
        writer.register_key(key=key, access=py_trees.common.Access.WRITE)
    writer.set(Keys.AFFORDANCES, shelf)
    writer.set(
        Keys.TABLE_DETECTIONS,
        tuple(Detection(n, -1, (0.4, -0.4, 0.1), 0.0, 1.0, (0, 0, 1, 1)) for n in table),
    )
    rank, gate = services.rank(), services.gate()
    rank.setup()
    gate.setup()
    rank.tick_once()
    gate.tick_once()
    reader = py_trees.blackboard.Client(name="reader")
    for key in (Keys.DECISION, Keys.STEP):
        reader.register_key(key=key, access=py_trees.common.Access.READ)
    return reader.get(Keys.DECISION), reader.get(Keys.STEP)


STEPS = ("Bring water to the boil.", "Cook the spaghetti.", "Fry the garlic in the oil.")


def test_a_never_used_item_is_not_fetched_and_the_step_is_the_robots_own(tmp_path) -> None:
    services = _Episode(tmp_path, STEPS, ["pasta", "garlic"], aliases={"pasta": ("spaghetti",)})
    decision, view = _tick(services, _shelf("honey", "pasta", "garlic"))
    # step 1 names nothing the robot can fetch: it moves to step 2 by itself
    assert view.index == 1 and view.skipped == ((0, "nothing to fetch"),)
    assert (decision.kind, decision.action, decision.need) == (DecisionKind.ACT, "Put pasta on table", "now")
    assert decision.object_name == "pasta"  # the decision carries its object: no text lookups downstream
    (event,) = services.events.events
    assert isinstance(event, DecisionMade) and (event.step, event.object_name) == (2, "pasta")


def test_a_completed_step_is_recognised_from_the_table_camera(tmp_path) -> None:
    services = _Episode(tmp_path, STEPS, ["pasta", "garlic"], aliases={"pasta": ("spaghetti",)})
    decision, view = _tick(services, _shelf("honey", "garlic"), table=("pasta",))
    assert view.index == 2 and (1, "completed") in view.skipped
    assert decision.action == "Put garlic on table"


def test_items_for_later_steps_are_fetched_only_when_the_step_has_nothing_left(tmp_path) -> None:
    services = _Episode(tmp_path, ("Cook the spaghetti.", "Add the garlic."), ["pasta", "garlic"])
    services.needed = ("spaghetti", "garlic")
    decision, view = _tick(services, _shelf("garlic"), table=())
    # spaghetti is named but not on the shelf (the human may be fetching it): garlic is fetched, marked later
    assert view.index == 0
    assert (decision.action, decision.need) == ("Put garlic on table", "later")


def test_ambiguous_step_asks_and_the_answer_is_used(tmp_path) -> None:
    human = FakeHuman(wanted=("sesame oil",))
    services = _Episode(tmp_path, ("Heat the oil in a wok.",), ["canola oil", "sesame oil"], human=human)
    decision, view = _tick(services, _shelf("canola oil", "sesame oil"))
    assert decision.kind is DecisionKind.CLARIFY
    assert set(decision.candidates) == {"Put canola oil on table", "Put sesame oil on table"}
    ask = AskToClarify("clarify", human, services.events, services.robot.now)
    ask.tick_once()
    assert ask.status is py_trees.common.Status.RUNNING  # the human takes a moment to answer
    services.robot.time = 2.5
    ask.tick_once()
    assert ask.status is py_trees.common.Status.SUCCESS
    assert services.events.stats.clarifications == 1 and human.asked
    asked = [e for e in services.events.events if isinstance(e, ClarificationAsked)]
    assert asked == [ClarificationAsked(0.0, ("canola oil", "sesame oil"), ("sesame oil",), 1)]
    decision, _ = _tick(services, _shelf("canola oil", "sesame oil"))
    assert (decision.kind, decision.action) == (DecisionKind.ACT, "Put sesame oil on table")


def test_items_no_step_names_are_gathered_at_the_first_step(tmp_path) -> None:
    services = _Episode(tmp_path, ("Cook the spaghetti.", "Serve."), ["pasta", "vanilla"])
    services.needed = ("spaghetti", "vanilla")
    decision, view = _tick(services, _shelf("vanilla"), table=("spaghetti",))
    assert view.index == 0 and view.selection.now == ("vanilla",)
    assert decision.need == "now"
