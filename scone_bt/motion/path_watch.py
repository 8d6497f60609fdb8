"""A product put down in the carry's way: the rest of the motion checked against what stands on the table now.

The plan avoided what the robot knew stood on the table when it planned. A person may put a product down while
the robot carries its own (the `impatient-human` scenario: the olive oil beside the crushed tomatoes' spot, where
the hand goes down). Looking only at the place spot (`motion.new_spot`) misses that: the hand hits the product in
transit. While carrying, the execution asks `PathWatch.in_the_way` which products the plan did not know (new on
the table, or moved more than `MOVED_M` since) the rest of the motion would hit: the carried product's transit
with the planner's carry padding, its lowering with the lowering's. When one would, the arm holds and asks for the
rest of the motion with them known (`motion.new_spot`), as when its spot is taken.

Each product is checked once where it stands; a product the path clears is not checked again until it moves or
turns. Every re-plan knows every product learnt since the first plan, not only the latest.

The look is the simulation's own state (a real backend answers it from its table camera), while what the plan
knew came from the cameras: a product the cameras placed more than `MOVED_M` from where it stands (a miscalibrated
camera) counts as unknown, and is checked where it really stands.
"""

from __future__ import annotations

from collections.abc import Collection, Sequence
from dataclasses import dataclass, field

import numpy as np

from scone_bt.motion.collision import CollisionWorld, Obstacle
from scone_bt.motion.model import ArmModel
from scone_bt.motion.placement_search import CARRY_PADDING

__all__ = ["CLEARED_MOVE_M", "CLEARED_TURN_RAD", "LOWER_PADDING", "MOVED_M", "PathWatch"]

MOVED_M = 0.02
"""A product the plan knew counts as unknown once it stands this far (m, on the table top) from where the plan
had it: farther than the table camera's error, nearer than a product's own size."""
CLEARED_MOVE_M = 0.003
"""Metres a product the path cleared may move before it is checked again."""
CLEARED_TURN_RAD = 0.05
"""Radians a product the path cleared may turn (or tip) before it is checked again."""
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
        learnt: The products learnt since the first plan, by name, where they stood when learnt: every re-plan
            is told all of them.
    """

    arm: ArmModel
    carried: Obstacle
    fingers: float | None
    known: dict[str, np.ndarray] = field(default_factory=dict)
    learnt: dict[str, Obstacle] = field(default_factory=dict)
    _cleared: dict[str, np.ndarray] = field(default_factory=dict)  # name -> the pose it was cleared at
    _bare: CollisionWorld | None = None  # the arm and the carried product alone (built on first need)

    @classmethod
    def of(
        cls, arm: ArmModel, carried: Obstacle, fingers: float | None, known: Sequence[Obstacle]
    ) -> PathWatch:
        """The watch of a plan that knew ``known`` on the table."""
        watch = cls(arm, carried, fingers)
        watch._know(known)
        return watch

    def _know(self, obstacles: Sequence[Obstacle]) -> None:
        self.known.update((o.name, np.array(o.pose[:2, 3], dtype=float)) for o in obstacles)

    def learn(self, obstacles: Sequence[Obstacle]) -> tuple[Obstacle, ...]:
        """The rest of the motion is planned anew knowing ``obstacles`` where they stand; returns every product
        learnt since the first plan (what the re-plan must know). Nothing is cleared for the new motion yet."""
        self._know(obstacles)
        self.learnt.update((o.name, o) for o in obstacles)
        self._cleared.clear()
        return tuple(self.learnt.values())

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
            if self._still_cleared(ob):
                continue
            if self._hits(ob, transit, CARRY_PADDING) or (
                lower is not None and self._hits(ob, lower, LOWER_PADDING)
            ):
                hits.append(ob)
            else:
                self._cleared[ob.name] = np.array(ob.pose, dtype=float)
        return tuple(hits)

    def _still_cleared(self, ob: Obstacle) -> bool:
        """The path cleared ``ob`` where it stands now (it has not moved or turned since)."""
        was = self._cleared.get(ob.name)
        if was is None:
            return False
        moved = float(np.linalg.norm(ob.pose[:3, 3] - was[:3, 3]))
        cos = (np.trace(was[:3, :3].T @ ob.pose[:3, :3]) - 1.0) / 2.0
        turned = float(np.arccos(np.clip(cos, -1.0, 1.0)))
        return moved <= CLEARED_MOVE_M and turned <= CLEARED_TURN_RAD

    def _hits(self, ob: Obstacle, samples: np.ndarray, padding: float) -> bool:
        """Some sample collides with ``ob`` that collides with nothing without it (the arm's own pairs and the
        carried product's are the plan's business, checked when it was made)."""
        world = CollisionWorld(self.arm, [ob], self.carried, padding=padding, finger_position=self.fingers)
        if world.states_valid(samples):  # the usual answer, in one compiled pass
            return False
        for q in samples:
            if world.is_valid(q):
                continue
            if self._bare is None:
                self._bare = CollisionWorld(self.arm, [], self.carried, finger_position=self.fingers)
            if self._bare.is_valid(q):
                return True
        return False
