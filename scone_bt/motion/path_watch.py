"""A product put down in the carry's way: the rest of the motion checked against what stands on the table now.

The plan avoided what the robot knew stood on the table when it planned. A person may put a product down while
the robot carries its own (the `impatient-human` scenario: the olive oil beside the crushed tomatoes' spot, where
the hand goes down). Looking only at the place spot (`motion.new_spot`) misses that: the hand hits the product in
transit. While carrying, the execution asks `PathWatch.in_the_way` which products the plan did not know (new on
the table, or moved more than `MOVED_M` since) the rest of the motion would hit: the carried product's transit
with the planner's carry padding, its lowering with the lowering's. When one would, the arm holds and asks for the
rest of the motion with them known (`motion.new_spot`), as when its spot is taken.

Each product is checked once where it stands; a product the path clears is not checked again until it moves.
"""

from __future__ import annotations

from collections.abc import Collection, Sequence
from dataclasses import dataclass, field

import numpy as np

from scone_bt.motion.collision import CollisionWorld, Obstacle
from scone_bt.motion.model import ArmModel
from scone_bt.motion.placement_search import CARRY_PADDING

__all__ = ["LOWER_PADDING", "MOVED_M", "PATH_SAMPLE_S", "PathWatch"]

MOVED_M = 0.02
"""A product the plan knew counts as unknown once it stands this far (m, on the table top) from where the plan
had it: farther than the table camera's error, nearer than a product's own size."""
PATH_SAMPLE_S = 0.02
"""Simulated seconds between two checked samples of the rest of the motion (the carried hand moves about a
centimetre in that time)."""
LOWER_PADDING = 0.004
"""Metres of padding on an unknown product while lowering: the lowering plan's own (`placement_search`)."""


@dataclass
class PathWatch:
    """What the plan knew stood on the table, and the carried product's shape for checking the rest of the
    motion against products it did not know.

    Attributes:
        arm: The arm model.
        carried: The held product's shape, its pose relative to the end effector.
        fingers: The hand's pre-shape (m per finger), as planned; None: fully open.
        known: Where (x, y, metres) the plan had each product on the table, by name; it grows with each replan.
    """

    arm: ArmModel
    carried: Obstacle
    fingers: float | None
    known: dict[str, np.ndarray] = field(default_factory=dict)
    _cleared: set[tuple[str, int, int]] = field(default_factory=set)

    @classmethod
    def of(
        cls, arm: ArmModel, carried: Obstacle, fingers: float | None, known: Sequence[Obstacle]
    ) -> PathWatch:
        """The watch of a plan that knew ``known`` on the table."""
        watch = cls(arm, carried, fingers)
        watch.learn(known)
        return watch

    def learn(self, obstacles: Sequence[Obstacle]) -> None:
        """The rest of the motion was planned knowing ``obstacles`` where they stand: nothing is cleared yet."""
        self.known.update((o.name, np.array(o.pose[:2, 3], dtype=float)) for o in obstacles)
        self._cleared.clear()

    def unknown(self, on_table: Sequence[Obstacle], ignore: Collection[str]) -> tuple[Obstacle, ...]:
        """The products of ``on_table`` the plan did not know where they stand now (``ignore``: by name)."""
        out = []
        for ob in on_table:
            if ob.name in ignore:
                continue
            was = self.known.get(ob.name)
            if was is None or float(np.hypot(*(ob.pose[:2, 3] - was))) > MOVED_M:
                out.append(ob)
        return tuple(out)

    def in_the_way(
        self, transit: np.ndarray, lower: np.ndarray | None, unknown: Sequence[Obstacle]
    ) -> tuple[Obstacle, ...]:
        """Those of ``unknown`` that the carried product's remaining ``transit`` (n, dof) or its ``lower`` samples
        would collide with (the arm, the hand or the product itself); each is checked once where it stands."""
        hits = []
        for ob in unknown:
            x, y = (int(round(float(v) / MOVED_M)) for v in ob.pose[:2, 3])
            key = (ob.name, x, y)
            if key in self._cleared:
                continue
            if self._hits(ob, transit, CARRY_PADDING) or (
                lower is not None and self._hits(ob, lower, LOWER_PADDING)
            ):
                hits.append(ob)
            else:
                self._cleared.add(key)
        return tuple(hits)

    def _hits(self, ob: Obstacle, samples: np.ndarray, padding: float) -> bool:
        """Some sample collides with ``ob`` that collides with nothing without it (the arm's own pairs and the
        carried product's are the plan's business, checked when it was made)."""
        world = CollisionWorld(self.arm, [ob], self.carried, padding=padding, finger_position=self.fingers)
        if world.states_valid(samples):  # the usual answer, in one compiled pass
            return False
        bare: CollisionWorld | None = None
        for q in samples:
            if world.is_valid(q):
                continue
            bare = bare or CollisionWorld(self.arm, [], self.carried, finger_position=self.fingers)
            if bare.is_valid(q):
                return True
        return False
