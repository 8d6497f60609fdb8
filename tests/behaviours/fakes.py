"""Fakes of the behaviours' collaborators: a robot implementing `scone_bt.robot.Robot`, a human channel, a clock.

No simulator: the fake robot's detections and outcomes are whatever the test says.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import py_trees

from scone_bt.affordances.types import Affordance, action_text
from scone_bt.motion.types import FailureStage, MotionOutcome, MotionPhase, MotionProgress
from scone_bt.perception.observe import Observation
from scone_bt.perception.types import Detection
from scone_bt.robot.interface import PickRequest


def det(name: str, xyz: tuple[float, float, float] = (0.5, 0.3, 0.1), track: int = 0) -> Detection:
    return Detection(name, track, xyz, 0.0, 1.0, (0, 0, 1, 1))


def affordance(name: str) -> Affordance:
    return Affordance(name, action_text(name), det(name))


class FakeHandle:
    """A pick-and-place that plans for ``planning_ticks`` polls, then runs until the test finishes it."""

    def __init__(self, planning_ticks: int = 0) -> None:
        self.planning_ticks = planning_ticks
        self.cancelled = False
        self._outcome: MotionOutcome | None = None

    def progress(self) -> MotionProgress:
        if self._outcome is not None:
            return MotionProgress(MotionPhase.DONE, 1.0)
        if self.planning_ticks > 0:
            self.planning_ticks -= 1
            return MotionProgress(MotionPhase.PLANNING, 0.0)
        return MotionProgress(MotionPhase.TRANSIT, 0.5)

    def done(self) -> bool:
        return self._outcome is not None

    def outcome(self) -> MotionOutcome | None:
        return self._outcome

    def cancel(self) -> None:
        self.cancelled = True
        if self._outcome is None:
            self._outcome = MotionOutcome(False, FailureStage.CANCELLED, "cancelled", 1.0)

    def finish(self, success: bool, stage: FailureStage | None = None, message: str = "placed") -> None:
        self._outcome = MotionOutcome(success, stage, message, 9.0)


@dataclass
class FakePlanned:
    """A `PlannedPick` that is ready at once: feasible unless ``infeasible`` is set; execute starts the handle."""

    robot: FakeRobot
    request: PickRequest
    verdict: object = None

    def ready(self) -> bool:
        return True

    def infeasible(self):
        return self.verdict

    def execute(self) -> FakeHandle:
        return self.robot.start_pick_and_place(self.request)


@dataclass
class FakeRobot:
    """A `Robot` whose world is a list of detections and a set of objects on the table."""

    shelf: list[Detection] = field(default_factory=list)
    table: tuple[Detection, ...] = ()
    on_table: set[str] = field(default_factory=set)
    time: float = 0.0
    requests: list[PickRequest] = field(default_factory=list)
    handles: list[FakeHandle] = field(default_factory=list)
    planning_ticks: int = 0
    closed: bool = False
    plans: list[PickRequest] = field(default_factory=list)
    # object name → Infeasible: what plan_pick_and_place says of that object (absent: a plan exists)
    infeasible: dict = field(default_factory=dict)
    looks: list[int] = field(default_factory=list)  # each look's frames per camera (more: a longer look)

    def perceive(self, exposures: int = 1) -> Observation:
        self.looks.append(exposures)
        return Observation(None, {}, tuple(self.shelf), tuple(self.table))  # type: ignore[arg-type]

    def start_pick_and_place(self, request: PickRequest) -> FakeHandle:
        self.requests.append(request)
        self.handles.append(FakeHandle(self.planning_ticks))
        return self.handles[-1]

    def plan_pick_and_place(self, request: PickRequest) -> FakePlanned:
        self.plans.append(request)
        return FakePlanned(self, request, self.infeasible.get(request.target.name))

    def is_on_table(self, object_name: str) -> bool:
        return object_name in self.on_table

    def now(self) -> float:
        return self.time

    def home(self) -> None:
        pass

    def close(self) -> None:
        self.closed = True


@dataclass
class FakeHuman:
    """A `HumanChannel` that records what the robot asked and answers as the test sets it up."""

    wanted: tuple[str, ...] = ()
    takeover: str | None = None
    pending: set[str] = field(default_factory=set)
    fetching: set[str] = field(default_factory=set)
    busy: list[bool] = field(default_factory=list)
    asked: list[tuple[str, ...]] = field(default_factory=list)
    helped: list[str] = field(default_factory=list)
    taken: list[str] = field(default_factory=list)
    declines: set[str] = field(default_factory=set)
    clarify_time_s: float = 2.0
    step_index: int = 0
    done: bool = False
    current_instruction: str | None = None

    def steps_completed(self) -> int:
        return self.step_index

    def is_fetching(self, object_name: str) -> bool:
        return object_name in self.fetching

    def help_pending(self, object_name: str) -> bool:
        return object_name in self.pending

    def request_help(self, object_name: str) -> None:
        self.helped.append(object_name)
        self.pending.add(object_name)

    def declined(self, object_name: str) -> bool:
        return object_name in self.declines

    def answer_clarification(self, candidates: tuple[str, ...]) -> tuple[str, ...]:
        self.asked.append(candidates)
        return tuple(c for c in candidates if c in self.wanted)

    def decide_takeover(self, object_name: str) -> None:
        pass

    def wants_takeover(self, object_name: str) -> bool:
        return self.takeover == object_name

    def take_over(self, object_name: str) -> None:
        self.taken.append(object_name)
        self.takeover = None

    def robot_busy(self, busy: bool) -> None:
        self.busy.append(busy)


def blackboard(**values: object) -> py_trees.blackboard.Client:
    """A client that writes ``values`` (keyword: a `Keys` attribute name) and can read every key back."""
    from scone_bt.behaviours import Keys

    client = py_trees.blackboard.Client(name="test")
    for attr in vars(Keys):
        if attr.isupper():
            client.register_key(key=getattr(Keys, attr), access=py_trees.common.Access.WRITE)
    # what the tree's earlier stages write every tick, as they write it when they have nothing to say
    every_tick = {"STEP": None, "PLANNED": None, "TARGET_CONTEXT": None}
    for attr, value in {**every_tick, **values}.items():
        client.set(getattr(Keys, attr), value)
    return client


class FixedKappa:
    """κ̂ that says the same for every action, and remembers its updates."""

    def __init__(self, confidence: float = 0.9) -> None:
        self.confidence = confidence
        self.updates: list[bool] = []

    def predict(self, x):
        import numpy as np

        return np.full(len(x), self.confidence)

    def update(self, x, success: bool) -> None:
        self.updates.append(success)


def fake_context(
    tmp_path,
    robot: FakeRobot | None = None,
    human: FakeHuman | None = None,
    kappa: FixedKappa | None = None,
    recipe_steps: tuple[tuple[str, tuple[str, ...]], ...] = (("Add the salt.", ("salt",)),),
):
    """An `EpisodeContext` of fakes (onehot embedder, the real kitchen scene and catalogue files, no simulator)."""
    from types import SimpleNamespace

    from scone_bt.behaviours import BehaviourOptions, EpisodeContext, OutcomeLabels
    from scone_bt.config import load_kitchen
    from scone_bt.embedding import load_embedder
    from scone_bt.episode.seeds import PlannerSeedStream, SeedPlan
    from scone_bt.events import EventLog
    from scone_bt.stocking import StockedStep

    kitchen = load_kitchen()
    steps = tuple(StockedStep(text, objects) for text, objects in recipe_steps)
    needed = tuple(dict.fromkeys(o for _, objects in recipe_steps for o in objects))
    recipe = SimpleNamespace(steps=steps, needed=needed, unstocked=(), off_shelf=())
    events = EventLog()
    embedder = load_embedder("onehot", tmp_path)
    kappa = kappa or FixedKappa()
    return EpisodeContext(
        robot=robot or FakeRobot(),
        human=human or FakeHuman(),
        events=events,
        history=events,
        seeds=PlannerSeedStream(SeedPlan(0)),
        recipe=recipe,  # type: ignore[arg-type]
        scene=kitchen.scene,
        catalogue=kitchen.catalogue,
        # the paper's fixed threshold: these fakes pin the tree's wiring (the budget gate has tests of its own)
        options=BehaviourOptions(embedder="onehot", gate="paper").resolve(),
        labels=OutcomeLabels("onehot", "fake", "panda"),
        embedder=lambda: embedder,
        kappa=lambda: kappa,
        recorder=lambda: None,
    )
