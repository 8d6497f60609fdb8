"""Fast mode: synthetic episodes without physics, for quick simulated studies and tests of the analysis.

A synthetic robot has a true success probability per object (most objects easy, some hard) and a self-confidence
estimate κ̂ that is the truth plus a fixed error (a trained but imperfect κ̂). An episode fetches one object per
recipe step and follows the same rules as the behaviour tree:
- self-confidence on: ask for help when κ̂ < threshold, otherwise act; off: always act;
- after ``max_failures`` failures on the same object, ask for help whatever κ̂ says;
- a failure drops the object with probability ``drop_probability``; the participant then fetches it (an
  intervention, like SimulatedHuman's clean-up);
- the participant may take over any action (the trust model decides).
It emits the same events, with the same fields, as run_episode, so logging and analysis cannot tell the difference
except by the session's ``synthetic`` flag. Simulated times are nominal.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from scone_bt.errors import SconeError
from scone_bt.study.design import Condition
from scone_bt.study.trust import SimulatedParticipant

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
    """

    steps: int = 5
    confidence_threshold: float = 0.5
    max_failures: int = 3
    drop_probability: float = 0.3
    act_time_s: float = 25.0
    fetch_time_s: float = 6.0

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


def run_synthetic_episode(
    robot: SyntheticRobot,
    condition: Condition,
    participant: SimulatedParticipant,
    on_event: Callable[[str, dict[str, Any]], None],
    seed: int,
    options: SyntheticOptions = SyntheticOptions(),
) -> dict[str, Any]:
    """One synthetic episode; every event goes to on_event (and to the participant's trust); returns a summary."""
    rng = np.random.default_rng([seed, 11])
    names = sorted(robot.success)
    if options.steps > len(names):
        raise SconeError(
            f"synthetic episode wants {options.steps} steps but the robot knows {len(names)} objects"
        )
    objects = [str(n) for n in rng.choice(names, size=options.steps, replace=False)]
    clock = 0.0
    counts = {
        "attempted": 0,
        "successes": 0,
        "failures": 0,
        "help_requests": 0,
        "interventions": 0,
        "decisions": 0,
    }

    def emit(event: str, **data: Any) -> None:
        payload = {"sim_time": round(clock, 3), **data}
        on_event(event, payload)
        participant.observe(event, payload)

    for step, name in enumerate(objects, 1):
        action = f"Put {name} on table"
        instruction = f"Step {step}: bring the {name}."
        failures = 0
        while True:
            conf = robot.confidence[name]
            ask = (
                condition is Condition.ON and conf < options.confidence_threshold
            ) or failures >= options.max_failures
            counts["decisions"] += 1
            emit(
                "decision",
                step=step,
                instruction=instruction,
                action=action,
                relevance=1.0,
                confidence=round(conf, 4),
                kind="ask" if ask else "act",
            )
            if ask:
                counts["help_requests"] += 1
                emit("help_request", action=action, object=name)
                clock += options.fetch_time_s
                emit("help", object=name, detail="fetched by the human")
                break
            counts["attempted"] += 1
            emit("act", action=action, object=name, confidence=round(conf, 4))
            if participant.decides_to_take_over():
                clock += 1.0
                emit("intervention", action=action, object=name)
                clock += options.fetch_time_s
                counts["interventions"] += 1
                emit("intervention", object=name, detail="fetched by the human")
                break
            clock += options.act_time_s
            success = bool(rng.random() < robot.success[name])
            if success:
                counts["successes"] += 1
                emit("outcome", action=action, object=name, success=True, stage=None)
                break
            failures += 1
            counts["failures"] += 1
            dropped = bool(rng.random() < options.drop_probability)
            emit("outcome", action=action, object=name, success=False, stage="place" if dropped else "grasp")
            if dropped:
                emit("fetching", object=name, detail="the robot dropped it")
                clock += options.fetch_time_s
                counts["interventions"] += 1
                emit("intervention", object=name, detail="fetched by the human")
                break
        clock += 2.0
        emit("step_done", object=None, detail=instruction)
    return {
        "synthetic": True,
        "completed": True,
        "steps_completed": options.steps,
        "steps_total": options.steps,
        **counts,
        "sim_time": round(clock, 3),
        "objects": objects,
    }
