"""What one tick shows: the typed record the tree hands to a recorder after every tick."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from scone_bt.experience.types import ExecutionContext
from scone_bt.gate.types import Decision
from scone_bt.motion.types import TimedTrajectory
from scone_bt.perception.types import Detection, Frame

__all__ = ["Pose", "AffordanceRow", "RecipeView", "TickSnapshot"]

Pose = tuple[Sequence[float], Sequence[float]]
"""A world pose: position (x, y, z) in metres and quaternion (x, y, z, w)."""

AffordanceRow = tuple[str, float, float]
"""One affordance as shown: (action text, relevance as cosine similarity in [-1, 1], κ̂ confidence in [0, 1])."""


@dataclass(frozen=True)
class RecipeView:
    """The recipe as the user follows it.

    Attributes:
        title: Recipe title.
        steps: Instruction texts, in order.
        current: Index of the instruction being worked on; None when the recipe is finished.
        done: One flag per step, True once the step is completed (or judged irrelevant to the robot).
    """

    title: str
    steps: tuple[str, ...]
    current: int | None
    done: tuple[bool, ...]

    def __post_init__(self) -> None:
        if len(self.done) != len(self.steps):
            raise ValueError(f"RecipeView: {len(self.steps)} steps but {len(self.done)} done flags")


@dataclass(frozen=True, eq=False)
class TickSnapshot:
    """Everything one tick shows. Optional fields are None (or empty) when nothing new happened this tick.

    Attributes:
        tick: Tick counter of the behaviour tree, starting at 0.
        sim_time: Simulated time at the end of the tick, seconds.
        link_poses: Robot link name → world pose, as `Kitchen.link_poses()` returns it (the root link is 'base'
            and, as PyBullet reports it, sits at the root's centre of mass).
        object_poses: Object name → world pose (ground truth, for the 3D scene only).
        frame: The RGB-D capture taken this tick, or None when no new image exists.
        detections: Objects detected in `frame`, drawn over it (ignored when `frame` is None).
        affordances: (action, relevance, confidence) for each current affordance, any order; None: unchanged.
        decision: The gate's decision made this tick, or None.
        ee_path: (N, 3) planned end-effector positions in metres, when a new plan was made this tick.
        trajectory: The jerk-limited trajectory that starts executing at `sim_time`, when a new one exists.
        executed_q: (dof,) arm joint positions measured at the end of this tick, radians.
        tree: Root behaviour of the py_trees tree (or the BehaviourTree); every node's status is logged.
        confidences: Object name → κ̂ success probability in [0, 1], for the objects re-estimated this tick.
        person_trust: Object name → the person's trust in the robot's fetching it, in [0, 1], as the robot
            estimates it from what the person saw (scone_bt.trust.estimate), drawn beside κ̂.
        contexts: Action text → the execution context the gate perceived for it this tick (grounded κ̂).
        counters: Counter name → running total (successes, failures, help requests, interventions, ...).
        recipe: The recipe's state, when it changed (or every tick; unchanged states are not re-logged).
        log_lines: Human-readable lines produced this tick.
    """

    tick: int
    sim_time: float
    link_poses: Mapping[str, Pose] = field(default_factory=dict)
    object_poses: Mapping[str, Pose] = field(default_factory=dict)
    frame: Frame | None = None
    detections: Sequence[Detection] = ()
    affordances: Sequence[AffordanceRow] | None = None
    decision: Decision | None = None
    ee_path: np.ndarray | None = None
    trajectory: TimedTrajectory | None = None
    executed_q: np.ndarray | None = None
    tree: Any | None = None
    confidences: Mapping[str, float] = field(default_factory=dict)
    person_trust: Mapping[str, float] = field(default_factory=dict)
    contexts: Mapping[str, ExecutionContext] = field(default_factory=dict)
    counters: Mapping[str, int] = field(default_factory=dict)
    recipe: RecipeView | None = None
    log_lines: Sequence[str] = ()
