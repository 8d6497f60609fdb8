"""What happens in an episode, as typed events.

Behaviours and the human emit these frozen dataclasses to one `EventSink`; the CLI printer
(`scone_bt.episode.printer`), the tablet (`scone_bt.study.ui`), the study log (`scone_bt.study.log`) and the
episode summary consume them. The summary is folded from the events (`summarise`), so a counter cannot disagree
with the stream it counts.

Each event has a ``kind`` (the name the study log stores) and `to_json()` (the stored payload, ``sim_time`` first);
`from_json` reads a stored one back. Two things that were both called "intervention" are now two types: the
robot's action taken over by the human (`TakeOver`, kind ``takeover``) and an object the human fetched on their own
(`Intervention`). Logs written before the split stored a take-over as an ``intervention`` with an ``action`` key;
`from_json` reads those as `TakeOver`.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping
from dataclasses import MISSING, dataclass, field, fields, replace
from functools import reduce
from types import MappingProxyType
from typing import Any, ClassVar

from scone_bt.errors import SconeError
from scone_bt.experience.types import ExecutionContext
from scone_bt.gate.budget import FeltCarry
from scone_bt.gate.types import DecisionKind

__all__ = [
    "Event",
    "EventSink",
    "NO_ROOM",
    "DecisionMade",
    "ActStarted",
    "ActOutcome",
    "ActCancelled",
    "HelpRequested",
    "ClarificationAsked",
    "PlanInfeasible",
    "ProbeAborted",
    "TakeOver",
    "HelpDeclined",
    "HelpGiven",
    "Intervention",
    "INTERVENTION_CAUSES",
    "CleanUpStarted",
    "StepDone",
    "TrustEstimated",
    "ConfidenceStated",
    "EVENT_TYPES",
    "EpisodeStats",
    "fold",
    "summarise",
    "EventLog",
    "from_json",
    "is_legacy_takeover",
]


@dataclass(frozen=True)
class Event:
    """Base of every episode event.

    Attributes:
        sim_time: Simulated seconds since the episode started, when it happened.
    """

    kind: ClassVar[str] = ""
    sim_time: float

    def to_json(self) -> dict[str, Any]:
        """The stored payload: ``sim_time`` (rounded to ms) then the fields under their stored names."""
        out: dict[str, Any] = {"sim_time": round(self.sim_time, 3)}
        for f in fields(self):
            if f.name == "sim_time":
                continue
            out[_JSON_NAMES.get(f.name, f.name)] = _plain(getattr(self, f.name))
        return out


EventSink = Callable[[Event], None]
"""Where behaviours and the human send events."""

_JSON_NAMES = {"object_name": "object", "verdict": "kind"}


def _plain(value: Any) -> Any:
    if isinstance(value, tuple):
        return [_plain(v) for v in value]
    if hasattr(value, "value") and isinstance(value.value, str):  # str enums are stored by value
        return value.value
    return value


@dataclass(frozen=True)
class _ActionEvent(Event):
    """An event about one of the robot's actions: its text and the object it moves."""

    action: str
    object_name: str


@dataclass(frozen=True)
class _HumanFetch(Event):
    """The human and one object; ``detail`` says what happened or why."""

    object_name: str
    detail: str = ""


