"""The study's design: participants cook twice, once with self-confidence on and once off, in two groups.

Group A has self-confidence on in session 1 and off in session 2; group B the reverse (counterbalancing).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from enum import StrEnum
from typing import Protocol

from scone_bt.errors import SconeError, UnknownNameError

__all__ = ["Condition", "Group", "SessionPlan", "plan_session", "assign_group", "check_next_session"]


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
        raise UnknownNameError("participant id", participant, ["any non-empty text, e.g. P01"])
    return SessionPlan(participant.strip(), g, session_index, _ORDER[g][session_index - 1])


def assign_group(index: int) -> Group:
    """Alternate groups by enrolment order (participant 0 → A, 1 → B, ...)."""
    return Group.A if index % 2 == 0 else Group.B


class _StoredSession(Protocol):
    """What `check_next_session` reads of a stored session (`scone_bt.study.log.SessionRow`)."""

    @property
    def participant(self) -> str: ...
    @property
    def group(self) -> str: ...
    @property
    def session_index(self) -> int: ...
    @property
    def ended(self) -> float | None: ...


def check_next_session(plan: SessionPlan, sessions: Iterable[_StoredSession], source: str) -> None:
    """Refuse a session that would break the participant's crossover, before it begins; one line naming `source`
    (the study log), the participant and the session(s) that would be valid.

    A participant's group is their condition order, fixed by their first session: every later session keeps it
    (with another group they would see one condition twice and never the other). Each session index is run once
    and in order: session 2 follows a finished session 1. A session that was interrupted (a row without an end:
    the analysis leaves it out) may be run again, in the same group.
    """
    p = plan.participant
    rows = [s for s in sessions if s.participant == p]
    if not rows:
        if plan.session_index != 1:
            raise SconeError(f"{p} has no session 1 in {source}; next: --session 1 --group A or --group B")
        return
    groups = sorted({s.group for s in rows})
    if len(groups) > 1:
        raise SconeError(
            f"{p} has sessions in groups {' and '.join(groups)} in {source}, so their crossover is broken; "
            "give a new participant id"
        )
    group = groups[0]
    finished = {s.session_index for s in rows if s.ended is not None}
    if {1, 2} <= finished:
        raise SconeError(
            f"{p} already has both sessions (group {group}) in {source}; give a new participant id"
        )
    following = f"--session {1 if 1 not in finished else 2} --group {group}"
    if plan.group.value != group:
        indices = sorted({s.session_index for s in rows})
        held = f"session{'s' if len(indices) > 1 else ''} {', '.join(map(str, indices))}"
        raise SconeError(f"{p} is in group {group} in {source} ({held}); next: {following}")
    if plan.session_index in finished:
        raise SconeError(
            f"{p} already has session {plan.session_index} (group {group}) in {source}; next: {following}"
        )
    if plan.session_index == 2 and 1 not in finished:
        interrupted = any(s.session_index == 1 for s in rows)
        raise SconeError(
            f"{p} has no {'finished ' if interrupted else ''}session 1 in {source}"
            f"{' (it was interrupted)' if interrupted else ''}; next: {following}"
        )
