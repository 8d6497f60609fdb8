"""One observed outcome, as stored in the experience database."""

from __future__ import annotations

from dataclasses import dataclass, field

__all__ = ["Outcome"]


@dataclass(frozen=True)
class Outcome:
    """An action the robot attempted and what happened.

    Attributes:
        time: Unix time of the observation, seconds.
        action: Action text ("Put salt on table").
        object_name: Catalogue name of the object acted on.
        embedder: Name of the embedder κ̂ was trained with when this was observed.
        success: Whether the object ended upright on the table.
        failure_stage: FailureStage value on failure, else None.
        context: Free-form JSON-serialisable details (robot, profile, seed, episode, ...).
    """

    time: float
    action: str
    object_name: str
    embedder: str
    success: bool
    failure_stage: str | None = None
    context: dict = field(default_factory=dict)