@dataclass(frozen=True)
class DecisionMade(Event):
    """The gate decided (one per decision cycle).

    Attributes:
        step: The robot's place in the recipe, 1-based.
        instruction: That step's text; past the last one "(every step is served)", or "(past the last step: items
            on the card)" while items of the card no open step names are still fetched.
        action: The chosen action text, or None (idle, clarify).
        relevance: Its cosine similarity (NaN when none).
        confidence: κ̂ for it, in [0, 1] (NaN when none).
        verdict: ACT, ASK (for help), CLARIFY or IDLE (stored as ``kind``).
        need: "now", "later" or "".
        candidates: With CLARIFY, the action texts the robot asks about.
        object_name: The chosen action's object, or None.
        reason: The gate's one-sentence reason.
        explored: ACT on an ε-greedy exploration draw although κ̂ was below the threshold.
        context: The chosen action's execution context as perceived (what a grounded κ̂ saw), or None.
        rule: What made the verdict when it was not κ̂ against the gate's threshold: "failure-limit" (the
            paper's rule: asked after N failures on the action), "infeasible" (no plan exists: known before the
            arm moved), "missing" (the step needs an item the robot cannot see), "declined" (the human declined
            to fetch it: the robot tries itself, or waits), "too-wide" (measured wider than the gripper
            opens), "self-confidence-off" (the
            control condition acted without consulting κ̂), "probe" (the heft test set it back before: asked);
            "" when κ̂ and the threshold decided.
        probe: ACT with the heft test first (κ̂ within the probe band around the threshold; gate.probe).
        planning_s: Wall seconds the robot planned before committing (plan before commit), or None.
    """

    kind: ClassVar[str] = "decision"
    step: int
    instruction: str
    action: str | None
    relevance: float
    confidence: float
    verdict: DecisionKind
    need: str = ""
    candidates: tuple[str, ...] = ()
    object_name: str | None = None
    reason: str = ""
    explored: bool = False
    context: ExecutionContext | None = None
    rule: str = ""
    planning_s: float | None = None
    probe: bool = False

    def to_json(self) -> dict[str, Any]:
        out = super().to_json()
        out["relevance"] = round(self.relevance, 4)
        out["confidence"] = round(self.confidence, 4)
        out["context"] = None if self.context is None else self.context.to_json()
        return out


@dataclass(frozen=True)
class ActStarted(_ActionEvent):
    """The robot starts a pick-and-place; ``confidence`` is κ̂ for it.

    Attributes:
        window_s: Simulated seconds the robot announces the attempt before it moves (the take-over window; 0: it
            moves at once).
    """

    kind: ClassVar[str] = "act"
    confidence: float
    window_s: float = 0.0


@dataclass(frozen=True)
class ActOutcome(_ActionEvent):
    """A pick-and-place ended and was labelled (stored in the experience store before this is emitted).

    Attributes:
        success: The object rests on the table (the robot's outcome sensor).
        stage: Where it failed (a FailureStage value), None on success.
        duration_s: Simulated seconds the attempt took.
        message: The motion system's first line of detail.
        explored: The attempt carried on after a heft test although κ̂ on what it felt was below the threshold,
            on the strict rule's credit (gate.after_probe): counted as explored, like an ε-greedy attempt.
        held_fast: The heft test before it felt the product held fast (gate.probe.held_fast): counted in that
            rule's own record (gate.budget.BudgetCounts.held_fast_record).
        by_feel: It was carried on by feel alone (gate.after_probe): counted in that record's own
            (gate.budget.BudgetCounts.by_feel_record).
        traction: The load over the grip that heft test felt (dimensionless; None: no heft test, or not
            measured): where the attempt sits in that record.
    """

    kind: ClassVar[str] = "outcome"
    success: bool
    stage: str | None
    duration_s: float = 0.0
    message: str = ""
    explored: bool = False
    held_fast: bool = False
    by_feel: bool = False
    traction: float | None = None


@dataclass(frozen=True)
class ProbeAborted(_ActionEvent):
    """The heft test set the product back where it stood (an *aborted* attempt): not an attempt of the failure
    budget, not a failure; the person has to fetch it, so it is asked for next (counted in the help rate).

    Attributes:
        reason: The robot's words ("the jar slips in my fingers").
        duration_s: Simulated seconds from the start of the motion to the hand back home.
        probe_s: Simulated seconds the probe itself took (lift, hold, set-down, release, leaving).
        load_n: The load the fingers felt, newtons.
    """

    kind: ClassVar[str] = "aborted"
    reason: str
    duration_s: float = 0.0
    probe_s: float = 0.0
    load_n: float = 0.0


@dataclass(frozen=True)
class PlanInfeasible(_ActionEvent):
    """The robot planned before committing and no plan exists in this scene: stored as experience, not an attempt.

    Attributes:
        reason: Which planning stage ran out of options (a PlanFailureReason value).
        message: The planner's one line.
    """

    kind: ClassVar[str] = "infeasible"
    reason: str
    message: str = ""


