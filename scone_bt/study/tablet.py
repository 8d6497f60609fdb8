"""The tablet's shared state and the tablet-driven human.

The web server (a background thread) and the episode loop (the main thread) share one `TabletState`; every access
goes through its lock. The episode side never blocks on the participant: a help request or a take-over becomes a
pending fetch that the participant confirms on the tablet, and the next `TabletHuman.update()` (main thread, the
only one that touches PyBullet) carries it out.
"""

from __future__ import annotations

import math
import threading
from collections import deque
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from enum import Enum
from typing import Any

from scone_bt.events import Event
from scone_bt.human import FetchReason, SimulatedHuman
from scone_bt.human.simulated import _Fetch
from scone_bt.study.questionnaires import (
    Questionnaire,
    QuestionnaireError,
    get_questionnaire,
    validate_answers,
)
from scone_bt.study.words import it_them

__all__ = ["TabletState", "TabletHuman", "TabletPhase", "PHASES", "START_BY", "AlreadySubmittedError"]


class TabletPhase(str, Enum):  # noqa: UP042 (the page receives the values)
    """What the tablet shows: waiting for the episode, the episode, the questionnaires, the end."""

    WAITING = "waiting"
    EPISODE = "episode"
    QUESTIONNAIRE = "questionnaire"
    DONE = "done"


PHASES = tuple(p.value for p in TabletPhase)
_REASONS = {
    FetchReason.HELP.value: "The robot asks for your help: please bring {it} to the table.",
    FetchReason.INTERVENTION.value: "You took over: please bring {it} to the table.",
}


class AlreadySubmittedError(QuestionnaireError):
    """A questionnaire submitted a second time: the first answers stand."""


START_BY = ("participant", "researcher", "autostart")
"""Who started a session: the participant's Start, the researcher's page, or --autostart."""


