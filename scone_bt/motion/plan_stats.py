"""Why a planning step rejected its candidates: the statistics each step returns with its result.

Steps build them immutably (each rejection returns a new `PlanStats`) and the caller adds them up in the order the
steps ran, so a failure's message lists reasons in the order they happened.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass, replace

__all__ = ["PlanStats", "format_point"]


@dataclass(frozen=True)
class PlanStats:
    """Rejections of one step's candidates (grasps, or the placements of a grasp).

    Attributes:
        examined: Candidates looked at.
        reachable: Whether any candidate had an IK solution (without one, the step failed on reach, not collision).
        reasons: One line per rejection, in the order they happened.
        blockers: Obstacle names each rejection blamed, in order; a name blamed twice appears twice.
    """

    examined: int = 0
    reachable: bool = False
    reasons: tuple[str, ...] = ()
    blockers: tuple[str, ...] = ()

    def blocked(self, why: str, names: Sequence[str]) -> PlanStats:
        """These stats with one more rejection, blamed on `names` (possibly none)."""
        return replace(self, reasons=(*self.reasons, why), blockers=(*self.blockers, *names))

    def reached(self) -> PlanStats:
        """These stats with a candidate that had an IK solution."""
        return self if self.reachable else replace(self, reachable=True)

    def counted(self, n: int = 1) -> PlanStats:
        """These stats with `n` more candidates examined."""
        return replace(self, examined=self.examined + n)

    def __add__(self, later: PlanStats) -> PlanStats:
        """Both steps' rejections, `later`'s after these."""
        return PlanStats(
            self.examined + later.examined,
            self.reachable or later.reachable,
            (*self.reasons, *later.reasons),
            (*self.blockers, *later.blockers),
        )

    def top(self, n: int = 3) -> tuple[str, ...]:
        """The `n` most blamed obstacles, most often first (ties: first blamed first)."""
        return tuple(name for name, _ in Counter(self.blockers).most_common(n))

    def summary(self, n: int = 3) -> str:
        """The first `n` distinct reasons, joined for a one-line message."""
        return "; ".join(list(dict.fromkeys(self.reasons))[:n])


def format_point(p: Sequence[float]) -> str:
    """A position for a message, e.g. '(0.37, 0.30)' (metres, two decimals)."""
    return "(" + ", ".join(f"{v:.2f}" for v in p) + ")"
