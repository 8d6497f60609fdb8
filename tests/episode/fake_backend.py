"""A backend with no simulator: a `Robot` and a `World` over a dictionary of where each product stands.

`fake_backend(script)` is a `BackendFactory` for `run_episode(..., backend=...)`. The robot perceives every product
on the shelf and on the table exactly where it stands (no camera frames), plans at once (a product the script calls
infeasible has no plan), and a pick-and-place takes ``duration_s`` of world time, then ends as the script says for
that product's n-th attempt (default: success), moving the product to a free table spot on success. The human
(`SimulatedHuman`) fetches through the same `World`. Nothing here imports PyBullet, `scone_bt.world` or
`scone_bt.robot.sim`: an episode on it proves that the episode sees the backend only through its protocols.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from scone_bt.config import KitchenConfig, ObjectSpec
from scone_bt.motion.types import FailureStage, MotionOutcome, MotionPhase, MotionProgress
from scone_bt.perception.observe import Observation
from scone_bt.perception.types import Detection
from scone_bt.robot.backend import BackendRequest, BackendStats
from scone_bt.robot.interface import Infeasible, PickRequest
from scone_bt.robot.rig import SlotRef

__all__ = ["FakeScript", "FakeWorld", "FakeRobot", "FakeBackend", "fake_backend"]

Position = tuple[float, float, float]


@dataclass(frozen=True)
class FakeScript:
    """How the fake robot's actions end.

    Attributes:
        outcomes: Product → the stage each successive attempt fails at (None: that attempt succeeds); attempts
            past the list succeed.
        infeasible: Products no plan exists for (the planner says so before the arm moves).
        duration_s: World seconds one pick-and-place takes.
        planning_polls: Polls of a started pick-and-place that report the planner computing (world time stands
            still meanwhile).
    """

    outcomes: Mapping[str, Sequence[FailureStage | None]] = field(default_factory=dict)
    infeasible: frozenset[str] = frozenset()
    duration_s: float = 4.0
    planning_polls: int = 2


class FakeWorld:
    """`World`: each product stands on a shelf slot, on the table, in the gripper or out of the kitchen."""

    def __init__(self, config: KitchenConfig) -> None:
        self.config = config
        self.sim_time = 0.0
        self.specs: dict[str, ObjectSpec] = {}
        self.where: dict[str, Position | None] = {}  # top-face centre; None: out of the kitchen
        self.on_table: set[str] = set()
        self.held: str | None = None
        self.hidden_markers: set[str] = set()
        self.covered_cameras: set[str] = set()
        self.calibration_offset: Position = (0.0, 0.0, 0.0)
        self.advances = 0

    # ------------------------------------------------------------------------------------------- HumanWorld
    def is_on_table(self, name: str) -> bool:
        return name in self.on_table

    def is_on_shelf(self, name: str) -> bool:
        at = self.where.get(name)
        return at is not None and name not in self.on_table and self.config.scene.on_shelf(at, margin=0.0)

    def touches_robot(self, name: str) -> bool:
        return self.held == name

    def place_on_table(self, name: str) -> bool:
        spot = self._free_table_spot()
        if spot is None:
            return False
        x, y = spot
        self._stand(name, (x, y, self._table_top()))
        self.on_table.add(name)
        return True

    def put_away(self, name: str) -> None:
        self.on_table.discard(name)
        self.where[name] = None

    # ------------------------------------------------------------------------------------------- World
    def advance(self, seconds: float) -> None:
        self.sim_time += seconds
        self.advances += 1

    def stock(self, specs: Sequence[ObjectSpec], rng: np.random.Generator) -> None:
        slots = self.config.scene.shelf_slots()
        order = rng.permutation(len(slots))
        for spec, slot in zip(specs, order, strict=False):
            self.specs[spec.name] = spec
            self._stand(spec.name, slots[slot])
        for spec in specs[len(slots) :]:  # no slot left: out of the kitchen (the human brings it)
            self.specs[spec.name] = spec
            self.where[spec.name] = None

    def products(self) -> list[str]:
        return list(self.specs)

    def slots_on_tier(self, unit: str, tier: int) -> int:
        units = {u.name: u for u in self.config.scene.shelves}
        return len(units[unit].tiers[tier].slots)

    def place_on_shelf(self, name: str, slot: SlotRef, yaw: float = 0.0) -> None:
        unit = next(u for u in self.config.scene.shelves if u.name == slot.unit)
        tier = unit.tiers[slot.tier]
        x, y = unit.to_world(tier.center, tier.slots[slot.index])
        self.on_table.discard(name)
        self._stand(name, (x, y, tier.top_z))

    def swap(self, name: str, other: str) -> None:
        self.where[name], self.where[other] = self.where[other], self.where[name]
        a, b = name in self.on_table, other in self.on_table
        self.on_table -= {name, other}
        self.on_table |= {n for n, there in ((name, b), (other, a)) if there}

    def place_beside(self, name: str, anchor: str, gap_m: float, side: int) -> None:
        at = self.where[anchor]
        if at is None:
            raise ValueError(f"{anchor!r} is not in the kitchen")
        width = self.specs[anchor].size[1] / 2 + gap_m + self.specs[name].size[1] / 2
        self.where[name] = (at[0], at[1] + (1 if side >= 0 else -1) * width, at[2])

    def remove(self, name: str) -> None:
        self.where[name] = None
        self.on_table.discard(name)

    def hide_marker(self, name: str) -> None:
        self.hidden_markers.add(name)

    def show_marker(self, name: str) -> None:
        self.hidden_markers.discard(name)

    def cover_camera(self, camera: str) -> None:
        self.covered_cameras.add(camera)

    def uncover_camera(self, camera: str) -> None:
        self.covered_cameras.discard(camera)

    def apply_fault(self, calibration_offset: Position | None = None, **ignored: float | None) -> None:
        """Only a calibration offset changes what this fake perceives; the other faults have no model here."""
        if calibration_offset is not None:
            self.calibration_offset = tuple(float(c) for c in calibration_offset)  # type: ignore[assignment]

    # ------------------------------------------------------------------------------------------- helpers
    def _table_top(self) -> float:
        (_, _, cz), (_, _, sz) = self.config.scene.table
        return cz + sz / 2

    def _free_table_spot(self) -> tuple[float, float] | None:
        taken = {(round(p[0], 3), round(p[1], 3)) for n in self.on_table if (p := self.where[n]) is not None}
        for x, y in self.config.scene.place_spots:
            if (round(x, 3), round(y, 3)) not in taken:
                return (x, y)
        return None

    def _stand(self, name: str, surface: Position) -> None:
        x, y, z = surface
        self.where[name] = (x, y, z + self.specs[name].height)


class _Pick:
    """A `PlannedPick` and, once executed, its `MotionHandle`, timed by the world's clock; the script says how it
    ends (``fails_at``: the failure stage, None: success)."""

    def __init__(self, robot: FakeRobot, name: str, fails_at: FailureStage | None, infeasible: bool) -> None:
        self.robot, self.world, self.script = robot, robot.world, robot.script
        self.name, self.fails_at, self._infeasible = name, fails_at, infeasible
        self.polls_left = self.script.planning_polls
        self.started: float | None = None
        self._outcome: MotionOutcome | None = None

    # PlannedPick
    def ready(self) -> bool:
        return True

    def infeasible(self) -> Infeasible | None:
        if self._infeasible:
            return Infeasible("grasps_blocked", f"no grasp of the {self.name} is free", ("a neighbour",))
        return None

    def execute(self) -> _Pick:
        self.robot.attempts[self.name] = self.robot.attempts.get(self.name, 0) + 1
        self.started = self.world.sim_time  # world time stands still while progress() reports planning
        if self._infeasible:  # started without asking first: the planner finds nothing
            self._end(MotionOutcome(False, FailureStage.PLANNING, "no plan", 0.0))
        else:
            self.world.held = self.name
        return self

    # MotionHandle
    def progress(self) -> MotionProgress:
        self._finish_if_due()
        if self._outcome is not None:
            return MotionProgress(MotionPhase.DONE, 1.0)
        if self.polls_left > 0:
            self.polls_left -= 1
            return MotionProgress(MotionPhase.PLANNING, 0.0)
        done = self._elapsed() / self.script.duration_s
        return MotionProgress(MotionPhase.TRANSIT, min(1.0, done))

    def done(self) -> bool:
        self._finish_if_due()
        return self._outcome is not None

    def outcome(self) -> MotionOutcome | None:
        self._finish_if_due()
        return self._outcome

    def cancel(self) -> None:
        if self._outcome is None:
            self._end(MotionOutcome(False, FailureStage.CANCELLED, "cancelled", self._elapsed()))

    def _elapsed(self) -> float:
        return 0.0 if self.started is None else self.world.sim_time - self.started

    def _finish_if_due(self) -> None:
        if self._outcome is not None or self.started is None:
            return
        if self.world.sim_time - self.started < self.script.duration_s:
            return
        if self.fails_at is None and self.world.place_on_table(self.name):
            self._end(MotionOutcome(True, None, f"{self.name} placed", self._elapsed()))
        else:
            stage = self.fails_at or FailureStage.PLACE
            self._end(MotionOutcome(False, stage, f"scripted {stage.value} failure", self._elapsed()))

    def _end(self, outcome: MotionOutcome) -> None:
        self._outcome = outcome
        if self.world.held == self.name:
            self.world.held = None


class FakeRobot:
    """`Robot` over a `FakeWorld`: perfect perception of what stands in the kitchen, scripted pick-and-places."""

    def __init__(self, world: FakeWorld, script: FakeScript) -> None:
        self.world, self.script = world, script
        self.attempts: dict[str, int] = {}
        self.perceived = 0
        self.exposures: list[int] = []  # each look's frames per camera (1, or more for a longer look)
        self.closed = False

    def perceive(self, exposures: int = 1) -> Observation:
        self.perceived += 1
        self.exposures.append(exposures)
        w = self.world
        seen = [] if w.covered_cameras else sorted(n for n, at in w.where.items() if at is not None)
        dets = tuple(self._detection(n) for n in seen if n != w.held and n not in w.hidden_markers)
        table = tuple(d for d in dets if d.name in w.on_table)
        return Observation(None, {}, dets, table)  # type: ignore[arg-type]  # no camera, no frame

    def _detection(self, name: str) -> Detection:
        at = self.world.where[name]
        assert at is not None
        x, y, z = (a + b for a, b in zip(at, self.world.calibration_offset, strict=True))
        return Detection(name, sorted(self.world.specs).index(name), (x, y, z), 0.0, 1.0, (0, 0, 1, 1))

    def plan_pick_and_place(self, request: PickRequest) -> _Pick:
        name = request.target.name
        n = self.attempts.get(name, 0)
        script = list(self.script.outcomes.get(name, ()))
        return _Pick(self, name, script[n] if n < len(script) else None, name in self.script.infeasible)

    def start_pick_and_place(self, request: PickRequest) -> _Pick:
        return self.plan_pick_and_place(request).execute()

    def is_on_table(self, object_name: str) -> bool:
        return self.world.is_on_table(object_name)

    def now(self) -> float:
        return self.world.sim_time

    def home(self) -> None:
        pass

    def close(self) -> None:
        self.closed = True


class FakeBackend:
    """`Backend`: the fake robot and its world; no scene for a recording."""

    scene = None

    def __init__(self, request: BackendRequest, script: FakeScript) -> None:
        self.world = FakeWorld(request.kitchen)
        self.robot = FakeRobot(self.world, script)
        self.set_up = False

    def setup(self) -> None:
        self.set_up = True

    def stats(self) -> BackendStats:
        return BackendStats(renders=self.robot.perceived)


def fake_backend(script: FakeScript | None = None, built: list[FakeBackend] | None = None):  # noqa: ANN201
    """A `BackendFactory` of fake backends following ``script``; each one built is appended to ``built``."""

    def factory(request: BackendRequest) -> FakeBackend:
        backend = FakeBackend(request, script or FakeScript())
        if built is not None:
            built.append(backend)
        return backend

    return factory
