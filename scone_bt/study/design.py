"""The study's design: participants cook twice, once with self-confidence on and once off, in two groups.

Group A has self-confidence on in session 1 and off in session 2; group B the reverse (counterbalancing).
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum

from scone_bt.errors import UnknownNameError

__all__ = ["Condition", "Group", "SessionPlan", "plan_session", "assign_group"]


class Condition(StrEnum):
    """Whether the robot uses its self-confidence (asks for help when it predicts a failure)."""

    ON = "on"
    OFF = "off"


class Group(StrEnum):
    """Condition order: A = self-confidence on first, B = off first."""

    A = "A"
    B = "B"


_ORDER = {Group.A: (Condition.ON, Condition.OFF), Group.B: (Condition.OFF, Condition.ON)}


@dataclass(frozen=True)
class SessionPlan:
    """One participant's session.

    Attributes:
        participant: Participant id (free text, e.g. "P07").
        group: Condition order.
        session_index: 1 or 2.
        condition: Self-confidence on or off, implied by group and session_index.
    """

    participant: str
    group: Group
    session_index: int
    condition: Condition


def plan_session(participant: str, group: str | Group, session_index: int) -> SessionPlan:
    """The session's condition from the group's order; errors name the valid choices."""
    try:
        g = Group(group)
    except ValueError:
        raise UnknownNameError("group", str(group), [x.value for x in Group]) from None
    if session_index not in (1, 2):
        raise UnknownNameError("session index", str(session_index), ["1", "2"])
    if not participant or not participant.strip():
        raise UnknownNameError("participant id", repr(participant), ["any non-empty text, e.g. P01"])
    return SessionPlan(participant.strip(), g, session_index, _ORDER[g][session_index - 1])


def assign_group(index: int) -> Group:
    """Alternate groups by enrolment order (participant 0 → A, 1 → B, ...)."""
    return Group.A if index % 2 == 0 else Group.B