@dataclass(frozen=True)
class ActCancelled(_ActionEvent):
    """The attempt ended cancelled (the human took over): no label, κ̂ unchanged."""

    kind: ClassVar[str] = "cancelled"


@dataclass(frozen=True)
class HelpRequested(_ActionEvent):
    """ASK-HELP: the robot asks the human to fetch the object.

    Attributes:
        reason: Why, when the gate did not decide it (e.g. the object stuck in the gripper); "" for the gate's ask,
            whose reason its DecisionMade carries.
    """

    kind: ClassVar[str] = "help_request"
    reason: str = ""


@dataclass(frozen=True)
class ClarificationAsked(Event):
    """ASK-CLARIFY: the robot asked which of ``candidates`` step ``step`` (1-based) means; ``answer`` is the reply."""

    kind: ClassVar[str] = "clarification"
    candidates: tuple[str, ...]
    answer: tuple[str, ...]
    step: int


@dataclass(frozen=True)
class TakeOver(_ActionEvent):
    """The human took over the robot's action on ``object_name`` (the robot cancels it)."""

    kind: ClassVar[str] = "takeover"


@dataclass(frozen=True)
class HelpGiven(_HumanFetch):
    """The human put an object the robot asked for on the table."""

    kind: ClassVar[str] = "help"


@dataclass(frozen=True)
class HelpDeclined(_HumanFetch):
    """The human declined to fetch an object the robot asked for ("try it yourself"); ``detail`` says so."""

    kind: ClassVar[str] = "declined"


NO_ROOM = "the human found no room on the table for it"
"""`HelpDeclined.detail` when the human declines because the product fits nowhere on the table, not as a "try it
yourself"."""


INTERVENTION_CAUSES: Mapping[str, str] = MappingProxyType(
    {
        "takeover": "the participant took over the robot's action and brought the item",
        "dropped": "the participant brought an item the robot had dropped, unasked",
        "idle": "the participant brought an item the robot neither fetched nor asked for",
        "by-hand": "the participant did a step by hand",
    }
)
"""Why an intervention counts, by cause: something the participant did that the robot did not ask for. Time the
robot waits on its own help request never makes one."""


@dataclass(frozen=True)
class Intervention(_HumanFetch):
    """The human put an object on the table unasked (after a take-over, a drop or a long idle robot).

    Attributes:
        cause: Why it counts, a key of `INTERVENTION_CAUSES` ("" only in logs written before causes were stored).
    """

    kind: ClassVar[str] = "intervention"
    cause: str = ""


@dataclass(frozen=True)
class CleanUpStarted(_HumanFetch):
    """The human starts fetching an object on their own; ``detail`` says why."""

    kind: ClassVar[str] = "fetching"


@dataclass(frozen=True)
class StepDone(Event):
    """The human finished a recipe step; ``detail`` is its text."""

    kind: ClassVar[str] = "step_done"
    detail: str = ""

    def to_json(self) -> dict[str, Any]:
        return {"sim_time": round(self.sim_time, 3), "object": None, "detail": self.detail}


@dataclass(frozen=True)
class TrustEstimated(_ActionEvent):
    """The robot's estimate of how much the person trusts it with an action, beside its own κ̂
    (`scone_bt.trust.estimate`: the trust-transfer model fitted to human ratings, fed what the person saw).

    Attributes:
        trust: Predicted trust of the person that the action succeeds, in [0, 1].
        confidence: κ̂ for the action, in [0, 1].
        risk: "over" (the person likely trusts it more than κ̂ warrants), "under" (they saw similar actions fail
            but κ̂ is high) or "" (neither).
    """

    kind: ClassVar[str] = "trust_estimate"
    trust: float
    confidence: float
    risk: str = ""


