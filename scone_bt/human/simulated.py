"""A simulated human who cooks alongside the robot.

The human reads the recipe step by step. A step is done once every object it needs is on the table; the human
then cooks it (``cook_time_s``) and moves to the next step. The human fetches objects by hand in three cases:
- help: the robot asked for help with an object (counted as a help request answered);
- take-over: the human intervenes on an action the robot is attempting (a seeded coin per act decision, with
  probability ``takeover_probability``);
- clean-up: a needed object is neither on the shelf nor on the table (the robot dropped it), or the robot has been
  idle on this step for ``patience_s`` (the human stops waiting).
Take-overs and clean-ups are interventions, each with its cause (`scone_bt.events.INTERVENTION_CAUSES`). Idle means
neither acting nor asking: the patience clock restarts whenever the robot stops acting or stops waiting on its own
request, so the time the robot waits on the human never counts. A clean-up of an item the robot then asks for
becomes that help request (the item is brought at the robot's request, not counted as an intervention). Fetching
takes ``fetch_time_s`` of simulated time. When the table has no room for a fetched product, the human makes room
first: they put away, one by one (earliest step first), the products on the table that the current and later steps
no longer need (`put_away_products`), as a cook clears what they have used. A product the step in hand needs that
still does not fit makes the human set aside, onto the counter, products only later steps need, the latest-needed
first (`set_aside_products`; a robot working ahead can fill the table with them), and bring each back when its step
comes: neither help nor an intervention. A product of the step in hand that fits nowhere even then (the step needs
more than the table holds) is used straight from the human's hands (`used_in_hand`). A product the robot asked for
that no step in hand needs and that does not fit is declined ("no room on the table", a `HelpDeclined` event): the
robot stops asking for it, and the human brings it once its step needs it (the robot idle for ``patience_s``).

When the robot asks which item a step means (ASK-CLARIFY), the human names the candidates its current step
needs, else those the next step that needs any of them needs, else none ("none of those"); answering takes
``clarify_time_s``. A scenario can make the human answer otherwise (`ClarifyAnswer`: the wrong candidates, or
"none of those"), and decline help requests (`HelpAnswer.DECLINE`: "try it yourself", a `HelpDeclined` event).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import Enum
from typing import TYPE_CHECKING

import numpy as np

from scone_bt.defaults import EPISODE
from scone_bt.events import (
    NO_ROOM,
    CleanUpStarted,
    Event,
    HelpDeclined,
    HelpGiven,
    Intervention,
    StepDone,
)
from scone_bt.stocking import StockedRecipe

if TYPE_CHECKING:  # the human reads the world only through the test rig's protocol, never the simulator
    from scone_bt.robot.rig import HumanWorld

__all__ = ["ClarifyAnswer", "HelpAnswer", "HumanOptions", "FetchReason", "SimulatedHuman"]


class HelpAnswer(Enum):
    """How the human answers a help request: fetch the object, or decline ("try it yourself")."""

    FETCH = "fetch"
    DECLINE = "decline"


class ClarifyAnswer(Enum):
    """How the human answers "which one?": the candidates the step needs (RIGHT), the others (WRONG), or none."""

    RIGHT = "right"
    WRONG = "wrong"
    NONE = "none"


@dataclass(frozen=True)
class HumanOptions:
    """How the simulated human behaves. Times in simulated seconds.

    Attributes:
        fetch_time_s: Time to walk to the shelf and bring one object.
        cook_time_s: Time spent on a step once its objects are on the table.
        patience_s: Idle robot time on a step before the human fetches what is missing.
        takeover_probability: Chance that the human intervenes on an action the robot attempts.
        takeover_delay_s: How long into the robot's action the take-over happens.
        clarify_time_s: Time to answer the robot's "which one?" question.
        help_answer: How help requests are answered.
        clarify_answer: How "which one?" is answered.
    """

    fetch_time_s: float = 6.0
    cook_time_s: float = 2.0
    patience_s: float = 20.0
    takeover_probability: float = EPISODE.takeover_probability
    takeover_delay_s: float = 1.0
    clarify_time_s: float = 2.0
    help_answer: HelpAnswer = HelpAnswer.FETCH
    clarify_answer: ClarifyAnswer = ClarifyAnswer.RIGHT


class FetchReason(Enum):
    """Why the human fetches an object: the robot asked (HELP), on their own (INTERVENTION), or it is one they set
    aside themselves to make room and its step has come (SET_ASIDE: the robot's record is not touched)."""

    HELP = "help"
    INTERVENTION = "intervention"
    SET_ASIDE = "set aside"


@dataclass
class _Fetch:
    object_name: str
    ready_at: float
    kind: FetchReason
    cause: str = ""  # with INTERVENTION: the key of INTERVENTION_CAUSES it will be counted under


@dataclass
class SimulatedHuman:
    """The human's state machine; call `update()` once per control tick after the world advanced.

    ``kitchen`` is the world the human works in (`HumanWorld`: a backend's `World`, or a `world.Kitchen`).
    """

    kitchen: HumanWorld
    recipe: StockedRecipe
    options: HumanOptions = field(default_factory=HumanOptions)
    seed: int = 0

    def __post_init__(self) -> None:
        self.rng = np.random.default_rng(self.seed)
        self.step_index = 0
        self.step_done = [False] * len(self.recipe.steps)
        self._cooking_until: float | None = None
        self._idle_since = (
            self.kitchen.sim_time
        )  # when the robot last stopped acting or asking (or the step began)
        self._robot_busy_since: float | None = None
        self._fetches: list[_Fetch] = []
        self.help_given = 0
        self.clarifications = 0
        self.interventions = 0
        self.help_declined = 0
        self._declined: list[Event] = []  # answers to requests, reported with the next update()
        self._declined_objects: set[str] = set()
        # Used products taken off the table to make room, in order.
        self.put_away_products: list[str] = []
        # Products of later steps set aside for the step in hand, in order; those not brought back yet.
        self.set_aside_products: list[str] = []
        self._aside: set[str] = set()
        # Brought for a step but used from the hands, with no place on the table (they stay at the stove).
        self.used_in_hand: set[str] = set()
        self._acting_on: str | None = None  # the product of the robot's action under way: never set aside
        self.events: list[Event] = []

    # -------------------------------------------------------------------------------------------- state
    @property
    def done(self) -> bool:
        return all(self.step_done)

    @property
    def clarify_time_s(self) -> float:
        """How long answering "which one?" takes, simulated seconds."""
        return self.options.clarify_time_s

    @property
    def current_instruction(self) -> str | None:
        return None if self.done else self.recipe.steps[self.step_index].instruction

    def steps_completed(self) -> int:
        return sum(self.step_done)

    def is_fetching(self, object_name: str) -> bool:
        return any(f.object_name == object_name for f in self._fetches)

    def help_pending(self, object_name: str) -> bool:
        return any(f.object_name == object_name and f.kind is FetchReason.HELP for f in self._fetches)

    # -------------------------------------------------------------------------------------------- robot → human
    def request_help(self, object_name: str) -> None:
        """The robot asks the human to fetch this object (a declining human says so: a HelpDeclined event)."""
        if self.options.help_answer is HelpAnswer.DECLINE:
            self._decline(object_name, "the human declined: try it yourself")
            return
        for fetch in self._fetches:
            if fetch.object_name != object_name:
                continue
            # A clean-up, or a product the human set aside coming back: now brought because the robot asked (a
            # set-aside fetch kept as it was left the request unanswered: no HelpGiven, no HelpDeclined).
            if fetch.kind is FetchReason.SET_ASIDE or (
                fetch.kind is FetchReason.INTERVENTION and fetch.cause != "takeover"
            ):
                fetch.kind, fetch.cause = FetchReason.HELP, ""
            return
        if not self.is_fetching(object_name):
            self._fetches.append(
                _Fetch(object_name, self.kitchen.sim_time + self.options.fetch_time_s, FetchReason.HELP)
            )

    def _decline(self, object_name: str, detail: str) -> None:
        """Answer the robot's request for this object with no (reported with the next update())."""
        self.help_declined += 1
        self._declined_objects.add(object_name)
        self._declined.append(HelpDeclined(self.kitchen.sim_time, object_name, detail))

    def declined(self, object_name: str) -> bool:
        """The human declined a help request for this object."""
        return object_name in self._declined_objects

    def answer_clarification(self, candidates: tuple[str, ...]) -> tuple[str, ...]:
        """The robot asks which of ``candidates`` the step wants; see the module docstring."""
        self.clarifications += 1
        if self.options.clarify_answer is ClarifyAnswer.NONE:
            return ()
        right: tuple[str, ...] = ()
        for step in self.recipe.steps[self.step_index :]:
            right = tuple(c for c in candidates if c in step.objects and not self.kitchen.is_on_table(c))
            if right:
                break
        if self.options.clarify_answer is ClarifyAnswer.WRONG:
            return tuple(c for c in candidates if c not in right)
        return right

    def decide_takeover(self, object_name: str) -> None:
        """Called once when the robot starts an action on an object: the human decides whether to take over."""
        self._takeover_at = None
        self._acting_on = object_name
        if self.options.takeover_probability > 0 and self.rng.random() < self.options.takeover_probability:
            self._takeover_at = (object_name, self.kitchen.sim_time + self.options.takeover_delay_s)

    def wants_takeover(self, object_name: str) -> bool:
        """Polled every tick while the robot acts on the object: True once the human intervenes."""
        planned = getattr(self, "_takeover_at", None)
        return planned is not None and planned[0] == object_name and self.kitchen.sim_time >= planned[1]

    def take_over(self, object_name: str) -> None:
        """The human intervenes: the robot's action is cancelled and the human fetches the object."""
        self._takeover_at = None
        if not self.is_fetching(object_name):
            self._fetches.append(
                _Fetch(
                    object_name,
                    self.kitchen.sim_time + self.options.fetch_time_s,
                    FetchReason.INTERVENTION,
                    "takeover",
                )
            )

    def robot_busy(self, busy: bool) -> None:
        """The robot reports whether it acts or waits on its own request (True), or neither (False).

        Either edge restarts the human's patience: it runs only while the robot neither acts nor asks.
        """
        self._robot_busy_since = self.kitchen.sim_time if busy else None
        self._idle_since = self.kitchen.sim_time
        if not busy:
            self._acting_on = None

    # -------------------------------------------------------------------------------------------- table
    def _place_on_table(self, name: str) -> bool:
        """Put the fetched product on the table, making room when it is full, or, for the step in hand when the
        table cannot hold it, take it in hand (`used_in_hand`); False: no room, and no step in hand needs it (see
        the module docstring).

        Without this a full table made every fetch fail quietly: the robot asked again and again for a product
        too wide for its gripper until the episode's tick limit.
        """
        if self.kitchen.place_on_table(name):
            return True
        for used in self._used_on_table():
            self.kitchen.put_away(used)
            self.put_away_products.append(used)
            if self.kitchen.place_on_table(name):
                return True
        if self.done or name not in self.recipe.steps[self.step_index].objects:
            return False
        # The step in hand cannot wait for room: a table full of what later steps need (a robot working ahead
        # filled it) left the human waiting for ever on a product it could not put down.
        for later in self._needed_later_on_table():
            self.kitchen.put_away(later)
            self.set_aside_products.append(later)
            self._aside.add(later)
            if self.kitchen.place_on_table(name):
                return True
        # The step needs more than the table holds: the cook uses it from their hands.
        self.kitchen.put_away(name)
        self.used_in_hand.add(name)
        return True

    def _needed_later_on_table(self) -> list[str]:
        """Products on the table that only steps after the current one need, the one needed latest first."""
        steps = self.recipe.steps
        now = set(steps[self.step_index].objects)
        first_need: dict[str, int] = {}
        for i in range(self.step_index + 1, len(steps)):
            for o in steps[i].objects:
                first_need.setdefault(o, i)
        # Not what the robot is acting on or touching: one it has just put down is its outcome, judged next tick.
        later = [
            o
            for o in first_need
            if o not in now
            and o != self._acting_on
            and self.kitchen.is_on_table(o)
            and not self.kitchen.touches_robot(o)
        ]
        return sorted(later, key=lambda o: -first_need[o])

    def _used_on_table(self) -> list[str]:
        """Products on the table that only steps before the current one needed, earliest step first."""
        still_needed = {o for step in self.recipe.steps[self.step_index :] for o in step.objects}
        used = dict.fromkeys(o for step in self.recipe.steps[: self.step_index] for o in step.objects)
        return [o for o in used if o not in still_needed and self.kitchen.is_on_table(o)]

    # -------------------------------------------------------------------------------------------- tick
    def update(self) -> list[Event]:
        """Advance the human by one tick; returns the events of this tick."""
        now = self.kitchen.sim_time
        new: list[Event] = self._declined
        self._declined = []
        for fetch in list(self._fetches):
            if now >= fetch.ready_at:
                self._fetches.remove(fetch)
                if self.kitchen.is_on_table(fetch.object_name):
                    continue
                if self._place_on_table(fetch.object_name):
                    self._aside.discard(fetch.object_name)
                    if fetch.kind is FetchReason.SET_ASIDE:
                        continue  # the human's own doing: no help, no intervention
                    if fetch.kind is FetchReason.HELP:
                        self.help_given += 1
                        new.append(HelpGiven(now, fetch.object_name, "fetched by the human"))
                    else:
                        self.interventions += 1
                        new.append(Intervention(now, fetch.object_name, "fetched by the human", fetch.cause))
                elif fetch.kind is FetchReason.HELP:
                    # No room even after clearing what was used: the human says so (the robot then stops asking
                    # and waits, `gate.rules.after_decline`), and brings it when its step needs it and room is made.
                    self._decline(fetch.object_name, NO_ROOM)
                    new += self._declined
                    self._declined = []
        if self.done:
            self.events += new
            return new
        step = self.recipe.steps[self.step_index]
        missing = [o for o in step.objects if not self.kitchen.is_on_table(o) and o not in self.used_in_hand]
        if self._cooking_until is not None and missing:
            # Something the step uses left the table while the human cooked (a bottle that slid off after the
            # robot let go): the step is not done; the human waits for it, or picks it up, as before it started.
            self._cooking_until = None
        if self._cooking_until is not None:
            if now >= self._cooking_until:
                self.step_done[self.step_index] = True
                new.append(StepDone(now, step.instruction))
                self._cooking_until = None
                self.step_index = min(self.step_index + 1, len(self.recipe.steps) - 1)
                self._idle_since = now
        elif not missing:
            self._cooking_until = now + self.options.cook_time_s
        else:
            for name in missing:
                if name in self._aside:
                    if not self.is_fetching(name):
                        self._fetches.append(
                            _Fetch(name, now + self.options.fetch_time_s, FetchReason.SET_ASIDE)
                        )
                    continue
                dropped = not self.kitchen.is_on_shelf(name) and not self.kitchen.touches_robot(name)
                waited = self._robot_busy_since is None and now - self._idle_since >= self.options.patience_s
                if (dropped or waited) and not self.is_fetching(name):
                    reason = "the robot dropped it" if dropped else "the robot was idle too long"
                    cause = "dropped" if dropped else "idle"
                    self._fetches.append(
                        _Fetch(name, now + self.options.fetch_time_s, FetchReason.INTERVENTION, cause)
                    )
                    new.append(CleanUpStarted(now, name, reason))
        self.events += new
        return new
