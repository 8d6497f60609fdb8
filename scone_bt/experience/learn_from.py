"""Whose stored outcomes rebuild a robot's κ̂: its own, those of robots of the same arm model, or the fleet's.

A robot's own and its model's outcomes are also those of its backend (``scone-run --robot``: PyBullet's "sim",
"mujoco"): the same arm fails at different things in another simulator, so a run on one engine does not learn
from the other's outcomes unless it asks for the fleet's. Each outcome names its backend in its context
(`BACKEND_KEY`); an outcome stored before backends were recorded names none and counts for every backend.
"""

from __future__ import annotations

from collections.abc import Callable
from enum import Enum
from typing import TypedDict

from scone_bt.errors import UnknownNameError
from scone_bt.experience.types import Outcome

__all__ = ["BACKEND_KEY", "LearnFrom", "StoreFilters", "on_backend", "unlabelled_backend"]

BACKEND_KEY = "backend"
"""Context key naming the robot backend an outcome was observed on (`scone_bt.robot.registry.BACKENDS`)."""


class StoreFilters(TypedDict, total=False):
    """The filters of `OutcomeStore.outcomes` a `LearnFrom` selects by (none: every outcome)."""

    robot_id: str
    arm: str
    profile: str
    where: Callable[[Outcome], bool]


def on_backend(backend: str) -> Callable[[Outcome], bool]:
    """Keeps outcomes observed on ``backend``, and those stored before outcomes named theirs."""

    def keep(outcome: Outcome) -> bool:
        return outcome.context.get(BACKEND_KEY, backend) == backend

    return keep


def unlabelled_backend(outcome: Outcome) -> bool:
    """An outcome stored before outcomes named their backend."""
    return BACKEND_KEY not in outcome.context


class LearnFrom(Enum):
    """Which outcomes of a (possibly shared) experience store a robot learns from."""

    SELF = "self"  # only outcomes with this robot's id, on its backend
    SAME_MODEL = "same-model"  # every robot with the same arm model and profile, on this backend
    FLEET = "fleet"  # every outcome in the store, every backend's

    @classmethod
    def parse(cls, name: str) -> LearnFrom:
        """The member named `name`; a one-line error naming the valid ones otherwise."""
        for member in cls:
            if member.value == name:
                return member
        raise UnknownNameError("--learn-from value", name, [m.value for m in cls])

    def filters(self, robot_id: str, arm: str, profile: str = "", backend: str | None = None) -> StoreFilters:
        """Filters for OutcomeStore.outcomes() (None ``backend``: any backend's outcomes).

        A model is an arm with a profile (gripper pads, camera, planner settings): robots of one model fail at
        the same things, robots of different models need not; nor need one model on two backends.
        """
        if self is LearnFrom.FLEET:
            return {}
        chosen: StoreFilters = (
            {"robot_id": robot_id} if self is LearnFrom.SELF else {"arm": arm, "profile": profile}
        )
        if backend is not None:
            chosen["where"] = on_backend(backend)
        return chosen

    def describe(self, robot_id: str, arm: str, profile: str = "", backend: str | None = None) -> str:
        """Human words for the selection ("of robot 'panda-2' on the 'mujoco' backend")."""
        if self is LearnFrom.FLEET:
            return "of the whole fleet" + (", every backend's" if backend is not None else "")
        if self is LearnFrom.SELF:
            who = f"of robot {robot_id!r}"
        else:
            who = f"of every {arm} robot" + (f" with profile {profile!r}" if profile else "")
        return who + (f" on the {backend!r} backend" if backend is not None else "")
