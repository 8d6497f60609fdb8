"""Expectations checked on an episode's typed event stream and its final state (pure: no simulator).

Each check returns None when the expectation holds, else an `ExpectationFailure` naming the expectation, the
control tick and simulated time where it broke, and the events around that point.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any, TypeVar

from scone_bt.events import ActOutcome, ActStarted, DecisionMade, Event, HelpRequested, StepDone
from scone_bt.scenario.model import (
    AsksBeforeAttempt,
    Completes,
    CompletesStep,
    Count,
    DecisionsMatch,
    EventMatch,
    Kappa,
    MaxFailures,
    NeverAttempts,
    NoRepeatedFailure,
    OnTable,
)

__all__ = [
    "CHECKS",
    "Episode",
    "Record",
    "Outcome",
    "ExpectationFailure",
    "check",
    "describe",
    "matches",
    "decision_tokens",
    "event_line",
]

CONTEXT_EVENTS = 3
"""Events shown on each side of the point where an expectation broke."""


@dataclass(frozen=True)
class Record:
    """One event as the scenario saw it: the control tick it happened in (0: before the first) and the event."""

    tick: int
    event: Event


@dataclass(frozen=True)
class Outcome:
    """The end of the episode: the recipe done or not, steps done, and the products on the table (ground truth)."""

    completed: bool
    steps_completed: int
    on_table: Mapping[str, bool]
    ticks: int
    sim_time: float


@dataclass(frozen=True)
class ExpectationFailure:
    """An expectation that did not hold.

    Attributes:
        expectation: Its name (the ``name:`` given, else the expectation as written).
        problem: What happened instead (one sentence).
        tick: The control tick where it broke (the last one when it broke at the end).
        sim_time: Simulated seconds at that point.
        around: The events around that point, one line each.
    """

    expectation: str
    problem: str
    tick: int
    sim_time: float
    around: tuple[str, ...]

    def format(self) -> str:
        head = f"expectation '{self.expectation}' failed at tick {self.tick} (t={self.sim_time:.1f} s): {self.problem}"
        return "\n".join([head, *(f"    {line}" for line in self.around)])


def describe(expectation: Any) -> str:
    """The expectation as written (``never_attempts: salt``), or its ``name:``."""
    if expectation.name:
        return expectation.name
    data = expectation.model_dump(exclude_none=True, exclude={"name"})
    parts = []
    for key, value in data.items():
        if isinstance(value, dict):
            value = "{" + ", ".join(f"{k}: {v}" for k, v in value.items()) + "}"
        parts.append(f"{key}: {value}")
    return ", ".join(parts)


def _field(event: Event, name: str) -> Any:
    if name == "object":
        return getattr(event, "object_name", None)
    if name == "verdict":
        v = getattr(event, "verdict", None)
        return None if v is None else str(v)
    return getattr(event, name, None)


def matches(event: Event, match: EventMatch) -> bool:
    """Whether the event is of the kind and has every field value the match gives."""
    if event.kind != match.kind:
        return False
    for key in ("object", "success", "stage", "verdict", "rule", "step", "explored"):
        wanted = getattr(match, key)
        if wanted is not None and _field(event, key) != wanted:
            return False
    return True


def event_line(record: Record) -> str:
    """One event as a line: tick, time, kind and what it is about."""
    e = record.event
    bits = [f"tick {record.tick:>4}", f"t={e.sim_time:7.1f} s", f"{e.kind:<13}"]
    if isinstance(e, DecisionMade):
        conf = "" if math.isnan(e.confidence) else f" κ̂={e.confidence:.2f}"
        bits.append(f"{e.verdict.label} {e.object_name or '-'}{conf}" + (f" rule={e.rule}" if e.rule else ""))
    elif isinstance(e, ActOutcome):
        bits.append(f"{e.object_name} {'success' if e.success else f'FAILED at {e.stage}'}")
    elif hasattr(e, "object_name"):
        detail = getattr(e, "detail", "")
        bits.append(str(e.object_name) + (f" ({detail})" if detail else ""))
    elif isinstance(e, StepDone):
        bits.append(e.detail[:60])
    else:
        bits.append(str({k: v for k, v in e.to_json().items() if k != "sim_time"})[:80])
    return "  ".join(bits)


def decision_tokens(records: Sequence[Record]) -> str:
    """The decision sequence as ``verdict:object`` tokens (spaces in names become ``_``), space-separated."""
    out = []
    for r in records:
        e = r.event
        if isinstance(e, DecisionMade):
            out.append(f"{e.verdict.value}:{(e.object_name or '-').replace(' ', '_')}")
    return " ".join(out)


def _around(records: Sequence[Record], index: int) -> tuple[str, ...]:
    lo, hi = max(0, index - CONTEXT_EVENTS), min(len(records), index + CONTEXT_EVENTS + 1)
    return tuple(("→ " if i == index else "  ") + event_line(records[i]) for i in range(lo, hi))


def _fail(
    label: str, problem: str, records: Sequence[Record], index: int | None, end: Outcome
) -> ExpectationFailure:
    if index is None or not records:
        around = _around(records, len(records) - 1) if records else ()
        return ExpectationFailure(label, problem, end.ticks, end.sim_time, tuple(around))
    r = records[index]
    return ExpectationFailure(label, problem, r.tick, r.event.sim_time, _around(records, index))


def _first(records: Sequence[Record], pred: Any, start: int = 0) -> int | None:
    return next((i for i in range(start, len(records)) if pred(records[i].event)), None)


@dataclass(frozen=True)
class Episode:
    """What an expectation is checked on: the event records and the end, and how its failures are labelled."""

    label: str
    records: Sequence[Record]
    end: Outcome

    def fail(self, problem: str, index: int | None) -> ExpectationFailure:
        """A failure at record ``index`` (None: at the end of the episode)."""
        return _fail(self.label, problem, self.records, index, self.end)

    def first(self, pred: Callable[[Event], bool], start: int = 0) -> int | None:
        """The index of the first record from ``start`` whose event satisfies ``pred``."""
        return _first(self.records, pred, start)


Rule = Callable[[Any, Episode], "ExpectationFailure | None"]
"""An expectation model's check: None when it holds on the episode, else the failure."""

