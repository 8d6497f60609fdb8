"""The narrow collaborators a behaviour receives (structural types: anything with these methods will do).

A behaviour gets only the ones it uses, in its constructor: the robot (`scone_bt.robot.Robot`), the human
channel, the event sink (`scone_bt.events.EventSink`), κ̂, the outcome recorder, the attempt history and the
planner seeds. Tests pass fakes; the episode passes the real ones (`EpisodeContext`).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Protocol, TypeVar, runtime_checkable

import numpy as np

from scone_bt.experience.types import ExecutionContext, Outcome
from scone_bt.gate.budget import FeltCarry
from scone_bt.perception.types import Detection, Frame

__all__ = [
    "Clock",
    "Provider",
    "HumanChannel",
    "SelfConfidence",
    "OutcomeRecorder",
    "AttemptHistory",
    "PlannerSeeds",
    "ContextSource",
]

T = TypeVar("T")

Clock = Callable[[], float]
"""Seconds since the episode started (the robot's clock)."""

Provider = Callable[[], T]
"""Builds (or returns the already built) heavy collaborator; behaviours call it in `setup()`, not `__init__`."""


@runtime_checkable
class HumanChannel(Protocol):
    """What the robot can ask of and learn from the human cook (the simulated one, or the tablet)."""

    @property
    def done(self) -> bool:
        """Every recipe step is done."""
        ...

    @property
    def step_index(self) -> int:
        """The human's current step, 0-based (read only by the recipe-blind paper setting)."""
        ...

    @property
    def current_instruction(self) -> str | None:
        """The human's current step's text, None when done (recipe-blind setting only)."""
        ...

    @property
    def clarify_time_s(self) -> float:
        """How long answering "which one?" takes, seconds."""
        ...

    def steps_completed(self) -> int: ...

    def is_fetching(self, object_name: str) -> bool: ...

    def help_pending(self, object_name: str) -> bool: ...

    def request_help(self, object_name: str) -> None: ...

    def declined(self, object_name: str) -> bool:
        """The human declined a help request for this object ("try it yourself")."""
        ...

    def answer_clarification(self, candidates: tuple[str, ...]) -> tuple[str, ...]: ...

    def decide_takeover(self, object_name: str) -> None: ...

    def wants_takeover(self, object_name: str) -> bool: ...

    def take_over(self, object_name: str) -> None: ...

    def robot_busy(self, busy: bool) -> None: ...


@runtime_checkable
class SelfConfidence(Protocol):
    """κ̂: success probabilities of action embeddings, updated with each labelled outcome.

    A grounded κ̂ (a ``grounded = True`` attribute) takes each embedding followed by its execution context
    (`scone_bt.confidence.grounded_features`). The gate also reads, where κ̂ has them (every
    `scone_bt.confidence.base.ConfidenceEstimator` does; read with ``getattr``, so a minimal κ̂ needs only these
    two methods): ``belief(x)`` (the probability without an ε-greedy draw), ``explores(x)`` (which rows an
    ε-greedy κ̂ tries to learn) and ``n_observations`` (outcomes learnt so far).
    """

    def predict(self, x: np.ndarray) -> np.ndarray: ...

    def update(self, x: np.ndarray, success: bool) -> None: ...


@runtime_checkable
class ContextSource(Protocol):
    """Builds the ExecutionContext of candidate targets from one tick's perception
    (`scone_bt.perception.context.execution_contexts` with the kitchen's scene and catalogue)."""

    def __call__(
        self, targets: Sequence[Detection], detections: Sequence[Detection], frames: Mapping[str, Frame]
    ) -> Mapping[str, ExecutionContext]: ...


@runtime_checkable
class OutcomeRecorder(Protocol):
    """The durable experience store: `append` commits before it returns."""

    def append(self, outcome: Outcome) -> object: ...


@runtime_checkable
class AttemptHistory(Protocol):
    """What the episode's events say about past attempts (folded from the event stream)."""

    def failures_of(self, action: str) -> int: ...

    def budget_counts(self) -> tuple[int, int, int]:
        """(labelled attempts, exploratory ones included; their failures; failed explorations) so far."""
        ...

    def held_fast_carries(self) -> tuple[FeltCarry, ...]:
        """The attempts after a heft test that felt the product held fast so far, with the load each felt: ()
        without probes."""
        ...

    def probe_reason(self, action: str) -> str | None:
        """Why a heft test set this action's product back in this episode, or None if none did."""
        ...


@runtime_checkable
class PlannerSeeds(Protocol):
    """The planner seed of each pick-and-place attempt, in order."""

    def next_seed(self) -> int: ...