class TabletState:
    """What the tablet shows and what the participant did, guarded by one lock.

    Args:
        start_gate: The episode waits in "Waiting to start" until the participant or the researcher presses Start
            (`start`, `wait_start`); False starts it at once (scone-run --ui, --autostart).
        trust_shown: The participant's tablet shows the person's estimated trust (`set_trust`) from the start; the
            researcher's page always shows it, and its switch changes this for the rest of the session
            (`show_trust`).
    """

    def __init__(self, start_gate: bool = False, trust_shown: bool = False) -> None:
        self._lock = threading.Lock()
        self._version = 0
        self.start_gate = start_gate
        self.started_by: str | None = None if start_gate else "autostart"
        self._started = threading.Event()
        self.ready = False  # the robot is set up and waits for Start (`ready_to_start`)
        if not start_gate:
            self._started.set()
        self.phase = TabletPhase.WAITING
        self.label = ""
        self.steps: list[str] = []
        self.step_index = 0
        self.step_done: list[bool] = []
        self.robot: dict[str, Any] = {"action": None, "confidence": None, "kind": None, "status": "idle"}
        self.sim_time = 0.0
        self.acting_object: str | None = None
        self.takeover_object: str | None = None
        self._fetches: dict[str, dict[str, Any]] = {}  # object name → {object, kind, reason}
        self._confirmed: set[str] = set()
        self.feed: deque[str] = deque(maxlen=8)
        self._questionnaires: list[Questionnaire] = []
        self._submitted: set[str] = set()
        self._storing: set[str] = set()  # claimed by a submission whose answers are being written
        self._on_submit: Callable[[str, dict[str, float | None]], None] | None = None
        self.questionnaires_done = threading.Event()
        self.trust_shown = trust_shown
        self.trust: list[dict[str, Any]] = []  # the study view's rows (`scone_bt.study.trust_view.TrustRow`)
        self.on_trust_view: Callable[[bool], None] | None = None  # told each change of `trust_shown`

    def _touch(self) -> None:
        self._version += 1

    # ----------------------------------------------------------------------------------------- episode side
    def start_episode(self, steps: Sequence[str], label: str = "") -> None:
        """The episode is built: show its recipe (and, behind the start gate, wait for Start)."""
        with self._lock:
            self.label = label or self.label
            self.phase = TabletPhase.EPISODE if self._started.is_set() else TabletPhase.WAITING
            self.steps, self.step_index, self.step_done = list(steps), 0, [False] * len(steps)
            self.robot = {"action": None, "confidence": None, "kind": None, "status": "idle"}
            self.acting_object = self.takeover_object = None
            self._fetches.clear()
            self._confirmed.clear()
            self.feed.clear()
            self.trust = []
            self._touch()

    def sync_recipe(self, step_index: int, step_done: Sequence[bool]) -> None:
        with self._lock:
            if step_index != self.step_index or list(step_done) != self.step_done:
                self.step_index, self.step_done = step_index, list(step_done)
                self._touch()

    def set_robot(self, **fields: Any) -> None:
        with self._lock:
            self.robot.update(fields)
            self._touch()

    def announce(self, object_name: str, window_s: float, now: float) -> None:
        """The robot announces an attempt and stays still for ``window_s`` simulated seconds (take-over window)."""
        with self._lock:
            self.robot.update(
                status="announcing",
                say=f"I am about to fetch the {object_name}. Take over now if you want to.",
                window_s=window_s,
                window_until=now + window_s,
            )
            self.sim_time = now
            self._touch()

    def sync_time(self, now: float) -> None:
        """The episode's simulated time (ticks the take-over window's countdown; the robot moves at its end)."""
        with self._lock:
            self.sim_time = now
            until = self.robot.get("window_until")
            if until is None:
                return
            if now >= until and self.robot.get("status") == "announcing":
                self.robot.update(status="acting", say=f"I am fetching the {self.acting_object}.")
                self.robot["window_until"] = None
            self._touch()

    def set_acting(self, object_name: str | None) -> None:
        with self._lock:
            self.acting_object = object_name
            if object_name is None:
                self.takeover_object = None
                if self.robot.get("status") in ("acting", "announcing"):
                    self.robot["status"] = "idle"
                self.robot["window_until"] = None
            self._touch()

    def add_fetch(self, object_name: str, kind: str, reason: str | None = None) -> None:
        with self._lock:
            self._fetches[object_name] = {
                "object": object_name,
                "kind": kind,
                "reason": reason or _REASONS.get(kind, "").format(it=it_them(object_name)),
            }
            self._touch()

    def explain_fetch(self, object_name: str, why: str) -> None:
        """Give a pending help request the robot's reason ("I cannot see the garlic.") above what to do."""
        with self._lock:
            fetch = self._fetches.get(object_name)
            if fetch is not None and fetch["kind"] == FetchReason.HELP.value and why:
                fetch["reason"] = f"{why} Please bring {it_them(object_name)} to the table."
                fetch["why"] = why
                self._touch()

    def retain_fetches(self, objects: set[str]) -> None:
        """Forget fetches the human has finished."""
        with self._lock:
            for name in [n for n in self._fetches if n not in objects]:
                del self._fetches[name]
                self._touch()

    def pop_confirmed(self) -> set[str]:
        with self._lock:
            out, self._confirmed = self._confirmed, set()
            return out

    def wants_takeover(self, object_name: str) -> bool:
        with self._lock:
            return self.takeover_object == object_name

    def clear_takeover(self) -> None:
        with self._lock:
            self.takeover_object = None
            self.acting_object = None
            self.robot["window_until"] = None
            self._touch()

    def set_trust(self, rows: Sequence[dict[str, Any]]) -> None:
        """The person's estimated trust per action on offer, as of the latest decision."""
        with self._lock:
            self.trust = [dict(r) for r in rows]
            self._touch()

    def note(self, line: str) -> None:
        with self._lock:
            self.feed.appendleft(line)
            self._touch()

    def finish_episode(self) -> None:
        with self._lock:
            self.acting_object = self.takeover_object = None
            self.robot["status"] = "finished"
            self._touch()

    def ready_to_start(self) -> None:
        """The robot is set up (models loaded, tree built): Start can be pressed now."""
        with self._lock:
            self.ready = True
            self._touch()

    def wait_start(self, poll_s: float = 0.25) -> str:
        """Say the robot is ready, then block until Start was pressed (at once without the gate); returns who
        started it (`START_BY`)."""
        self.ready_to_start()
        while not self._started.wait(poll_s):  # a short wait at a time: Ctrl-C still interrupts it
            pass
        assert self.started_by is not None
        return self.started_by

    # ----------------------------------------------------------------------------------------- participant side
    def start(self, by: str) -> bool:
        """The participant or the researcher presses Start; False if the session had started already or the robot
        is not ready yet."""
        if by not in START_BY:
            raise ValueError(f"start by {by!r}; valid: {', '.join(START_BY)}")
        with self._lock:
            if self._started.is_set() or not self.ready:
                return False
            self.started_by = by
            self._started.set()
            if self.phase is TabletPhase.WAITING and self.steps:
                self.phase = TabletPhase.EPISODE
            self._touch()
            return True

    def confirm(self, object_name: str) -> bool:
        """The participant says the object is on the table. False if nothing was pending for it."""
        with self._lock:
            if object_name not in self._fetches or object_name in self._confirmed:
                return False
            self._confirmed.add(object_name)
            self._fetches[object_name]["confirmed"] = True
            self._touch()
            return True

    def request_takeover(self) -> str | None:
        """The participant takes over the current action; returns its object, or None if the robot is not acting."""
        with self._lock:
            if self.acting_object is None:
                return None
            self.takeover_object = self.acting_object
            self._touch()
            return self.takeover_object

    # ----------------------------------------------------------------------------------------- researcher side
    def show_trust(self, shown: bool) -> bool:
        """The researcher shows (True) or hides the estimated trust on the participant's tablet; False if it was
        so already. `on_trust_view` hears each change (in the caller's thread, after the lock)."""
        with self._lock:
            if shown == self.trust_shown:
                return False
            self.trust_shown = shown
            self._touch()
            callback = self.on_trust_view
        if callback is not None:
            callback(shown)
        return True

    # ----------------------------------------------------------------------------------------- questionnaires
    def ask(
        self,
        questionnaires: Sequence[Questionnaire],
        on_submit: Callable[[str, dict[str, float | None]], None],
    ) -> None:
        with self._lock:
            self._questionnaires, self._submitted, self._on_submit = list(questionnaires), set(), on_submit
            self._storing = set()
            self.phase = TabletPhase.QUESTIONNAIRE
            self.questionnaires_done.clear()
            self._touch()

    def submit(self, name: str, answers: dict[str, Any]) -> None:
        """Validate and store one questionnaire, once.

        The first valid submission claims the questionnaire under the lock, so a concurrent or later one is
        refused (AlreadySubmittedError), never stored over the first. A claim whose storing fails is released.

        Raises:
            AlreadySubmittedError: it was submitted (or is being stored) already.
            QuestionnaireError, UnknownNameError: not asked now, or answers outside the scale.
        """
        q = get_questionnaire(name)
        checked = validate_answers(q, {k: (None if v is None else float(v)) for k, v in answers.items()})
        with self._lock:
            if self.phase not in (TabletPhase.QUESTIONNAIRE, TabletPhase.DONE) or q.name not in {
                x.name for x in self._questionnaires
            }:
                raise QuestionnaireError(f"questionnaire {name!r} is not being asked now")
            if q.name in self._submitted or q.name in self._storing:
                raise AlreadySubmittedError(
                    f"questionnaire {name!r} was already submitted; answers are not replaced"
                )
            self._storing.add(q.name)
            callback = self._on_submit
        try:
            if callback is not None:
                callback(q.name, checked)  # durable before the tablet hears "saved"
        except BaseException:
            with self._lock:
                self._storing.discard(q.name)
            raise
        with self._lock:
            self._storing.discard(q.name)
            self._submitted.add(q.name)
            if all(x.name in self._submitted for x in self._questionnaires):
                self.phase = TabletPhase.DONE
                self.questionnaires_done.set()
            self._touch()

    # ----------------------------------------------------------------------------------------- view
    def snapshot(self, researcher: bool = False) -> dict[str, Any]:
        """What a page shows: the participant's tablet gets the estimated trust only while it is shown; the
        researcher's page always gets it, and whether the participant sees it."""
        with self._lock:
            view: dict[str, Any] = {"trust_shown": self.trust_shown} if researcher else {}
            if researcher or self.trust_shown:
                view["trust"] = [dict(r) for r in self.trust]
            return view | {
                "version": self._version,
                "phase": self.phase.value,
                "can_start": self.ready and not self._started.is_set(),
                "getting_ready": not self.ready and not self._started.is_set(),
                "started_by": self.started_by,
                "label": self.label,
                "steps": [
                    {
                        "text": t,
                        "done": d,
                        "current": i == self.step_index and not d and self.phase is TabletPhase.EPISODE,
                    }
                    for i, (t, d) in enumerate(zip(self.steps, self.step_done, strict=True))
                ],
                "robot": {
                    **self.robot,
                    "window_left_s": (
                        None
                        if self.robot.get("window_until") is None
                        else round(max(0.0, self.robot["window_until"] - self.sim_time), 1)
                    ),
                },
                "can_take_over": self.acting_object is not None and self.takeover_object is None,
                "acting_object": self.acting_object,
                "requests": [dict(f) for f in self._fetches.values()],
                "feed": list(self.feed),
                "questionnaires_total": len(self._questionnaires),
                "questionnaires": [
                    q.as_json() for q in self._questionnaires if q.name not in self._submitted
                ],
            }