CHECKS: dict[type[Any], Rule] = {}
"""Expectation model (`scenario.model.EXPECTATION_KINDS`) → its check."""

_M = TypeVar("_M")


def _checks(model: type[_M]) -> Callable[[Callable[[_M, Episode], ExpectationFailure | None]], Rule]:
    """Register the decorated function as the check of ``model``."""

    def register(rule: Callable[[_M, Episode], ExpectationFailure | None]) -> Rule:
        CHECKS[model] = rule
        return rule

    return register


def check(expectation: Any, records: Sequence[Record], end: Outcome) -> ExpectationFailure | None:
    """None if the expectation holds on this episode, else what broke and where."""
    rule = CHECKS.get(type(expectation))
    if rule is None:
        raise TypeError(f"unknown expectation {type(expectation).__name__}")
    return rule(expectation, Episode(describe(expectation), records, end))


@_checks(AsksBeforeAttempt)
def _asks_before_attempt(ex: AsksBeforeAttempt, ep: Episode) -> ExpectationFailure | None:
    name = ex.asks_before_attempt
    ask = ep.first(lambda e: isinstance(e, HelpRequested) and e.object_name == name)
    act = ep.first(lambda e: isinstance(e, ActStarted) and e.object_name == name)
    if act is not None and (ask is None or act < ask):
        return ep.fail(f"the robot attempted {name!r} before asking for help with it", act)
    if ask is None:
        return ep.fail(f"the robot never asked for help with {name!r}", None)
    return None


@_checks(NeverAttempts)
def _never_attempts(ex: NeverAttempts, ep: Episode) -> ExpectationFailure | None:
    name = ex.never_attempts
    act = ep.first(lambda e: isinstance(e, ActStarted) and e.object_name == name)
    return None if act is None else ep.fail(f"the robot attempted {name!r}", act)


@_checks(CompletesStep)
def _completes_step(ex: CompletesStep, ep: Episode) -> ExpectationFailure | None:
    done = [i for i, r in enumerate(ep.records) if isinstance(r.event, StepDone)]
    k = ex.completes_step
    if len(done) < k:
        return ep.fail(f"step {k} was never done ({len(done)} steps done)", None)
    t = ep.records[done[k - 1]].event.sim_time
    if ex.within_s is not None and t > ex.within_s:
        return ep.fail(f"step {k} was done at {t:.1f} s, after {ex.within_s:g} s", done[k - 1])
    return None


