"""One seed, split per stage with `numpy.random.SeedSequence`: perception, planners, estimators, the human.

Each stage draws from its own stream, so a change in how much randomness one stage uses (a camera that renders
once more, a planner that samples longer) leaves every other stage's draws as they were. The stocking of the
shelf (which distractors, where each product stands) is seeded by the episode seed itself, as in every earlier
run, so a seed names the same kitchen. The failure budget's exploration draws come from
``numpy.random.default_rng([seed, 0x6A7E])`` of the behaviour seed (behaviours.gate.ConfidenceGate.setup), a
stream of their own that leaves κ̂'s draws as they were.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum

import numpy as np

__all__ = ["SeedStage", "SeedPlan", "PlannerSeedStream"]


class SeedStage(str, Enum):  # noqa: UP042 (the value names the stage in logs)
    """A stage with its own random stream; the order is the spawn order and must not change."""

    PERCEPTION = "perception"
    PLANNERS = "planners"
    ESTIMATORS = "estimators"
    HUMAN = "human"


@dataclass(frozen=True)
class SeedPlan:
    """The per-stage streams of one seed.

    Attributes:
        seed: The run's seed (a non-negative integer).
    """

    seed: int

    def stream(self, stage: SeedStage) -> np.random.SeedSequence:
        """The stage's own SeedSequence (the same object state for the same seed and stage, every time)."""
        children = np.random.SeedSequence(self.seed).spawn(len(SeedStage))
        return children[list(SeedStage).index(stage)]

    def generator(self, stage: SeedStage) -> np.random.Generator:
        """A generator drawing from the stage's stream."""
        return np.random.default_rng(self.stream(stage))

    def integer(self, stage: SeedStage) -> int:
        """A 32-bit integer seed from the stage's stream (for components that take an int)."""
        return int(self.stream(stage).generate_state(1)[0])


class PlannerSeedStream:
    """`PlannerSeeds` from the planners' stream: the n-th attempt's seed is its n-th spawned child's first word."""

    def __init__(self, plan: SeedPlan) -> None:
        self._stream = plan.stream(SeedStage.PLANNERS)
        self.issued = 0

    def next_seed(self) -> int:
        self.issued += 1
        return int(self._stream.spawn(1)[0].generate_state(1)[0])
