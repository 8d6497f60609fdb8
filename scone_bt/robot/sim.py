"""The PyBullet simulation as a backend: `SimRobot` (`world.Kitchen`, `motion.MotionSystem` and the simulated
cameras) and `SimWorld` around it, built by `sim_backend` (``scone-run --robot sim``)."""

from __future__ import annotations

import dataclasses
import threading
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from scone_bt.config import KitchenConfig, ObjectSpec, RobotConfig
from scone_bt.motion.pick_place import PickPlaceFailure
from scone_bt.motion.slide import SlideFailure
from scone_bt.motion.types import PlanFailureReason
from scone_bt.perception.observe import Observation
from scone_bt.perception.types import Detection
from scone_bt.robot.backend import BackendRequest, BackendStats
from scone_bt.robot.interface import Infeasible, MotionHandle, PickRequest, PlannedPick
from scone_bt.robot.rig import SimWorld
from scone_bt.world import Kitchen

if TYPE_CHECKING:
    from scone_bt.motion import ArmModel, MotionSystem
    from scone_bt.motion.system import PickAndPlaceTask
    from scone_bt.perception.observe import Observer

__all__ = ["SimBackend", "SimRobot", "sim_backend", "shared_arm"]

_ARMS = threading.local()
"""Per thread: robot configuration → its `motion.ArmModel` (parsing the URDF into Pinocchio and coal models takes
most of a second; the episodes of a benchmark or a study session run one after another in one thread)."""


def shared_arm(robot: RobotConfig) -> ArmModel:
    """The arm model of ``robot``, built once per thread and configuration and shared by the episodes the thread
    runs in turn (an arm model keeps nothing of an episode: see `motion.MotionSystem.build`)."""
    from scone_bt.motion import ArmModel

    models: dict[RobotConfig, ArmModel] = _ARMS.__dict__.setdefault("models", {})
    if robot not in models:
        models.clear()  # one robot at a time per thread: a changed robot file does not pile up models
        models[robot] = ArmModel(robot)
    return models[robot]


class SimRobot:
    """The simulated arm, its cameras and its outcome sensor in one `Kitchen` (which it owns and closes).

    Args:
        kitchen: The simulated kitchen (objects already spawned).
        config: The kitchen's configuration (cameras, scene, catalogue sizes for planning).
        robot: The arm's configuration.
        perception_rng: Seeds the cameras' noise.
    """

    def __init__(
        self, kitchen: Kitchen, config: KitchenConfig, robot: RobotConfig, perception_rng: np.random.Generator
    ) -> None:
        self.kitchen = kitchen
        self.config = config
        self.robot_config = robot
        self._rng = perception_rng
        self._observer: Observer | None = None
        self._motion: MotionSystem | None = None
        self.calibration_offset: tuple[float, float, float] = (0.0, 0.0, 0.0)
        """Systematic camera-to-robot error added to every perceived position, metres (a miscalibrated robot)."""

    # ------------------------------------------------------------------------------------------ components
    @property
    def observer(self) -> Observer:
        """The simulated cameras and detector (built on first use)."""
        if self._observer is None:
            from scone_bt.perception.observe import Observer

            self._observer = Observer(self.config)
        return self._observer

    @property
    def motion(self) -> MotionSystem:
        """The arm model and planner (built on first use; loading Pinocchio takes a moment)."""
        if self._motion is None:
            from scone_bt.motion import MotionSystem

            self._motion = MotionSystem.build(
                self.kitchen, self.robot_config, arm=shared_arm(self.robot_config)
            )
        return self._motion

    def setup(self) -> None:
        """Build the cameras and the motion system now (before the first tick, not during it)."""
        _ = self.observer, self.motion

    # ------------------------------------------------------------------------------------------ Robot
    def perceive(self, exposures: int = 1) -> Observation:
        seen = self.observer.observe(self.kitchen, self._rng, exposures)
        if not any(self.calibration_offset):
            return seen
        return dataclasses.replace(
            seen,
            detections=tuple(_shifted(d, self.calibration_offset) for d in seen.detections),
            table_detections=tuple(_shifted(d, self.calibration_offset) for d in seen.table_detections),
        )

    def _spec(self, name: str) -> ObjectSpec:
        return self.config.catalogue.get(name)

    def _with_specs(self, seen: tuple[Detection, ...]) -> list[tuple[Detection, ObjectSpec]]:
        return [(d, self._spec(d.name)) for d in seen]

    def _task(self, request: PickRequest) -> PickAndPlaceTask:
        target = request.target
        task = self.motion.pick_and_place(
            target,
            self._spec(target.name),
            self._with_specs(request.obstacles),
            rng_seed=request.rng_seed,
            table_obstacles=None if request.table is None else self._with_specs(request.table),
        )
        task.probe = request.probe
        task.judge = request.judge
        task.look = self._look_again
        return task

    def _look_again(self) -> dict[str, Detection]:
        """The shelf as the cameras see it now, by name (after a slide: `motion.slide`)."""
        return {d.name: d for d in self.perceive().detections}

    def start_pick_and_place(self, request: PickRequest) -> MotionHandle:
        task = self._task(request)
        task.start()
        return task

    def plan_pick_and_place(self, request: PickRequest) -> PlannedPick:
        task = self._task(request)
        task.submit_plan()
        return _PlannedTask(task)

    def is_on_table(self, object_name: str) -> bool:
        return self.kitchen.is_on_table(object_name)

    def now(self) -> float:
        return self.kitchen.sim_time

    def home(self) -> None:
        self.kitchen.hold_arm(self.robot_config.home)

    def close(self) -> None:
        if self._motion is not None:
            self._motion.close()
            self._motion = None
        self.kitchen.close()

    # ------------------------------------------------------------------------------------------ measurements
    @property
    def perception_seconds(self) -> tuple[float, float]:
        """Wall and CPU seconds spent rendering and detecting so far."""
        o = self._observer
        return (0.0, 0.0) if o is None else (o.wall_s, o.cpu_s)

    @property
    def renders(self) -> int:
        """Camera images rendered so far."""
        o = self._observer
        return 0 if o is None else sum(c.renders for c in o.cameras)


