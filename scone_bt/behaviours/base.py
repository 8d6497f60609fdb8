"""A small base class: blackboard access with declared READ/WRITE keys under stage namespaces.

Every key is a `Key`: its path on the blackboard and the type of what it holds. `StageBehaviour.write` checks the
value against it (a wrong type is an error where it is written, not where it is read), and `StageBehaviour.read`
of a key nobody wrote is an error unless the reader gives a default.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any, Generic, TypeVar, overload

import numpy as np
import py_trees
from py_trees.common import Access

from scone_bt.affordances.types import Affordance
from scone_bt.behaviours.context import EpisodeContext
from scone_bt.behaviours.probe_judge import ProbeJudge
from scone_bt.errors import SconeError
from scone_bt.experience.types import ExecutionContext, Outcome
from scone_bt.gate.types import Decision
from scone_bt.motion.types import MotionOutcome
from scone_bt.perception.types import Frame
from scone_bt.relevance.tracker import StepView
from scone_bt.robot.interface import Infeasible, MotionHandle, PlannedPick

__all__ = ["BlackboardError", "Key", "Keys", "StageBehaviour"]

T = TypeVar("T")
T_co = TypeVar("T_co", covariant=True)  # a Key[X] is read as, and written with, any supertype of X


class BlackboardError(SconeError):
    """A key read before anything wrote it, or written with a value of the wrong type."""


class Key(str, Generic[T_co]):
    """A blackboard key: its path (the string itself) and the type of the value it holds.

    Args:
        path: The key's path, under its stage's namespace.
        kind: The value's class (a container's class for collections; ``object`` for a protocol).
        optional: None is a valid value (e.g. no target while idle).
    """

    kind: type
    optional: bool

    def __new__(cls, path: str, kind: type, optional: bool = False) -> Key[T_co]:
        key = super().__new__(cls, path)
        key.kind = kind
        key.optional = optional
        return key

    def check(self, value: object, writer: str) -> None:
        """Raise BlackboardError unless ``value`` fits this key."""
        if value is None and self.optional:
            return
        if not isinstance(value, self.kind):
            raise BlackboardError(
                f"{writer} wrote {type(value).__name__} to blackboard key {self!s}, which holds "
                f"{self.kind.__name__}{' or None' if self.optional else ''}"
            )


class Keys:
    """Blackboard keys, one namespace per stage of the data flow."""

    FRAME: Key[Frame] = Key("/perception/frame", Frame, optional=True)
    # Every camera's frame of this tick, by camera name (the execution context measures sizes in them).
    FRAMES: Key[Mapping[str, Frame]] = Key("/perception/frames", Mapping)
    DETECTIONS: Key[Sequence[Any]] = Key("/perception/detections", Sequence)
    # What stands on the table, as the table camera sees it: tuple[Detection, ...] (position = top-face centre).
    TABLE_DETECTIONS: Key[Sequence[Any]] = Key("/perception/table_detections", Sequence, optional=True)
    AFFORDANCES: Key[Sequence[Affordance]] = Key("/affordances/list", Sequence)
    INSTRUCTION: Key[str] = Key("/relevance/instruction", str, optional=True)
    RANKED: Key[Sequence[Any]] = Key("/relevance/ranked", Sequence)
    ACTION_EMBEDDINGS: Key[Mapping[str, np.ndarray]] = Key("/relevance/action_embeddings", Mapping)
    # The robot's own place in the recipe: a StepView (scone_bt.relevance.tracker); None in the recipe-blind
    # setting.
    STEP: Key[StepView] = Key("/relevance/step", StepView, optional=True)
    # Answers to ASK-CLARIFY: dict[step index, tuple[item, ...]] (what the human said the step wants).
    CLARIFIED: Key[Mapping[int, tuple[str, ...]]] = Key("/relevance/clarified", Mapping)
    CONFIDENCES: Key[Mapping[str, float]] = Key("/gate/confidences", Mapping)
    DECISION: Key[Decision] = Key("/gate/decision", Decision)
    # The Affordance the decision acts on or asks about (None when idle or clarifying).
    TARGET: Key[Affordance] = Key("/gate/target", Affordance, optional=True)
    # ExecutionContext per ranked action text, as perceived this tick (what a grounded κ̂ reads).
    CONTEXTS: Key[Mapping[str, ExecutionContext]] = Key("/gate/contexts", Mapping)
    # The target's ExecutionContext (stored with its outcome), or None.
    TARGET_CONTEXT: Key[ExecutionContext] = Key("/gate/target_context", ExecutionContext, optional=True)
    # A PlannedPick for the decided target (plan before commit): PickAndPlace executes it; None once taken.
    PLANNED: Key[PlannedPick] = Key("/gate/planned", PlannedPick, optional=True)
    # An Infeasible found by this decision's planning (a scene the robot had not planned in), else None.
    PLAN_VERDICT: Key[Infeasible] = Key("/gate/plan_verdict", Infeasible, optional=True)
    # Items the step needs and the robot sees nowhere, to look for again with averaged frames at the next look
    # (perception.exposure; written by the gate, () when none).
    LOOK_AGAIN: Key[tuple] = Key("/gate/look_again", tuple)
    # The judge after a heft test (behaviours.probe_judge.ProbeJudge) when the decision probes, else None.
    PROBE_JUDGE: Key[ProbeJudge] = Key("/gate/probe_judge", ProbeJudge, optional=True)
    MOTION_OUTCOME: Key[MotionOutcome] = Key("/motion/outcome", MotionOutcome, optional=True)
    # The running pick-and-place (a MotionHandle).
    MOTION_TASK: Key[MotionHandle] = Key("/motion/task", MotionHandle, optional=True)
    MOTION_COMPUTING: Key[bool] = Key("/motion/computing", bool)
    OUTCOME: Key[Outcome] = Key("/experience/last_outcome", Outcome, optional=True)


_MISSING: Any = object()


def _writers_of(key: str) -> list[str]:
    """The behaviour classes (by name, as a tree file names them) that declare writing `key`."""
    found: set[str] = set()
    todo: list[type] = [StageBehaviour]
    while todo:
        cls = todo.pop()
        todo.extend(cls.__subclasses__())
        named = not cls.__name__.startswith("_")  # what a tree file can name
        if named and key in getattr(cls, "WRITES", ()):
            found.add(cls.__name__)
    return sorted(found)


class StageBehaviour(py_trees.behaviour.Behaviour):
    """A behaviour declaring the blackboard keys it reads and writes.

    Subclasses take their collaborators in the constructor (fakes in tests) and say in `from_context` which
    ones of the episode's they need; the tree builder calls `from_context` with the tree file's args.
    """

    READS: tuple[str, ...] = ()
    WRITES: tuple[str, ...] = ()

    def __init__(self, name: str) -> None:
        super().__init__(name=name)
        self.bb = self.attach_blackboard_client(name=name)
        for key in self.READS:
            self.bb.register_key(key=key, access=Access.READ)
        for key in self.WRITES:
            self.bb.register_key(key=key, access=Access.WRITE)

    @classmethod
    def from_context(cls, name: str, context: EpisodeContext) -> StageBehaviour:
        """This behaviour wired from the episode (subclasses with collaborators or args override it)."""
        return cls(name)

    @overload
    def read(self, key: Key[T]) -> T: ...

    @overload
    def read(self, key: Key[T], default: T) -> T: ...

    def read(self, key: Key[T], default: Any = _MISSING) -> Any:
        """The key's value; its ``default`` when nothing wrote it yet, or BlackboardError without one."""
        try:
            return self.bb.get(key)
        except KeyError:
            if default is _MISSING:
                writers = ", ".join(_writers_of(key)) or "no behaviour"
                raise BlackboardError(
                    f"{self.name} read blackboard key {key!s} before anything wrote it: in the tree file, a node "
                    f"that writes it ({writers}) must tick before {self.name}"
                ) from None
            return default

    def write(self, key: Key[T], value: T) -> None:
        """Set the key (checked against its type: BlackboardError on a wrong one)."""
        key.check(value, self.name)
        self.bb.set(key, value, overwrite=True)