@dataclass(frozen=True)
class ConfidenceStated(_ActionEvent):
    """The robot says its confidence in words before an act the person likely over-trusts (tree parameter
    ``trust_aware: true``).

    Attributes:
        text: What it says.
        confidence: κ̂ it states, in [0, 1].
    """

    kind: ClassVar[str] = "confidence_stated"
    text: str
    confidence: float


EVENT_TYPES: Mapping[str, type[Event]] = MappingProxyType(
    {
        cls.kind: cls
        for cls in (
            DecisionMade,
            ActStarted,
            ActOutcome,
            ProbeAborted,
            PlanInfeasible,
            ActCancelled,
            HelpRequested,
            ClarificationAsked,
            TakeOver,
            HelpGiven,
            HelpDeclined,
            Intervention,
            CleanUpStarted,
            StepDone,
            TrustEstimated,
            ConfidenceStated,
        )
    }
)
"""Stored kind → event type."""

_STORED_NAMES = {v: k for k, v in _JSON_NAMES.items()}


def is_legacy_takeover(kind: str, data: Mapping[str, Any]) -> bool:
    """A take-over as logs written before `TakeOver` stored it: an ``intervention`` with an ``action``."""
    return kind == "intervention" and "action" in data and "detail" not in data


def from_json(kind: str, data: Mapping[str, Any]) -> Event:
    """The event a study log row stores (`Event.to_json` read back).

    Raises:
        SconeError: an unknown kind, or a payload without a field the kind needs.
    """
    if is_legacy_takeover(kind, data):
        kind = TakeOver.kind
    cls = EVENT_TYPES.get(kind)
    if cls is None:
        raise SconeError(f"unknown event kind {kind!r}; valid: {', '.join(sorted(EVENT_TYPES))}")
    values: dict[str, Any] = {}
    for f in fields(cls):
        stored = _JSON_NAMES.get(f.name, f.name)
        if stored in data:
            values[f.name] = data[stored]
        elif f.default is MISSING and f.default_factory is MISSING:
            raise SconeError(f"event {kind!r} lacks {stored!r} (has: {', '.join(map(str, data)) or 'none'})")
    if cls is DecisionMade:
        values["verdict"] = DecisionKind(values["verdict"])
        values["candidates"] = tuple(values.get("candidates") or ())
        for key in ("relevance", "confidence"):
            values[key] = math.nan if values[key] is None else float(values[key])
        raw = values.get("context")
        values["context"] = (
            None if raw is None else ExecutionContext.from_json(raw, "decision event: context")
        )
    if cls is ClarificationAsked:
        values["candidates"], values["answer"] = tuple(values["candidates"]), tuple(values["answer"])
    return cls(**values)


# ------------------------------------------------------------------------------------------------ the summary
@dataclass(frozen=True)
class EpisodeStats:
    """The counters of an episode, folded from its events (`fold`, `summarise`).

    Attributes:
        decisions: Decisions the gate made.
        attempted: Pick-and-places started.
        successes: Attempts labelled a success.
        failures: Attempts labelled a failure.
        help_requests: ASK-HELP requests.
        help_declined: Help requests the human declined.
        clarifications: ASK-CLARIFY questions.
        cancelled: Attempts cancelled because the human took over.
        takeovers: Take-overs the human made.
        help_given: Objects the human fetched on request.
        interventions: Objects the human fetched unasked.
        steps_done: Recipe steps the human finished.
        failures_by_stage: FailureStage value → failures.
        failures_by_action: Action text → failures.
        explored_failures: Failed exploratory attempts (ε-greedy or the budget's exploration).
        exploring: The last decision was an exploratory ACT (its outcome is counted as explored).
        aborted: Attempts the heft test set back (`ProbeAborted`): neither successes nor failures.
        held_fast: The attempts after a heft test that felt the product held fast (`ActOutcome.held_fast`), in
            order, each with the load it felt, its outcome and whether it was carried by feel (an older log's
            failure without the load is kept at load 0, against every load; its success without one is left out).
        probe_reasons: Action text → why its probe set it back (the last one).
    """

    decisions: int = 0
    attempted: int = 0
    successes: int = 0
    failures: int = 0
    help_requests: int = 0
    help_declined: int = 0
    clarifications: int = 0
    cancelled: int = 0
    takeovers: int = 0
    help_given: int = 0
    interventions: int = 0
    steps_done: int = 0
    failures_by_stage: Mapping[str, int] = field(default_factory=dict)
    failures_by_action: Mapping[str, int] = field(default_factory=dict)
    explored_failures: int = 0
    exploring: bool = False
    aborted: int = 0
    probe_reasons: Mapping[str, str] = field(default_factory=dict)
    held_fast: tuple[FeltCarry, ...] = ()


