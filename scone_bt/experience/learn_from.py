"""Whose stored outcomes rebuild a robot's κ̂: its own, those of robots of the same arm model, or the fleet's."""

from __future__ import annotations

from enum import Enum
from typing import TypedDict

from scone_bt.errors import UnknownNameError

__all__ = ["LearnFrom", "StoreFilters"]


class StoreFilters(TypedDict, total=False):
    """The equality filters of `OutcomeStore.outcomes` a `LearnFrom` selects by (none: every outcome)."""

    robot_id: str
    arm: str
    profile: str


class LearnFrom(Enum):
    """Which outcomes of a (possibly shared) experience store a robot learns from."""

    SELF = "self"  # only outcomes with this robot's id
    SAME_MODEL = "same-model"  # every robot with the same arm model and profile
    FLEET = "fleet"  # every outcome in the store

    @classmethod
    def parse(cls, name: str) -> LearnFrom:
        """The member named `name`; a one-line error naming the valid ones otherwise."""
        for member in cls:
            if member.value == name:
                return member
        raise UnknownNameError("--learn-from value", name, [m.value for m in cls])

    def filters(self, robot_id: str, arm: str, profile: str = "") -> StoreFilters:
        """Keyword filters for OutcomeStore.outcomes().

        A model is an arm with a profile (gripper pads, camera, planner settings): robots of one model fail at
        the same things, robots of different models need not.
        """
        if self is LearnFrom.SELF:
            return {"robot_id": robot_id}
        if self is LearnFrom.SAME_MODEL:
            return {"arm": arm, "profile": profile}
        return {}

    def describe(self, robot_id: str, arm: str, profile: str = "") -> str:
        """Human words for the selection ("of robot 'panda-2'")."""
        if self is LearnFrom.SELF:
            return f"of robot {robot_id!r}"
        if self is LearnFrom.SAME_MODEL:
            return f"of every {arm} robot" + (f" with profile {profile!r}" if profile else "")
        return "of the whole fleet"