def _shifted(det: Detection, offset: Sequence[float]) -> Detection:
    """The detection as a robot whose camera-to-robot calibration is off by ``offset`` (m) perceives it."""
    x, y, z = (float(a + b) for a, b in zip(det.position, offset, strict=True))
    return dataclasses.replace(det, position=(x, y, z))


# Planner failures that the scene's geometry decides (the same request fails again); NO_PATH is the planner
# running out of its budget, which a rushed planner does at random: that one is attempted and may fail.
_GEOMETRIC = frozenset(
    {
        PlanFailureReason.NO_GRASP_IK,
        PlanFailureReason.GRASPS_BLOCKED,
        PlanFailureReason.NO_TABLE_SPACE,
        PlanFailureReason.NO_PLACEMENT_IK,
        PlanFailureReason.PLACEMENTS_BLOCKED,
    }
)


class _PlannedTask:
    """`PlannedPick` over the motion system's task: planned in the background, started on `execute`."""

    def __init__(self, task: PickAndPlaceTask) -> None:
        self.task = task

    def ready(self) -> bool:
        return not self.task.is_planning()

    def infeasible(self) -> Infeasible | None:
        result = self.task.plan
        if isinstance(result, PickPlaceFailure | SlideFailure) and result.reason in _GEOMETRIC:
            return Infeasible(result.reason.value, result.message.split(";")[0], tuple(result.blockers))
        return None

    def execute(self) -> MotionHandle:
        self.task.start()
        return self.task


class SimBackend:
    """The simulated robot, its kitchen as the test rig, and the kitchen as what a recording draws.

    Args:
        robot: The simulated robot (it owns the kitchen and closes it).
    """

    def __init__(self, robot: SimRobot) -> None:
        self.robot = robot
        self.world = SimWorld(robot.kitchen, robot)
        self.scene = robot.kitchen

    def setup(self) -> None:
        self.robot.setup()

    def stats(self) -> BackendStats:
        kitchen = self.robot.kitchen
        wall, cpu = self.robot.perception_seconds
        return BackendStats(
            perception_wall_s=wall,
            perception_cpu_s=cpu,
            renders=self.robot.renders,
            physics_steps=kitchen.steps,
            physics_steps_skipped=kitchen.steps_skipped,
            bodies=kitchen.bodies(),
            constraints=kitchen.constraints(),
        )


def sim_backend(request: BackendRequest) -> SimBackend:
    """A new PyBullet kitchen (no products yet) with the arm in it (``request.gui``: PyBullet's own window)."""
    kitchen = Kitchen(request.kitchen, request.robot, gui=request.gui)
    return SimBackend(SimRobot(kitchen, request.kitchen, request.robot, request.perception_rng))
