"""The robot interface: what a behaviour may ask of the robot, and nothing else.

A behaviour never sees the simulator, the motion system or the cameras: it asks the robot for an observation,
starts a pick-and-place with a `PickRequest` built from what it saw, polls the returned `MotionHandle`, and asks
the robot's outcome sensor whether the object now rests on the table.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol, runtime_checkable

if TYPE_CHECKING:  # the interface itself imports nothing heavy (scone-run --help imports it)
    from scone_bt.motion.probe import ProbeReading, ProbeSettings
    from scone_bt.motion.types import MotionOutcome, MotionProgress
    from scone_bt.perception.observe import Observation
    from scone_bt.perception.types import Detection

__all__ = [
    "PickRequest",
    "MotionHandle",
    "Infeasible",
    "PlannedPick",
    "Robot",
    "obstacles_except",
]


@dataclass(frozen=True)
class PickRequest:
    """One pick-and-place, in the robot's own perception terms.

    Attributes:
        target: The detection of the object to move from the shelf to the table (world frame, metres).
        obstacles: Everything else seen on the shelf.
        table: What stands on the table as the table camera sees it; None while the table is not observed
            (the robot then knows only what it placed itself).
        rng_seed: Seeds the planner (a seeded episode plans the same way every time).
        probe: Heft the product before carrying it (motion.probe.ProbeSettings), or None.
        judge: What decides after the probe, from its reading (motion.probe.ProbeController's ``judge``: the
            gate's post-probe decision, gate.after_probe), or None (the probe's own safety judge).
    """

    target: Detection
    obstacles: tuple[Detection, ...]
    table: tuple[Detection, ...] | None
    rng_seed: int
    probe: ProbeSettings | None = None
    judge: Callable[[ProbeReading], tuple[bool, str]] | None = None


@runtime_checkable
class MotionHandle(Protocol):
    """A running pick-and-place."""

    def progress(self) -> MotionProgress:
        """Its phase (`MotionPhase`) and the fraction of the planned motion executed, in [0, 1]."""
        ...

    def done(self) -> bool:
        """True once it ended (success, failure or cancelled)."""
        ...

    def outcome(self) -> MotionOutcome | None:
        """How it ended; None while running."""
        ...

    def cancel(self) -> None:
        """Stop it (the human took over, or the tree interrupted it); the arm returns home."""
        ...


@dataclass(frozen=True)
class Infeasible:
    """Why no pick-and-place exists in this scene, known before the arm moves (geometry, not a planner's luck).

    Attributes:
        reason: Which stage ran out of options (a `PlanFailureReason` value: no_grasp_ik, grasps_blocked,
            no_table_space, no_placement_ik, placements_blocked).
        message: The planner's one line.
        blockers: What blocked the most candidates (object names or scene parts), most frequent first.
    """

    reason: str
    message: str
    blockers: tuple[str, ...] = ()


@runtime_checkable
class PlannedPick(Protocol):
    """A pick-and-place planned but not started: the robot has not committed to it yet."""

    def ready(self) -> bool:
        """True once planning finished."""
        ...

    def infeasible(self) -> Infeasible | None:
        """Once ready: why no plan exists in this scene, or None (a plan exists, or the planner ran out of time,
        which an attempt may still overcome)."""
        ...

    def execute(self) -> MotionHandle:
        """Commit: run the plan (a planner that ran out of time ends as a failure at planning)."""
        ...


@runtime_checkable
class Robot(Protocol):
    """What the behaviours need of a robot."""

    def perceive(self, exposures: int = 1) -> Observation:
        """One synchronised capture of the shelf cameras and the table camera: tracked detections of both.
        ``exposures`` > 1: a longer look, each camera's frames of the still scene averaged (perception.exposure)."""
        ...

    def start_pick_and_place(self, request: PickRequest) -> MotionHandle:
        """Start moving ``request.target`` to the table; returns at once (planning runs in the background)."""
        ...

    def plan_pick_and_place(self, request: PickRequest) -> PlannedPick:
        """Plan moving ``request.target`` to the table without moving; returns at once (poll ``ready``)."""
        ...

    def is_on_table(self, object_name: str) -> bool:
        """The outcome sensor: does the object rest upright on the table now?"""
        ...

    def now(self) -> float:
        """The robot's clock, seconds since the episode started (simulated time in simulation)."""
        ...

    def home(self) -> None:
        """Move to the home configuration (between episodes)."""
        ...

    def close(self) -> None:
        """Release the hardware or the simulation (worker threads, connections)."""
        ...


def obstacles_except(detections: Sequence[Detection], name: str) -> tuple[Detection, ...]:
    """The detections of every object but ``name``."""
    return tuple(d for d in detections if d.name != name)