@dataclass
class TabletHuman(SimulatedHuman):
    """A human driven by the tablet, with SimulatedHuman's interface and recipe progress.

    Help requests and take-overs wait for the participant's "done" on the tablet (the object is then moved to the
    table in simulation); the take-over button makes `wants_takeover` True for the robot's current action.
    """

    state: TabletState = field(default_factory=TabletState)
    announces_attempts = True  # a person: the robot announces each attempt and waits its take-over window

    def __post_init__(self) -> None:
        super().__post_init__()
        self.state.start_episode([s.instruction for s in self.recipe.steps], self.state.label)

    def request_help(self, object_name: str) -> None:
        for f in self._fetches:
            if f.object_name == object_name and f.kind is FetchReason.INTERVENTION and f.cause != "takeover":
                # a clean-up the participant was asked to do: the robot now asks for it, so it is help
                f.kind, f.cause = FetchReason.HELP, ""
                self.state.add_fetch(object_name, FetchReason.HELP.value)
                return
        if not self.is_fetching(object_name):
            self._fetches.append(_Fetch(object_name, math.inf, FetchReason.HELP))
            self.state.add_fetch(object_name, FetchReason.HELP.value)

    def decide_takeover(self, object_name: str) -> None:
        self.state.set_acting(object_name)

    def wants_takeover(self, object_name: str) -> bool:
        return self.state.wants_takeover(object_name)

    def take_over(self, object_name: str) -> None:
        self.state.clear_takeover()
        if not self.is_fetching(object_name):
            self._fetches.append(_Fetch(object_name, math.inf, FetchReason.INTERVENTION, "takeover"))
            self.state.add_fetch(object_name, FetchReason.INTERVENTION.value)

    def robot_busy(self, busy: bool) -> None:
        super().robot_busy(busy)
        if not busy:
            self.state.set_acting(None)

    def update(self) -> list[Event]:
        now = self.kitchen.sim_time
        confirmed = self.state.pop_confirmed()
        for f in self._fetches:
            if f.object_name in confirmed:
                f.ready_at = now  # the participant has brought it: SimulatedHuman places it this tick
        new = super().update()
        for f in self._fetches:
            if math.isfinite(
                f.ready_at
            ):  # a clean-up SimulatedHuman started: the participant does it instead
                f.ready_at = math.inf
                name, it = f.object_name, it_them(f.object_name)
                said = (
                    f"The robot dropped the {name}: please bring {it} to the table."
                    if f.cause == "dropped"
                    else f"The robot has not fetched the {name} for a while: please bring {it} to the table."
                )
                self.state.add_fetch(name, f.kind.value, said)
        self.state.retain_fetches({f.object_name for f in self._fetches})
        self.state.sync_time(now)
        self.state.sync_recipe(self.step_index, self.step_done)
        return new