def _bump(counts: Mapping[str, int], key: str) -> dict[str, int]:
    return {**counts, key: counts.get(key, 0) + 1}


_COUNTERS: Mapping[type[Event], str] = MappingProxyType(
    {
        DecisionMade: "decisions",
        ActStarted: "attempted",
        HelpRequested: "help_requests",
        ClarificationAsked: "clarifications",
        ActCancelled: "cancelled",
        TakeOver: "takeovers",
        HelpGiven: "help_given",
        HelpDeclined: "help_declined",
        Intervention: "interventions",
        StepDone: "steps_done",
    }
)


def fold(stats: EpisodeStats, event: Event) -> EpisodeStats:
    """The stats after one more event (pure)."""
    if isinstance(event, DecisionMade):
        explored = event.explored and event.verdict is DecisionKind.ACT
        return replace(stats, decisions=stats.decisions + 1, exploring=explored)
    if isinstance(event, ActOutcome):
        if stats.exploring or event.explored:
            stats = replace(stats, explored_failures=stats.explored_failures + (not event.success))
        carry = FeltCarry.of(event.held_fast, event.traction, event.success, event.by_feel)
        if carry is not None:
            stats = replace(stats, held_fast=(*stats.held_fast, carry))
        if event.success:
            return replace(stats, successes=stats.successes + 1)
        stage = event.stage or "place"
        return replace(
            stats,
            failures=stats.failures + 1,
            failures_by_stage=_bump(stats.failures_by_stage, stage),
            failures_by_action=_bump(stats.failures_by_action, event.action),
        )
    if isinstance(event, ProbeAborted):
        return replace(
            stats,
            aborted=stats.aborted + 1,
            exploring=False,
            probe_reasons={**stats.probe_reasons, event.action: event.reason},
        )
    name = _COUNTERS.get(type(event))
    return stats if name is None else replace(stats, **{name: getattr(stats, name) + 1})


def summarise(events: Iterable[Event]) -> EpisodeStats:
    """The episode's counters: every event folded in order."""
    return reduce(fold, events, EpisodeStats())


class EventLog:
    """An `EventSink` that keeps the events, their running `stats`, and passes each one on to listeners.

    Args:
        listeners: Called with each event after it is recorded (the printer, the tablet, the study log, ...).
    """

    def __init__(self, *listeners: EventSink) -> None:
        self.events: list[Event] = []
        self.stats = EpisodeStats()
        self._listeners = list(listeners)

    def listen(self, listener: EventSink) -> None:
        """Add one more listener."""
        self._listeners.append(listener)

    def __call__(self, event: Event) -> None:
        self.events.append(event)
        self.stats = fold(self.stats, event)
        for listener in self._listeners:
            listener(event)

    def failures_of(self, action: str) -> int:
        """Failed attempts of this action so far in the episode (what the failure-limit rule reads)."""
        return self.stats.failures_by_action.get(action, 0)

    def budget_counts(self) -> tuple[int, int, int]:
        """(labelled attempts, their failures, failed explorations) so far: what the failure budget reads."""
        s = self.stats
        return s.successes + s.failures, s.failures, s.explored_failures

    def held_fast_carries(self) -> tuple[FeltCarry, ...]:
        """The attempts after a heft test that felt the product held fast so far, with the load each felt."""
        return self.stats.held_fast

    def probe_reason(self, action: str) -> str | None:
        """Why the heft test set this action's product back in this episode, or None if it never did."""
        return self.stats.probe_reasons.get(action)
