"""A number's allowed interval, declared once and checked with one message wherever the number is taken.

A tree file's parameters are validated by their pydantic fields; a dataclass built from them in code (a gate's or a
motion's options) checks the same interval with `Range.check`, read from the field by `Range.of_field`, so the
two cannot drift apart.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from pydantic import BaseModel

from scone_bt.errors import SconeError

__all__ = ["Range"]


@dataclass(frozen=True)
class Range:
    """A closed, open or half-open interval of finite numbers.

    Attributes:
        low: Lower end.
        high: Upper end.
        low_open: The lower end itself is outside.
        high_open: The upper end itself is outside.
        unit: Words the message adds after the interval ("metres"; "" for a share or a probability).
    """

    low: float
    high: float
    low_open: bool = False
    high_open: bool = False
    unit: str = ""

    @classmethod
    def of_field(cls, model: type[BaseModel], name: str, unit: str = "") -> Range:
        """The interval a pydantic field's ``ge``/``gt``/``le``/``lt`` declare."""
        low, high, low_open, high_open = -math.inf, math.inf, False, False
        for item in model.model_fields[name].metadata:  # annotated_types' Ge, Gt, Le, Lt
            if (ge := getattr(item, "ge", None)) is not None:
                low = float(ge)
            elif (gt := getattr(item, "gt", None)) is not None:
                low, low_open = float(gt), True
            elif (le := getattr(item, "le", None)) is not None:
                high = float(le)
            elif (lt := getattr(item, "lt", None)) is not None:
                high, high_open = float(lt), True
        return cls(low, high, low_open, high_open, unit)

    def __contains__(self, value: float) -> bool:
        above = value > self.low if self.low_open else value >= self.low
        below = value < self.high if self.high_open else value <= self.high
        return math.isfinite(value) and above and below

    def __str__(self) -> str:
        text = f"{'(' if self.low_open else '['}{self.low:g}, {self.high:g}{')' if self.high_open else ']'}"
        return f"{text} ({self.unit})" if self.unit else text

    def check(self, label: str, value: object) -> None:
        """One line naming ``label`` and this interval unless ``value`` is a number inside it."""
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise SconeError(f"{label} must be a number, got {value!r}")
        if float(value) not in self:
            raise SconeError(f"{label} must be in {self}, got {value}")