@_checks(Completes)
def _completes(ex: Completes, ep: Episode) -> ExpectationFailure | None:
    end = ep.end
    if end.completed != ex.completes:
        what = "was done" if end.completed else f"was not done ({end.steps_completed} steps done)"
        return ep.fail(f"the recipe {what}", None)
    if ex.completes and ex.within_s is not None:
        last = max((i for i, r in enumerate(ep.records) if isinstance(r.event, StepDone)), default=None)
        t = ep.records[last].event.sim_time if last is not None else end.sim_time
        if t > ex.within_s:
            return ep.fail(f"the recipe was done at {t:.1f} s, after {ex.within_s:g} s", last)
    return None


@_checks(MaxFailures)
def _max_failures(ex: MaxFailures, ep: Episode) -> ExpectationFailure | None:
    failed = [
        i
        for i, r in enumerate(ep.records)
        if isinstance(r.event, ActOutcome)
        and not r.event.success
        and (ex.object is None or r.event.object_name == ex.object)
    ]
    if len(failed) > ex.max_failures:
        return ep.fail(f"{len(failed)} failures, more than {ex.max_failures}", failed[ex.max_failures])
    return None


@_checks(Kappa)
def _kappa(ex: Kappa, ep: Episode) -> ExpectationFailure | None:
    start = 0
    after = ex.after
    if after is not None:
        hit = ep.first(lambda e: matches(e, after))
        if hit is None:
            return ep.fail(f"the event it waits for ({describe_match(after)}) never happened", None)
        start = hit + 1
    i = ep.first(
        lambda e: isinstance(e, DecisionMade) and e.object_name == ex.kappa and not math.isnan(e.confidence),
        start,
    )
    if i is None:
        return ep.fail(f"no decision about {ex.kappa!r} followed", None)
    decision = ep.records[i].event
    assert isinstance(decision, DecisionMade)  # what ep.first looked for
    value = decision.confidence
    if ex.below is not None and not value < ex.below:
        return ep.fail(f"κ̂ was {value:.3f}, not below {ex.below:g}", i)
    if ex.above is not None and not value > ex.above:
        return ep.fail(f"κ̂ was {value:.3f}, not above {ex.above:g}", i)
    return None


@_checks(NoRepeatedFailure)
def _no_repeated_failure(ex: NoRepeatedFailure, ep: Episode) -> ExpectationFailure | None:
    seen: set[tuple[str, str | None]] = set()
    for i, r in enumerate(ep.records):
        e = r.event
        if isinstance(e, ActOutcome) and not e.success:
            key = (e.action, e.stage)
            if key in seen:
                return ep.fail(f"{e.action!r} failed at {e.stage} again", i)
            seen.add(key)
    return None


@_checks(DecisionsMatch)
def _decisions_match(ex: DecisionsMatch, ep: Episode) -> ExpectationFailure | None:
    tokens = decision_tokens(ep.records)
    if re.search(ex.decisions_match, tokens) is None:
        shown = tokens if len(tokens) <= 300 else tokens[:297] + "..."
        return ep.fail(f"the decisions were: {shown or '(none)'}", None)
    return None


@_checks(Count)
def _count(ex: Count, ep: Episode) -> ExpectationFailure | None:
    hits = [i for i, r in enumerate(ep.records) if matches(r.event, ex.count)]
    if ex.max is not None and len(hits) > ex.max:
        return ep.fail(f"{len(hits)} matching events, more than {ex.max}", hits[ex.max])
    if len(hits) < ex.min:
        return ep.fail(f"{len(hits)} matching events, fewer than {ex.min}", None)
    return None


@_checks(OnTable)
def _on_table(ex: OnTable, ep: Episode) -> ExpectationFailure | None:
    off = [n for n in ex.on_table if not ep.end.on_table.get(n, False)]
    return None if not off else ep.fail(f"not on the table at the end: {', '.join(off)}", None)


def describe_match(match: EventMatch) -> str:
    return ", ".join(f"{k}: {v}" for k, v in match.model_dump(exclude_none=True).items())
