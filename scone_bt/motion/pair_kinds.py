"""The kinds of collision pair a world checks, as the compiled sphere test reads them (`compiled.pair_candidates`)."""

__all__ = ["PAIR_HELD", "PAIR_HELD_OBSTACLE", "PAIR_OBSTACLE", "PAIR_ROBOT"]

PAIR_ROBOT = 0
"""A robot geometry against another (self-collision)."""
PAIR_OBSTACLE = 1
"""A robot geometry against an obstacle."""
PAIR_HELD = 2
"""A robot geometry against the held object."""
PAIR_HELD_OBSTACLE = 3
"""The held object against an obstacle."""
