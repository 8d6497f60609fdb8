"""Fast mode: synthetic episodes without physics, for quick simulated studies and tests of the analysis.

A synthetic robot has a true success probability per object (most objects easy, some hard) and a self-confidence
estimate κ̂ that is the truth plus a fixed error (a trained but imperfect κ̂). An episode fetches one object per
recipe step and follows the same rules as the behaviour tree:
- self-confidence on: ask for help when κ̂ < threshold, otherwise act; off: always act;
- after ``max_failures`` failures on the same object, ask for help whatever κ̂ says;
- a failure drops the object with probability ``drop_probability``; the participant then fetches it (an
  intervention, like SimulatedHuman's clean-up);
- the participant may take over any action (the trust model decides).
It emits the same typed events as run_episode, and decides with the same gate and failure rule, so logging and
analysis cannot tell the difference except by the session's ``synthetic`` flag. Simulated times are nominal.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from scone_bt.affordances.types import action_text
from scone_bt.errors import SconeError
from scone_bt.events import (
    ActOutcome,
    ActStarted,
    CleanUpStarted,
    ConfidenceStated,
    DecisionMade,
    Event,
    EventLog,
    EventSink,
    HelpGiven,
    HelpRequested,
    Intervention,
    StepDone,
    TakeOver,
)
from scone_bt.gate.types import DecisionKind
from scone_bt.motion.types import FailureStage
from scone_bt.study.design import Condition
from scone_bt.study.trust import SimulatedParticipant
from scone_bt.trust.estimate import confidence_in_words

__all__ = ["SyntheticRobot", "SyntheticOptions", "run_synthetic_episode"]


@dataclass(frozen=True)
class SyntheticOptions:
    """Fast-mode episode settings. Times in nominal simulated seconds.

    Attributes:
        steps: Recipe steps per episode (one object each).
        confidence_threshold: Ask when κ̂ is below this (self-confidence on).
        max_failures: Failures on one object before the robot asks whatever κ̂ says (the paper used 3).
        drop_probability: Share of failures that drop the object (the participant cleans up).
        act_time_s: Duration of one robot attempt.
        fetch_time_s: Duration of the participant fetching an object.
        trust_aware: As the tree parameter: the robot tracks the person's trust online and, before an act they
            likely over-trust, states its confidence (`ConfidenceStated`).
    """

    steps: int = 5
    confidence_threshold: float = 0.5
    max_failures: int = 3
    drop_probability: float = 0.3
    act_time_s: float = 25.0
    fetch_time_s: float = 6.0
    trust_aware: bool = False

    def __post_init__(self) -> None:
        if self.steps < 1 or self.max_failures < 1:
            raise SconeError("synthetic episodes need steps >= 1 and max_failures >= 1")
        if not 0 <= self.confidence_threshold <= 1 or not 0 <= self.drop_probability <= 1:
            raise SconeError("confidence_threshold and drop_probability must be in [0, 1]")


@dataclass(frozen=True)
class SyntheticRobot:
    """True success probability and κ̂ per object.

    Attributes:
        success: Object name → probability that an attempt succeeds.
        confidence: Object name → the robot's estimate of it (κ̂).
    """

    success: dict[str, float]
    confidence: dict[str, float]

    @classmethod
    def sample(
        cls, objects: Sequence[str], seed: int, hard_share: float = 0.35, kappa_error_sd: float = 0.12
    ) -> SyntheticRobot:
        """A seeded robot: easy objects ~ Beta(6, 2), hard ones ~ Beta(1.5, 4); κ̂ = truth + Normal(0, error)."""
        rng = np.random.default_rng([seed, 7])
        success, confidence = {}, {}
        for name in objects:
            p = rng.beta(1.5, 4.0) if rng.random() < hard_share else rng.beta(6.0, 2.0)
            success[name] = float(p)
            confidence[name] = float(np.clip(p + rng.normal(0.0, kappa_error_sd), 0.02, 0.98))
        return cls(success, confidence)


def _online_trust():  # noqa: ANN202 - an OnlineTrust (the model loads ζ once per process)
    from scone_bt.study.trust import _transfer_model
    from scone_bt.trust.estimate import OnlineTrust
    from scone_bt.trust.transfer import load_fitted

    return OnlineTrust(_transfer_model(load_fitted()))


@dataclass(frozen=True)
class _Episode:
    """What every step of one synthetic episode shares.

    Attributes:
        robot: The synthetic robot (true success and κ̂ per object).
        gate: The gate's options (`GateOptions`) for the episode's condition.
        options: The episode's settings.
        participant: The simulated participant (decides take-overs).
        rng: The episode's outcome draws.
        events: The episode's events so far (failure counts, the summary's fold).
        emit: Sends one event to the log, the caller, the participant and the trust tracker.
        trust: The online trust tracker (`OnlineTrust`), or None when the robot is not trust-aware.
    """

    robot: SyntheticRobot
    gate: Any
    options: SyntheticOptions
    participant: SimulatedParticipant
    rng: np.random.Generator
    events: EventLog
    emit: Callable[[Event], None]
    trust: Any


def _decide(ep: _Episode, step: int, instruction: str, name: str, clock: float) -> DecisionKind:
    """The tree's decision on the step's one action (the gate, then the failure limit), emitted."""
    from scone_bt.gate import decide
    from scone_bt.gate.rules import apply_failure_limit
    from scone_bt.relevance.types import RankedAction

    action = action_text(name)
    conf = ep.robot.confidence[name]
    decision = decide([RankedAction(action, 1.0)], [conf], ep.gate)
    decision = apply_failure_limit(decision, ep.events.failures_of(action), ep.options.max_failures)
    ep.emit(
        DecisionMade(
            clock,
            step,
            instruction,
            action,
            1.0,
            round(conf, 4),
            decision.kind,
            object_name=name,
            reason=decision.reason,
        )
    )
    return decision.kind


def _act(ep: _Episode, name: str, clock: float) -> tuple[float, bool]:
    """One attempt at fetching ``name`` (stating its confidence first when trust-aware); (clock, step done)."""
    action, conf, opts = action_text(name), ep.robot.confidence[name], ep.options
    if ep.trust is not None:
        (estimate,) = ep.trust.estimate(clock, {action: (name, conf)})
        ep.emit(estimate)
        if estimate.risk == "over":
            ep.emit(ConfidenceStated(clock, action, name, confidence_in_words(name, conf), round(conf, 4)))
    ep.emit(ActStarted(clock, action, name, round(conf, 4)))
    if ep.participant.decides_to_take_over():
        clock += 1.0
        ep.emit(TakeOver(clock, action, name))
        clock += opts.fetch_time_s
        ep.emit(Intervention(clock, name, "fetched by the human", "takeover"))
        return clock, True
    clock += opts.act_time_s
    success = bool(ep.rng.random() < ep.robot.success[name])
    if success:
        ep.emit(ActOutcome(clock, action, name, True, None, opts.act_time_s))
        return clock, True
    dropped = bool(ep.rng.random() < opts.drop_probability)
    stage = FailureStage.PLACE if dropped else FailureStage.GRASP
    ep.emit(ActOutcome(clock, action, name, False, stage.value, opts.act_time_s))
    if dropped:
        ep.emit(CleanUpStarted(clock, name, "the robot dropped it"))
        clock += opts.fetch_time_s
        ep.emit(Intervention(clock, name, "fetched by the human", "dropped"))
        return clock, True
    return clock, False


def _step(ep: _Episode, step: int, name: str, clock: float) -> float:
    """One recipe step: decide and act until the object is on the table; returns the clock after it."""
    action = action_text(name)
    instruction = f"Step {step}: bring the {name}."
    done = False
    while not done:
        if _decide(ep, step, instruction, name, clock) is DecisionKind.ASK:
            ep.emit(HelpRequested(clock, action, name))
            clock += ep.options.fetch_time_s
            ep.emit(HelpGiven(clock, name, "fetched by the human"))
            break
        clock, done = _act(ep, name, clock)
    clock += 2.0
    ep.emit(StepDone(clock, instruction))
    return clock


def run_synthetic_episode(
    robot: SyntheticRobot,
    condition: Condition,
    participant: SimulatedParticipant,
    on_event: EventSink,
    seed: int,
    options: SyntheticOptions = SyntheticOptions(),
) -> dict[str, Any]:
    """One synthetic episode; every event goes to on_event (and to the participant's trust); returns a summary.

    Each decision is the tree's: `scone_bt.gate.decide` on the step's one action, then the failure limit
    (`apply_failure_limit`); the counts are the events' fold (`scone_bt.events.summarise`).
    """
    from scone_bt.gate import GateOptions

    rng = np.random.default_rng([seed, 11])
    names = sorted(robot.success)
    if options.steps > len(names):
        raise SconeError(
            f"synthetic episode wants {options.steps} steps but the robot knows {len(names)} objects"
        )
    objects = [str(n) for n in rng.choice(names, size=options.steps, replace=False)]
    gate = GateOptions(
        confidence_threshold=options.confidence_threshold, use_self_confidence=condition is Condition.ON
    )
    events = EventLog()
    trust = _online_trust() if options.trust_aware else None

    def emit(event: Event) -> None:
        events(event)
        on_event(event)
        participant.observe(event)
        if trust is not None:
            trust(event)

    episode = _Episode(robot, gate, options, participant, rng, events, emit, trust)
    clock = 0.0
    for step, name in enumerate(objects, 1):
        clock = _step(episode, step, name, clock)
    stats = events.stats
    return {
        "synthetic": True,
        "completed": True,
        "steps_completed": options.steps,
        "steps_total": options.steps,
        "attempted": stats.attempted,
        "successes": stats.successes,
        "failures": stats.failures,
        "help_requests": stats.help_requests,
        "interventions": stats.interventions,
        "decisions": stats.decisions,
        "sim_time": round(clock, 3),
        "objects": objects,
    }
