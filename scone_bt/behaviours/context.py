"""What the tree builder wires the behaviours from: one `EpisodeContext` per episode.

Only `from_context` classmethods read it; each behaviour keeps the few collaborators it needs and nothing else.
Heavy parts (the embedder, κ̂, the store) are callables, built on first use by whoever owns them
(`scone_bt.episode.resources.EpisodeResources`), so a tree that does not use one never loads it.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from scone_bt.behaviours.options import BehaviourOptions
from scone_bt.behaviours.ports import (
    AttemptHistory,
    HumanChannel,
    OutcomeRecorder,
    PlannerSeeds,
    SelfConfidence,
)
from scone_bt.config import Catalogue, SceneSpec
from scone_bt.embedding.base import Embedder
from scone_bt.events import EventSink
from scone_bt.robot.interface import Robot
from scone_bt.stocking import StockedRecipe

__all__ = ["EpisodeContext", "OutcomeLabels"]


@dataclass(frozen=True)
class OutcomeLabels:
    """What each stored outcome is labelled with besides the attempt itself.

    Attributes:
        embedder: ζ's name (outcomes are re-embedded with it when κ̂ is rebuilt).
        robot_id: This robot's id in a fleet.
        arm: The arm model's name.
        profile: Configuration label ("" for none).
        context: Extra fields (robot, seed, recipe); the simulated time is added per outcome.
    """

    embedder: str
    robot_id: str
    arm: str
    profile: str = ""
    context: Mapping[str, Any] = field(default_factory=dict)


@dataclass(frozen=True)
class EpisodeContext:
    """Everything a tree's behaviours may be wired from (the builder's view, not a behaviour's).

    Attributes:
        robot: The robot (perception, pick-and-place, outcome sensor, clock).
        human: The human channel.
        events: The event sink every behaviour emits to.
        history: Past attempts, folded from the events (the failure-limit rule).
        seeds: Planner seeds per attempt.
        recipe: The stocked recipe the robot knows.
        scene: The kitchen's static scene (where the shelf is).
        catalogue: Product models (the recipe items' wordings).
        options: The resolved decision settings.
        labels: Labels of stored outcomes.
        embedder: Builds (once) ζ.
        kappa: Builds (once) κ̂, rebuilt from the store.
        recorder: Opens (once) the experience store, or gives None.
        gripper_opening_m: How wide the arm's gripper opens, metres (None: unknown; the budget gate then never
            asks because a product is too wide).
        slide_pinch: The arm slides and pinches a flat pack on a lowest tier (its robot file's
            ``grasp.slide_pinch``): the budget gate lets κ̂ decide on such a pack.
        trust: The person's trust estimated online (`scone_bt.trust.estimate.OnlineTrust`), listening to
            the events; set with the tree parameter ``trust_aware``, else None.
    """

    robot: Robot
    human: HumanChannel
    events: EventSink
    history: AttemptHistory
    seeds: PlannerSeeds
    recipe: StockedRecipe
    scene: SceneSpec
    catalogue: Catalogue
    options: BehaviourOptions
    labels: OutcomeLabels
    embedder: Callable[[], Embedder]
    kappa: Callable[[], SelfConfidence]
    recorder: Callable[[], OutcomeRecorder | None]
    gripper_opening_m: float | None = None
    slide_pinch: bool = False
    trust: Any = None
