"""One observed outcome, as stored in the experience database."""

from __future__ import annotations

import uuid
from dataclasses import dataclass, field

__all__ = ["Outcome", "new_outcome_id"]


def new_outcome_id() -> str:
    """A fresh idempotency key (random UUID, hex)."""
    return uuid.uuid4().hex


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
        context: Free-form JSON-serialisable details (seed, episode, recipe, ...).
        robot_id: Which robot of a fleet observed it ("" for outcomes stored before robots had ids).
        arm: The robot's arm model (robots/<arm>.yaml name, e.g. "panda").
        profile: The robot's proficiency profile or configuration label ("" if none).
        outcome_id: Idempotency key: storing the same outcome twice (a retry after a lost connection, a restarted
            robot replaying its last attempt) keeps one row. Not part of equality.
    """

    time: float
    action: str
    object_name: str
    embedder: str
    success: bool
    failure_stage: str | None = None
    context: dict = field(default_factory=dict)
    robot_id: str = ""
    arm: str = ""
    profile: str = ""
    outcome_id: str = field(default_factory=new_outcome_id, compare=False)
