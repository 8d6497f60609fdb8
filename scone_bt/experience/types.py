"""One observed outcome, as stored in the experience database, and the execution context it was observed in."""

from __future__ import annotations

import math
import uuid
from collections.abc import Mapping
from dataclasses import astuple, dataclass, field, fields
from types import MappingProxyType
from typing import Any

import numpy as np

from scone_bt.errors import SconeError

__all__ = [
    "CONTEXT_FIELDS",
    "FELT_FIELDS",
    "FELT_RANGES",
    "ROUND_FILL_BELOW",
    "ExecutionContext",
    "Outcome",
    "new_outcome_id",
]

ROUND_FILL_BELOW = 0.88
"""A lid filling less than this of its bounding rectangle (``detected_fill``) is round, a cylinder's (π/4 ≈ 0.79
for a disc, about 1 for a box lid): perception measures a round lid's width by it, and `physical` κ̂ reads it."""


@dataclass(frozen=True)
class ExecutionContext:
    """Where and how one action is executed; None where it is unknown.

    It lives beside Outcome (not in scone_bt.confidence) because the store persists it and κ̂ reads it: both
    depend on it, neither on the other.

    Attributes:
        shelf_tier: Tier of the target's shelf slot (0 = lowest), or None off the shelf.
        clearance_m: Free distance from the target to its nearest neighbour on its tier, metres.
        neighbours: Number of products whose centre lies near the target's.
        detected: Whether perception detected the target's marker.
        detected_width_m: Width of the target as perceived, metres (None if not measured).
        detected_height_m: Height of the target as perceived, metres (None if not measured).
        detected_depth_m: Longer horizontal extent of the target's lid as perceived, metres (None likewise).
        detected_fill: The lid's area over its bounding rectangle as perceived: about π/4 (0.79) for a cylinder,
            1 for a box (None likewise; round below `ROUND_FILL_BELOW`).
        felt_held: The heft test (motion.probe) ended with the product still in both fingers; None: the action
            was not probed (every ``felt_`` field is None then; experience.felt sets them).
        felt_traction: The load the fingers carried over their grip force during the hold (1 is about where a
            rubber fingertip slides), capped at 10.
        felt_unsteady: The share by which that load changed between the hold's halves (0: held fast), capped at 1.
        felt_mass_kg: The mass the load stands for, kilograms, capped at 10.
    """

    shelf_tier: int | None = None
    clearance_m: float | None = None
    neighbours: int | None = None
    detected: bool | None = None
    detected_width_m: float | None = None
    detected_height_m: float | None = None
    detected_depth_m: float | None = None
    detected_fill: float | None = None
    felt_held: bool | None = None
    felt_traction: float | None = None
    felt_unsteady: float | None = None
    felt_mass_kg: float | None = None

    def vector(self) -> np.ndarray:
        """(len(CONTEXT_FIELDS),) float64 in CONTEXT_FIELDS order, NaN for None."""
        return np.array([np.nan if v is None else float(v) for v in astuple(self)], dtype=np.float64)

    def to_json(self) -> dict[str, Any]:
        """The fields that are known, by name (None and NaN left out; booleans and counts kept exact)."""
        return {
            k: v
            for k, v in ((f.name, getattr(self, f.name)) for f in fields(self))
            if v is not None and not (isinstance(v, float) and math.isnan(v))
        }

    @classmethod
    def from_json(cls, data: Mapping[str, Any], where: str = "execution context") -> ExecutionContext:
        """Inverse of to_json; a missing field is None. An unknown field or a wrong type is SconeError."""
        if not isinstance(data, Mapping):
            raise SconeError(f"{where}: expected a JSON object, got {type(data).__name__}")
        unknown = sorted(set(data) - set(CONTEXT_FIELDS))
        if unknown:
            raise SconeError(f"{where}: unknown field {unknown[0]!r} (valid: {', '.join(CONTEXT_FIELDS)})")
        out: dict[str, Any] = {}
        for f in fields(cls):
            v = data.get(f.name)
            if v is None:
                continue
            kind = {"shelf_tier": int, "neighbours": int, "detected": bool, "felt_held": bool}.get(
                f.name, float
            )
            ok = (
                isinstance(v, bool)
                if kind is bool
                else isinstance(v, int | float) and not isinstance(v, bool)
            )
            if not ok or (kind is int and float(v) != int(v)):
                raise SconeError(f"{where}: {f.name} must be {kind.__name__}, got {v!r}")
            low, high = FELT_RANGES.get(f.name, (-math.inf, math.inf))
            if f.name in FELT_RANGES and not low <= v <= high:  # NaN fails too: to_json never writes it
                raise SconeError(f"{where}: {f.name} must be in [{low:g}, {high:g}], got {v!r}")
            out[f.name] = kind(v)
        felt = [name for name in FELT_FIELDS if name in out]
        if felt and len(felt) < len(FELT_FIELDS):  # a heft test sets them all (experience.felt)
            raise SconeError(
                f"{where}: {', '.join(sorted(set(FELT_FIELDS) - set(felt)))} missing beside {', '.join(felt)} "
                f"(a probed context has every one of {', '.join(FELT_FIELDS)}, or none)"
            )
        return cls(**out)


CONTEXT_FIELDS: tuple[str, ...] = tuple(f.name for f in fields(ExecutionContext))
"""Context columns, in the order of ExecutionContext.vector() (also the dataset CSV column names, but for the
``felt_`` ones: a dataset records its probe's raw readings apart, and the replay makes them felt only where it
probed)."""
FELT_FIELDS: tuple[str, ...] = tuple(f for f in CONTEXT_FIELDS if f.startswith("felt_"))
"""The context the heft test adds (experience.felt); NaN in a row of an action that was not probed."""
FELT_RANGES: Mapping[str, tuple[float, float]] = MappingProxyType(
    {"felt_traction": (0.0, 10.0), "felt_unsteady": (0.0, 1.0), "felt_mass_kg": (0.0, 10.0)}
)
"""The numeric ``felt_`` fields' valid ranges (experience.felt caps a reading into them; a stored value outside
is damage)."""


def new_outcome_id() -> str:
    """A fresh idempotency key (random UUID, hex)."""
    return uuid.uuid4().hex


@dataclass(frozen=True)
class Outcome:
    """An action the robot attempted and what happened.

    Attributes:
        time: Unix time of the observation, seconds.
        action: Action text ("Put salt on table").
        object_name: Catalogue name of the object acted on.
        embedder: Name of the embedder κ̂ was trained with when this was observed.
        success: Whether the object ended upright on the table.
        failure_stage: FailureStage value on failure, else None.
        context: Free-form JSON-serialisable details (seed, episode, recipe, ...).
        robot_id: Which robot of a fleet observed it ("" for outcomes stored before robots had ids).
        arm: The robot's arm model (robots/<arm>.yaml name, e.g. "panda").
        profile: The robot's proficiency profile or configuration label ("" if none).
        outcome_id: Idempotency key: storing the same outcome twice (a retry after a lost connection, a restarted
            robot replaying its last attempt) keeps one row. Not part of equality.
        execution: The context the attempt ran in, as perceived when the robot decided (what a grounded κ̂
            learns from); None for outcomes stored without one.
    """

    time: float
    action: str
    object_name: str
    embedder: str
    success: bool
    failure_stage: str | None = None
    context: dict = field(default_factory=dict)
    robot_id: str = ""
    arm: str = ""
    profile: str = ""
    outcome_id: str = field(default_factory=new_outcome_id, compare=False)
    execution: ExecutionContext | None = None
