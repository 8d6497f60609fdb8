"""One simulated execution of a proficiency profile: spawn, perceive, pick-and-place, record the outcome.

Everything is real: the camera renders the kitchen, the ArUco detector finds (or misses) the target, the motion
stage plans with OMPL and executes in PyBullet, and the outcome sensor says whether the object stands on the
table. A profile only changes parameters (and may sabotage a stage, see profiles.INJECTABLE_STAGES).
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from scone_bt.affordances.types import action_text
from scone_bt.benchmarks.self_confidence.dataset import ExecutionRecord
from scone_bt.benchmarks.self_confidence.profiles import Profile
from scone_bt.config import KitchenConfig, ObjectSpec, RobotConfig
from scone_bt.perception.types import Detection

__all__ = ["INJECTED_FORCE_FACTOR", "ExecutionTask", "choose_objects", "execute_task", "run_execution"]

INJECTED_FORCE_FACTOR = 0.1
"""An injected grasp failure closes the gripper with this fraction of its force."""

_ADVANCE_S = 0.1
_MAX_SIM_S = 60.0
_ARMS: dict[tuple[str, str], object] = {}


def _motion_system(kitchen: object, robot: RobotConfig) -> object:
    """A MotionSystem for this kitchen, reusing the process's Pinocchio model (loading it takes ~1 s).

    A profile never changes what the arm model holds (URDF, joints, frames, collision pairs), only the gripper,
    limits and planner settings, which are passed here.
    """
    from scone_bt.motion import (
        ArmModel,
        ExecutionSettings,
        GraspParams,
        MotionSystem,
        PlannerOptions,
        limits_of,
    )

    key = (str(robot.source), str(robot.urdf))
    if key not in _ARMS:
        _ARMS[key] = ArmModel(robot)
    p = robot.planner
    options = PlannerOptions(
        name=p.name, time_limit_s=p.time_limit_s, simplify=p.simplify, rng_seed=p.rng_seed
    )
    return MotionSystem(kitchen, _ARMS[key], options, limits_of(robot), GraspParams(), ExecutionSettings())  # type: ignore[arg-type]


def choose_objects(
    profile: Profile, index: int, catalogue: Sequence[ObjectSpec]
) -> tuple[ObjectSpec, list[ObjectSpec]]:
    """The target and the distractors of execution `index` (uniform draws, seeded by the execution seed)."""
    rng = np.random.default_rng([profile.execution_seed(index), 0])
    order = rng.permutation(len(catalogue))
    target = catalogue[int(order[0])]
    others = [catalogue[int(i)] for i in order[1 : profile.objects_on_shelf]]
    return target, others


def _shifted(det: Detection, offset: Sequence[float]) -> Detection:
    return dataclasses.replace(
        det, position=tuple(float(a + b) for a, b in zip(det.position, offset, strict=True))
    )


def run_execution(
    profile: Profile,
    index: int,
    kitchen_cfg: KitchenConfig,
    robot_cfg: RobotConfig,
    target_name: str | None = None,
) -> tuple[ExecutionRecord, float]:
    """Run execution `index` of `profile` in a fresh kitchen; returns the record and its wall time (s).

    Args:
        profile: The robot's proficiency.
        index: Execution number; with the profile's seed it fixes the objects, their slots and every draw.
        kitchen_cfg: The kitchen before the profile's overrides.
        robot_cfg: The robot before the profile's overrides.
        target_name: Force this target instead of the seeded draw (for per-object calibration sweeps).
    """
    from scone_bt.perception import Observer
    from scone_bt.world import Kitchen

    t0 = time.perf_counter()
    seed = profile.execution_seed(index)
    catalogue = kitchen_cfg.catalogue
    target, others = choose_objects(profile, index, catalogue.objects)
    if target_name is not None and target_name != target.name:
        forced = catalogue.get(target_name)
        others = [o for o in [target, *others] if o.name != forced.name][: len(others)]
        target = forced
    rng = np.random.default_rng([seed, 1])
    injected = profile.draw_injections(target, rng)
    kcfg, rcfg = profile.apply(kitchen_cfg, robot_cfg)
    if "grasp" in injected:
        g = rcfg.gripper
        rcfg = dataclasses.replace(
            rcfg, gripper=dataclasses.replace(g, max_force=g.max_force * INJECTED_FORCE_FACTOR)
        )

    def record(success: bool, stage: str | None, detail: str) -> tuple[ExecutionRecord, float]:
        rec = ExecutionRecord(index, action_text(target.name), target.name, success, stage, seed, detail)
        return rec, time.perf_counter() - t0

    with Kitchen(kcfg, rcfg) as kitchen:
        kitchen.spawn([target, *others], rng)
        # Every shelf camera: the shelving has several units (the table camera plays no part here).
        detections = list(Observer(kcfg, table_camera=False).observe(kitchen, rng).detections)
        by_name = {d.name: _shifted(d, profile.calibration_offset) for d in detections}
        if "perception" in injected:
            return record(False, "perception", "injected: target not detected")
        if target.name not in by_name:
            return record(False, "perception", f"target not detected ({len(detections)} objects seen)")
        if "planning" in injected:
            return record(False, "planning", "injected: no plan within the budget")
        obstacles = [(d, catalogue.get(n)) for n, d in by_name.items() if n != target.name]
        with _motion_system(kitchen, rcfg) as system:  # type: ignore[attr-defined]
            task = system.pick_and_place(by_name[target.name], target, obstacles, rng_seed=seed)
            task.start()
            while not task.done() and kitchen.sim_time < _MAX_SIM_S:
                if task.is_planning():
                    task.wait_planned()  # simulated time must not depend on the planning thread's speed
                kitchen.advance(_ADVANCE_S)
            if not task.done():
                task.cancel()
                return record(False, "timeout", f"not finished after {_MAX_SIM_S:.0f} simulated seconds")
            outcome = task.outcome()
        assert outcome is not None
        stage = None if outcome.success else (outcome.stage.value if outcome.stage is not None else "place")
        detail = ("injected weak grasp; " if "grasp" in injected else "") + outcome.message
        return record(outcome.success, stage, detail)


@dataclass(frozen=True)
class ExecutionTask:
    """One execution as a work item for scone_bt.distributed: small to ship, self-seeded (profile and index).

    Attributes:
        profile: The robot's proficiency.
        index: Execution number (fixes the seed).
        kitchen: Kitchen file name or path, loaded in the worker.
        robot: Robot file name or path, loaded in the worker.
    """

    profile: Profile
    index: int
    kitchen: str = "kitchen"
    robot: str = "panda"


_CONFIGS: dict[tuple[str, str], tuple[KitchenConfig, RobotConfig]] = {}


def execute_task(task: ExecutionTask) -> tuple[str, ExecutionRecord, float]:
    """Run one ExecutionTask (configs loaded once per worker process); (profile name, record, wall s)."""
    from scone_bt.config import load_kitchen, load_robot

    key = (task.kitchen, task.robot)
    if key not in _CONFIGS:
        _CONFIGS[key] = (load_kitchen(task.kitchen), load_robot(task.robot))
    kitchen_cfg, robot_cfg = _CONFIGS[key]
    record, wall = run_execution(task.profile, task.index, kitchen_cfg, robot_cfg)
    return task.profile.name, record, wall
