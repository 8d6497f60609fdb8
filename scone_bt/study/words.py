"""What the tablet says, in plain words: the robot's reason for its decision, and the feed's lines.

The reason comes from the gate's decision as the event carries it (`DecisionMade.rule` and ``reason``): the robot
says it is "not confident" only when κ̂ against the threshold decided (rule ""). Item names get the grammar of
plurals ("The crushed tomatoes are on the table") and mass nouns ("The spaghetti is on the table").
"""

from __future__ import annotations

import math
import re

from scone_bt.events import (
    NO_ROOM,
    ActCancelled,
    ActOutcome,
    ActStarted,
    ClarificationAsked,
    DecisionMade,
    Event,
    HelpDeclined,
    HelpGiven,
    HelpRequested,
    Intervention,
    PlanInfeasible,
    StepDone,
    TakeOver,
)
from scone_bt.gate.types import LOOKING_AGAIN, DecisionKind
from scone_bt.recipes.normalise import item_key

__all__ = ["is_plural", "is_are", "it_them", "decision_words", "help_words", "feed_line", "number_word"]

_SINGULAR_IN_S = frozenset(
    {"molasses", "hummus", "couscous", "asparagus", "citrus", "swiss", "schnapps", "grits"}
)
"""Items ending in "s" that take "is" (mass nouns and names); `item_key` keeps most ("hummus"), not these."""

_NUMBERS = ("no", "once", "twice", "three times", "four times", "five times", "six times", "seven times")

_FAILED_AT = {
    "perception": "it lost sight of it",
    "ik": "it could not reach it",
    "planning": "it could not find a safe way to move",
    "grasp": "it slipped out of the gripper",
    "transit": "it dropped it on the way",
    "collision": "it bumped into something",
    "place": "it did not land upright on the table",
    "timeout": "it took too long",
}


def is_plural(item: str) -> bool:
    """Whether an item name is a plural ("crushed tomatoes", "black beans"); mass nouns ("spaghetti", "salt",
    "hummus") are not."""
    words = item.strip().lower().split()
    if not words or words[-1] in _SINGULAR_IN_S:
        return False
    return item_key(item.strip().lower()) != item.strip().lower()


def is_are(item: str) -> str:
    return "are" if is_plural(item) else "is"


def it_them(item: str) -> str:
    return "them" if is_plural(item) else "it"


def number_word(times: int) -> str:
    """1 → "once", 3 → "three times"."""
    return _NUMBERS[times] if 0 <= times < len(_NUMBERS) else f"{times} times"


def _sentence(text: str) -> str:
    text = text.strip()
    if not text:
        return text
    text = text[0].upper() + text[1:]
    return text if text.endswith((".", "!", "?")) else text + "."


def _drop_notes(reason: str) -> str:
    """The gate's reason without its bracketed notes for the log ("(known: not planned again ...)")."""
    return re.sub(r"\s*\([^)]*\)", "", reason).strip()


def decision_words(event: DecisionMade) -> str:
    """The robot's reason for a decision, as it says it on the tablet (first person, one or two sentences)."""
    item = event.object_name or ""
    kind, rule = event.verdict, event.rule
    if kind is DecisionKind.CLARIFY:
        return "I am not sure which item this step means: I am asking."
    if kind is DecisionKind.IDLE:
        if rule in ("missing", "") and event.reason.startswith("waiting:"):
            items = _drop_notes(event.reason[len("waiting:") :]).replace(" not in sight", "")
            doing = "looking again" if event.reason.endswith(LOOKING_AGAIN) else "waiting"
            return _sentence(f"I cannot see the {items}: I am {doing}")
        if rule == "declined":
            return _sentence(_drop_notes(event.reason))
        return "There is nothing for me to do on this step; I am waiting."
    if kind is DecisionKind.ACT:
        if rule == "declined":
            return f"You asked me to try the {item} myself: I am about to fetch {it_them(item)}."
        if event.probe:  # the heft test first: the participant sees the arm lift, hold and maybe set it back
            them = it_them(item)
            return (
                f"I am not sure about the {item}: I will lift {them} a little first to feel whether I can hold "
                f"{them}, then fetch {them} or put {them} back and ask you."
            )
        return f"I am about to fetch the {item}."
    return help_words(event)


def help_words(event: DecisionMade) -> str:
    """Why the robot asks for help with the decision's item, in plain words (ASK decisions)."""
    item = event.object_name or "item"
    rule = event.rule
    if rule == "infeasible":
        said = _drop_notes(event.reason)
        return _sentence(said if said.lower().startswith(("i ", "there")) else f"I cannot reach the {item}")
    if rule == "failure-limit":
        match = re.search(r"(\d+)", event.reason)
        times = int(match.group(1)) if match else 0
        return f"I have failed {number_word(times) if times else 'several times'} with the {item}."
    if rule == "missing":
        return f"I cannot see the {item}."
    if rule == "too-wide":
        return f"The {item} {is_are(item)} too wide for my gripper."
    if rule == "":
        shown = (
            "" if not math.isfinite(event.confidence) else f" (confidence {round(event.confidence * 100)} %)"
        )
        return f"I might drop {it_them(item)}: I am not confident I can fetch the {item}{shown}."
    return _sentence(_drop_notes(event.reason)) or f"I need your help with the {item}."


def feed_line(event: Event) -> str | None:
    """The feed's line for an event, in the participant's words (None: nothing to say)."""
    if isinstance(event, ActStarted):
        if event.window_s > 0:
            return f"The robot is about to fetch the {event.object_name}."
        return f"The robot is fetching the {event.object_name}."
    if isinstance(event, ActOutcome):
        item = event.object_name
        if event.success:
            return f"The {item} {is_are(item)} on the table."
        why = _FAILED_AT.get(event.stage or "", "something went wrong")
        return f"The robot could not fetch the {item}: {why}."
    if isinstance(event, PlanInfeasible):
        return None  # the decision that follows says why, in the robot's words
    if isinstance(event, ActCancelled):
        return None  # the take-over line says it
    if isinstance(event, TakeOver):
        return f"You took over: the robot stopped fetching the {event.object_name}."
    if isinstance(event, HelpRequested):
        item = event.object_name
        if event.reason:
            return f'The robot asks: "{_sentence(event.reason)}"'
        return f"The robot asks you to bring the {item}."
    if isinstance(event, (HelpGiven, Intervention)):
        return f"You brought the {event.object_name}."
    if isinstance(event, HelpDeclined):
        if event.detail == NO_ROOM:
            return f"There was no room on the table for the {event.object_name}."
        return f"You asked the robot to try the {event.object_name} itself."
    if isinstance(event, ClarificationAsked):
        said = ", ".join(event.answer) or "none of those"
        return f"The robot asked which of {', '.join(event.candidates)} the step means: {said}."
    if isinstance(event, StepDone):
        return _sentence(f"Step done: {event.detail}")
    return None
