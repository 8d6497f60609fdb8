"""The episode's log lines, as the CLI prints them, made from its events."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import TYPE_CHECKING

from scone_bt.affordances.types import object_of_action
from scone_bt.events import (
    ActCancelled,
    ActOutcome,
    ClarificationAsked,
    DecisionMade,
    Event,
    HelpRequested,
    ProbeAborted,
)
from scone_bt.gate.types import DecisionKind
from scone_bt.motion.types import PLACED

if TYPE_CHECKING:
    from scone_bt.behaviours.options import BehaviourOptions

__all__ = [
    "RULE_LABELS",
    "condition_line",
    "decision_line",
    "percent",
    "promise_words",
    "rule_note",
    "shown_confidence",
    "LinePrinter",
]

RULE_LABELS = {
    "failure-limit": "failure rule",
    "self-confidence-off": "self-confidence off",
    "infeasible": "infeasible",
    "missing": "missing",
    "declined": "help declined",
    "too-wide": "too wide",
}
"""How a line names each `DecisionMade.rule` (a rule not listed is shown by its own name)."""


def promise_words(strict: bool) -> str:
    """How the failure budget is kept: over the long run (gate.budget bounds the excess failures, not zero in every
    episode), and with the strict promise (``exploration_credit``) the robot explores only on credit its successes
    earned (while one more failure keeps failures ≤ α × attempts + 1: gate.budget.has_credit). A confident attempt
    needs no credit and can still fail, so neither wording says the rate holds in every episode."""
    return "kept over the long run; explores only on earned credit" if strict else "kept over the long run"


def condition_line(options: BehaviourOptions) -> str:
    """The condition an episode runs in: self-confidence on (κ̂ and its threshold, or the failure budget, how it
    is kept and whether the robot hefts what it is unsure of) or off, and the failure rule.

    ``options`` must be resolved (`BehaviourOptions.resolve`).
    """
    n = options.max_failures_per_action
    failures = f"ask after {n} failure{'' if n == 1 else 's'} on one action"
    if not options.use_self_confidence:
        return f"self-confidence OFF (the paper's control: always act, {failures})"
    if options.gate == "budget":
        rate = options.target_failure_rate
        assert rate is not None and options.probe is not None  # resolved: every tree parameter is set
        heft = "; hefts what it is unsure of" if options.probe.enabled else ""
        return (
            f"self-confidence on ({options.estimator}, failure budget: {percent(rate)} "
            f"of attempts, {promise_words(bool(options.exploration_credit))}{heft}), {failures}"
        )
    return f"self-confidence on ({options.estimator}, threshold {options.confidence_threshold:g}), {failures}"


def percent(share: float) -> str:
    """A share as a percentage with the digits it has (0.004 is "0.4%", not "0%"; 0.15 is "15%")."""
    return f"{round(share * 100, 6):g}%"


def rule_note(event: DecisionMade) -> str:
    """The mark of a line a rule decided, not κ̂ against the threshold ("" when κ̂ did).

    For example "(failure rule: failed 3 times on this action)".
    """
    if not event.rule:
        return ""
    label = RULE_LABELS.get(event.rule, event.rule)
    if event.rule == "self-confidence-off":  # its reason only repeats the label
        return f"({label}: acts whatever κ̂ says)"
    return f"({label}: {event.reason})" if event.reason else f"({label})"


def decision_line(event: DecisionMade, steps_total: int) -> str:
    """One decision: the robot's step, the step's text, the action or question, relevance, κ̂ and the verdict."""
    instruction = event.instruction
    short = instruction if len(instruction) <= 48 else instruction[:45] + "..."
    if event.verdict is DecisionKind.CLARIFY:
        target = "which: " + " | ".join(object_of_action(c) for c in event.candidates) + "?"
    elif event.verdict is DecisionKind.IDLE and event.reason.startswith("waiting: "):
        target = "(" + event.reason + ")"
    else:
        target = event.action or "(none)"
    note = "  (needed later)" if event.need == "later" and event.action else ""
    if event.explored:  # κ̂ below the threshold: the robot tries it to learn (ε-greedy)
        note = "  (exploring)" + note
    if event.probe and event.verdict is DecisionKind.ACT:  # κ̂ unsure: a heft test before it commits
        note = "  (heft first)" + note
    if event.rule:  # a rule, not κ̂, made the verdict: the line must not read as κ̂'s call
        shown = target == "(" + event.reason + ")"  # the reason is already the target
        note += "  " + (f"({RULE_LABELS.get(event.rule, event.rule)})" if shown else rule_note(event))
    return (
        f"[step {event.step}/{steps_total}] {short!r:52} -> {target:28} "
        f"rel {_number(event.relevance):>5}  conf {shown_confidence(event):>4}  {event.verdict.label}{note}"
    )


def _number(value: float) -> str:
    """Two decimals, or "--" where the decision has no such number (a rule decided about an unseen item)."""
    return "--" if math.isnan(value) else f"{value:.2f}"


def shown_confidence(event: DecisionMade) -> str:
    """κ̂ with two decimals, rounded toward the side of the threshold the gate found it on.

    Plain rounding printed "conf 0.93 ASK-HELP" under "threshold 0.93" for a κ̂ of 0.928: an act on κ̂ rounds up
    (κ̂ ≥ threshold), an ask or an exploration on κ̂ rounds down (κ̂ < threshold), so the line never contradicts
    its verdict; where a rule decided, it rounds to nearest. Either way it is within 0.01 of κ̂.
    """
    conf = event.confidence
    if math.isnan(conf):
        return "--"
    hundredths = conf * 100
    if (
        abs(hundredths - round(hundredths)) < 1e-9 or event.rule
    ):  # exact to the print (0.93 * 100 is 93.000…01)
        return f"{conf:.2f}"
    if event.verdict is DecisionKind.ACT and not event.explored:
        return f"{math.ceil(hundredths) / 100:.2f}"
    if event.verdict is DecisionKind.ASK or event.explored:
        return f"{math.floor(hundredths) / 100:.2f}"
    return f"{conf:.2f}"


class LinePrinter:
    """An event listener that prints decisions, clarifications and outcomes as lines.

    A run of identical idle decisions is printed once, then counted ("… the same N more times", at the next
    different decision and at `flush`); `lines` keeps every decision line (the summary's decision log), and
    `rules` counts the decisions each rule other than κ̂ made (`DecisionMade.rule`).
    """

    def __init__(self, printer: Callable[[str], None], steps_total: int) -> None:
        self.printer = printer
        self.steps_total = steps_total
        self.lines: list[str] = []
        self.rules: dict[str, int] = {}
        self._last: str | None = None
        self._repeats = 0

    def __call__(self, event: Event) -> None:
        if isinstance(event, DecisionMade):
            line = decision_line(event, self.steps_total)
            self.lines.append(line)
            if event.rule:
                self.rules[event.rule] = self.rules.get(event.rule, 0) + 1
            if event.verdict is DecisionKind.IDLE and line == self._last:
                self._repeats += 1
                return
            self.flush()
            self._last = line
            self.printer(line)
        elif isinstance(event, ClarificationAsked):
            said = ", ".join(event.answer) or "none of those"
            self.printer(f"    ? asked which of {', '.join(event.candidates)}: the human says {said}")
        elif isinstance(event, ActOutcome):
            if event.success:
                # The outcome's notes (another place spot was taken during the carry) follow the line.
                notes = event.message[len(PLACED) :] if event.message.startswith(PLACED) else ""
                self.printer(
                    f"    + success: {event.object_name} is on the table ({event.duration_s:.1f} s){notes}"
                )
            else:
                self.printer(f"    x failure at {event.stage}: {event.message}")
        elif isinstance(event, ProbeAborted):
            self.printer(f"    - set back after the probe: {event.reason} ({event.probe_s:.1f} s hefting it)")
        elif isinstance(event, ActCancelled):
            self.printer(f"    ~ the human took over: {event.action}")
        elif isinstance(event, HelpRequested) and event.reason:  # the gate's asks print as decisions
            self.printer(f"    ? asked for help: {event.reason}")

    def flush(self) -> None:
        """Print the count of repeated idle decisions not yet printed."""
        if self._repeats:
            self.printer(f"    … the same {self._repeats} more time{'s' if self._repeats > 1 else ''}")
        self._repeats = 0
