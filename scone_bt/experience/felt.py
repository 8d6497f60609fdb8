"""What the heft test felt, as execution context: the one function that turns a probe's reading into the
``felt_`` fields of `ExecutionContext`.

The tree (behaviours.outcome, and the gate's post-probe decision) and the replay (``scone-bench gate --probe``)
both call `felt_values`, so κ̂ learns and decides from the same numbers wherever it runs. An action that was not
probed keeps every ``felt_`` field None (NaN in a row): a store or dataset without them reads as "not probed".
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Protocol

import numpy as np

from scone_bt.experience.types import CONTEXT_FIELDS, FELT_RANGES, ExecutionContext

__all__ = ["FeltReading", "felt_values", "felt_context", "felt_row", "MAX_TRACTION", "MAX_MASS_KG"]

MAX_TRACTION = FELT_RANGES["felt_traction"][1]
"""Load over grip is capped here (a grip of nothing reads infinite)."""
MAX_MASS_KG = FELT_RANGES["felt_mass_kg"][1]
"""The felt mass is capped here, kilograms: a product sliding out of the fingers can spike the load to tens of
kilograms."""
_MAX_UNSTEADY = FELT_RANGES["felt_unsteady"][1]


class FeltReading(Protocol):
    """What the heft test felt (motion.probe.ProbeReading has these)."""

    @property
    def held(self) -> bool: ...

    @property
    def traction(self) -> float: ...

    @property
    def unsteady(self) -> float: ...

    @property
    def mass_kg(self) -> float: ...


def _finite(value: float, cap: float) -> float:
    """``value`` clamped to [0, ``cap``]; not finite reads as the cap (a grip of nothing reads an infinite
    traction, and an unreadable value counts as the worst)."""
    v = float(value)
    return cap if not math.isfinite(v) else round(min(max(v, 0.0), cap), 6)


def felt_values(reading: FeltReading) -> dict[str, bool | float]:
    """The ``felt_`` fields of `ExecutionContext` for one probe's reading (finite, capped)."""
    return {
        "felt_held": bool(reading.held),
        "felt_traction": _finite(reading.traction, MAX_TRACTION),
        "felt_unsteady": _finite(reading.unsteady, _MAX_UNSTEADY),
        "felt_mass_kg": _finite(reading.mass_kg, MAX_MASS_KG),
    }


def felt_context(context: ExecutionContext | None, reading: FeltReading | None) -> ExecutionContext | None:
    """The context after the probe: ``context`` (the one perceived when the gate decided) with what the fingers
    felt; unchanged without a reading."""
    if reading is None:
        return context
    v = felt_values(reading)
    return replace(
        context if context is not None else ExecutionContext(),
        felt_held=bool(v["felt_held"]),
        felt_traction=float(v["felt_traction"]),
        felt_unsteady=float(v["felt_unsteady"]),
        felt_mass_kg=float(v["felt_mass_kg"]),
    )


def felt_row(row: np.ndarray, reading: FeltReading) -> np.ndarray:
    """A context row (CONTEXT_FIELDS order, the replay's) with the reading's felt values (a copy)."""
    out = np.array(row, dtype=np.float64, copy=True)
    for name, value in felt_values(reading).items():
        out[CONTEXT_FIELDS.index(name)] = float(value)
    return out
