"""What `ConfidenceGate` is built from: the ports it talks to and the settings it decides by."""

from __future__ import annotations

from dataclasses import dataclass

from scone_bt.behaviours.ports import (
    AttemptHistory,
    Clock,
    ContextSource,
    HumanChannel,
    PlannerSeeds,
    Provider,
    SelfConfidence,
)
from scone_bt.events import EventSink
from scone_bt.gate.budget import BudgetOptions
from scone_bt.gate.gate import GateOptions
from scone_bt.gate.probe import ProbeOptions
from scone_bt.gate.rules import GateRules
from scone_bt.robot.interface import Robot

__all__ = ["GatePorts", "GateSettings"]


@dataclass(frozen=True)
class GatePorts:
    """The gate's collaborators.

    Attributes:
        kappa: Builds κ̂ on first use (the behaviour's ``setup``).
        history: The episode's attempts (failures per action, the budget's counts, heft-test reasons).
        events: Where each `DecisionMade` goes.
        clock: Simulated time, seconds.
        human: The human's declines, and their current step in the recipe-blind setting (no tracked step).
        contexts: Builds execution contexts from the tick's detections and frames (None: none are built; a
            grounded κ̂ then sees every context value as missing).
        robot: Plans before committing (None: no planning before commitment; PickAndPlace plans when it starts).
        seeds: The planner's seeds, one per plan request (needed with ``robot``).
    """

    kappa: Provider[SelfConfidence]
    history: AttemptHistory
    events: EventSink
    clock: Clock
    human: HumanChannel
    contexts: ContextSource | None = None
    robot: Robot | None = None
    seeds: PlannerSeeds | None = None


@dataclass(frozen=True)
class GateSettings:
    """How the gate decides.

    Attributes:
        gate: The fixed-threshold options (the paper's gate; with ``budget``, its relevance and recipe options).
        max_failures_per_action: Failures of one action in an episode after which the gate stops acting on it.
        steps_total: The recipe's step count (a decision's reported step is capped at it).
        budget: The failure budget (the tree's ``gate: budget``; None: the fixed ``gate`` threshold decides).
        seed: The episode seed; the budget's exploration draws are their own stream from it.
        opening_m: The gripper's opening, metres (None: no too-wide rule, the paper's gate).
        probe: The heft test (gate.probe; None: none).
        slide_pinch: The arm slides and pinches a flat pack on a lowest tier (`GateRules.slide_pinch`).
    """

    gate: GateOptions
    max_failures_per_action: int
    steps_total: int
    budget: BudgetOptions | None = None
    seed: int = 0
    opening_m: float | None = None
    probe: ProbeOptions | None = None
    slide_pinch: bool = False

    @property
    def rules(self) -> GateRules:
        """The gate's rules (scone_bt.gate.rules) under these settings."""
        return GateRules(
            options=self.gate,
            budget=self.budget,
            exploration=self.budget,
            failure_limit=self.max_failures_per_action,
            opening_m=self.opening_m,
            probe=self.probe,
            slide_pinch=self.slide_pinch,
        )
