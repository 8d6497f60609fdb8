"""One simulated execution of a proficiency profile: stock, perceive, pick-and-place, record outcome and context.

The recorded context is the episode's own: `scone_bt.perception.context.execution_contexts` on the detections the
robot acts on (its calibration error included) and every frame rendered, as the tree's gate computes it when it
decides (`ContextExtractor`). Nothing in a record's context comes from the stocking plan or the simulator's state;
a target the cameras did not detect has no perceived context (`detected` 0, the rest empty).

Everything is real: the shelf cameras render the kitchen, the ArUco marker detector finds (or misses) the target, the
motion stage plans with OMPL on the robot file's grasp settings and executes in PyBullet, and the outcome sensor
says whether the product stands on the table. A profile only changes parameters (and may sabotage a stage, see
profiles.INJECTABLE_STAGES). The target and the distractors are drawn uniformly from the whole catalogue (or the
--products restriction) for every execution.

The engine is the backend's (`--robot`: ``sim`` is PyBullet, ``mujoco`` MuJoCo's `world.mj_kitchen.MjKitchen`); the
products, their slots, every seed, the detector, the planner and the outcome sensor are the same code on both, so
execution *i* of a profile is the same task on either engine.

Speed (scone-bench sc generate): one PyBullet kitchen per worker process, emptied and restored to its saved start state
(PyBullet saveState / restoreState) between executions instead of rebuilt; a shelf camera with no product in view
is not rendered (it would show nothing to detect; its noise comes from its own generator, so skipping it changes no
other draw). A MuJoCo kitchen is built afresh for each execution: it compiles its model whenever it is stocked anyway.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any, cast

import numpy as np

from scone_bt.affordances.types import action_text
from scone_bt.benchmarks.self_confidence.dataset import ExecutionRecord
from scone_bt.benchmarks.self_confidence.profiles import Profile
from scone_bt.config import KitchenConfig, ObjectSpec, RobotConfig
from scone_bt.config.catalogue import Catalogue
from scone_bt.errors import ConfigError
from scone_bt.experience.types import ExecutionContext
from scone_bt.motion.probe import ProbeReading, ProbeSettings
from scone_bt.perception import context as perception_context
from scone_bt.perception.types import Detection, Frame

__all__ = [
    "ENGINES",
    "INJECTED_FORCE_FACTOR",
    "ExecutionTask",
    "choose_objects",
    "drawable_products",
    "execute_task",
    "perceived_context",
    "RECORDING_PROBE",
    "run_execution",
]

RECORDING_PROBE = ProbeSettings(set_back=False)
"""Every execution hefts its product first and records what the fingers felt, then always carries on (the probe
only senses): a replay decides afterwards whether a robot that probes would have set it back (benchmarks.replay)."""

INJECTED_FORCE_FACTOR = 0.1
"""An injected grasp failure closes the gripper with this fraction of its force."""

ENGINES = ("sim", "mujoco")
"""The backends (`--robot`) the generator runs its executions on: PyBullet and MuJoCo."""

_ADVANCE_S = 0.1
_MAX_SIM_S = 60.0
_MAX_DRAWS = 100
"""Draws of an execution's products before giving up on finding a set that fits the shelving side by side."""


def drawable_products(kitchen: KitchenConfig, names: Sequence[str] | None = None) -> tuple[ObjectSpec, ...]:
    """The products an execution draws from: the catalogue (or `names` of it) that fits some shelf tier."""
    from scone_bt.stocking import fits_shelf

    chosen = kitchen.catalogue.objects if names is None else tuple(kitchen.catalogue.get(n) for n in names)
    return tuple(o for o in chosen if fits_shelf(o, kitchen.scene))


def choose_objects(
    profile: Profile, index: int, pool: Sequence[ObjectSpec], scene: Any = None
) -> tuple[ObjectSpec, list[ObjectSpec]]:
    """The target and the distractors of execution `index`: a uniform draw without replacement from `pool`.

    With `scene`, a draw whose products do not fit the shelving side by side is replaced by the next one (each
    draw seeded by the execution seed and the attempt number).
    """
    n = min(profile.objects_on_shelf, len(pool))
    for attempt in range(_MAX_DRAWS if scene is not None else 1):
        rng = np.random.default_rng([profile.execution_seed(index), 0, attempt])
        order = rng.permutation(len(pool))[:n]
        target, others = pool[int(order[0])], [pool[int(i)] for i in order[1:]]
        if scene is None or _fits(scene, [target, *others]):
            return target, others
    raise ConfigError(
        f"profile {profile.name}: no draw of {n} products fits the shelving in {_MAX_DRAWS} tries; "
        "restrict --products to narrower ones or lower objects_on_shelf"
    )


def _fits(scene: Any, specs: Sequence[ObjectSpec]) -> bool:
    from scone_bt.stocking import plan_stocking

    try:
        plan_stocking(scene, specs, np.random.default_rng(0))
    except ConfigError:
        return False
    return True


def _shifted(det: Detection, offset: Sequence[float]) -> Detection:
    return dataclasses.replace(
        det,
        position=cast(
            "tuple[float, float, float]",
            tuple(float(a + b) for a, b in zip(det.position, offset, strict=True)),
        ),
    )


class _Worker:
    """What a worker process keeps between executions: configs, the arm model, detectors, and the last execution's
    kitchen (closed when the next execution builds its own)."""

    def __init__(self) -> None:
        self.configs: dict[tuple[str, str, tuple[str, ...]], tuple[KitchenConfig, RobotConfig]] = {}
        self.arms: dict[tuple[str, str], Any] = {}  # ArmModel, imported in the worker
        self.detectors: dict[int, tuple[Any, Any]] = {}  # (catalogue, its Detector)
        self.kitchen: Any = None

    def arm(self, robot: RobotConfig) -> Any:
        from scone_bt.motion import ArmModel

        key = (str(robot.source), str(robot.urdf))
        if key not in self.arms:  # loading the Pinocchio model takes about a second
            self.arms[key] = ArmModel(robot)
        return self.arms[key]

    def detector(self, kitchen: KitchenConfig) -> Any:
        from scone_bt.perception import Detector

        key = id(kitchen.catalogue)
        if key not in self.detectors:
            self.detectors[key] = (kitchen.catalogue, Detector(kitchen.catalogue))
        return self.detectors[key][1]

    def empty_kitchen(self, kcfg: KitchenConfig, rcfg: RobotConfig, engine: str = "sim") -> Any:
        """A new kitchen for every execution, on either engine (the previous one closed).

        PyBullet's kitchen used to be restocked (`Kitchen.clear_products`), but a restocked world is not the world a
        new one starts as: the solver keeps state across removed bodies and a restored state, so an execution's
        outcome depended on which executions its worker had run before it, and with ``--workers 2`` on which
        worker the pool gave it. Two runs of the same executions differed in about 1 row in 60. A kitchen takes
        about 0.04 s to build: a seeded run now repeats exactly, with any number of workers.
        """
        from scone_bt.quiet import c_stdout_silenced

        if self.kitchen is not None:
            self.kitchen.close()
            self.kitchen = None
        if engine == "mujoco":
            from scone_bt.world.mj_kitchen import MjKitchen

            self.kitchen = MjKitchen(kcfg, rcfg)
            return self.kitchen
        from scone_bt.world import Kitchen

        with c_stdout_silenced():
            self.kitchen = Kitchen(kcfg, rcfg)
        self.kitchen.config, self.kitchen.robot_config = kcfg, rcfg
        self.kitchen.hold_arm(rcfg.home)
        self.kitchen.set_gripper_target(rcfg.gripper.open_position)
        return self.kitchen


_WORKER = _Worker()


def _motion_system(kitchen: Any, robot: RobotConfig) -> Any:
    """A MotionSystem for this kitchen: the worker's Pinocchio model and the robot file's grasp settings."""
    from scone_bt.config.grasp import GraspParams
    from scone_bt.motion import ExecutionSettings, MotionSystem, PlannerOptions, limits_of

    p = robot.planner
    options = PlannerOptions(
        name=p.name, time_limit_s=p.time_limit_s, simplify=p.simplify, rng_seed=p.rng_seed
    )
    params = GraspParams.of(robot)
    return MotionSystem(
        kitchen,
        _WORKER.arm(robot),
        options,
        limits_of(robot),
        params,
        ExecutionSettings(),
        robot,
    )


def _miscalibrated(frame: Frame, offset: Sequence[float]) -> Frame:
    """The frame as a robot with this camera-to-robot error has it: its pose shifted by `offset` (metres).

    Every depth point it yields then moves with the detections (`_shifted`), so the lid is found where the robot
    believes the top face is, and the height above the shelf step carries the error as the robot perceives it.
    """
    if not any(offset):
        return frame
    pose = frame.world_from_camera.copy()
    pose[:3, 3] += np.asarray(offset, dtype=pose.dtype)
    return dataclasses.replace(frame, world_from_camera=pose)


def _look(
    kitchen: Any, kcfg: KitchenConfig, seed: int, exposures: int = 1, after_slide: bool = False
) -> tuple[dict[str, Detection], list[Frame]]:
    """Render every shelf camera that has a product in view, detect, merge (most confident per product).

    ``exposures`` > 1: the longer look the robot takes before saying it cannot see its target, each camera's
    frames averaged (perception.exposure; its noise drawn from a stream of its own, so the first look's draws
    stay as they were; ``after_slide``: the look after a slide, from a stream of its own too). Returns detections by name and every frame used (what the episode's context function
    measures in).
    """
    from scone_bt.perception import Camera
    from scone_bt.perception.exposure import look
    from scone_bt.quiet import c_stdout_silenced
    from scone_bt.world.camera import box_in_view

    detector = _WORKER.detector(kcfg)
    boxes = _product_boxes(kitchen)
    best: dict[str, Detection] = {}
    frames: list[Frame] = []
    for k, spec in enumerate(kcfg.shelf_cameras):
        camera = Camera(spec)
        if not any(box_in_view(camera, lo, hi) for lo, hi in boxes):
            continue
        rng = np.random.default_rng([seed, 4 if after_slide else 2 if exposures <= 1 else 3, k])
        with c_stdout_silenced():
            frame = look(camera, kitchen, rng, exposures)
        frames.append(frame)
        for det in detector.detect(frame):
            # A shelf camera may glimpse the table; what stands there is the table camera's (unused here).
            if kcfg.scene.on_table(det.position):
                continue
            if det.name not in best or det.confidence > best[det.name].confidence:
                best[det.name] = det
    return best, frames


def _product_boxes(kitchen: Any) -> list[tuple[Any, Any]]:
    """Each product's axis-aligned box now (world, metres): PyBullet's AABB, or on another engine the box around
    the product's catalogue extent at its ground-truth pose (a cylinder as its square box)."""
    from scone_bt.world.ground_truth import rotation_of

    bc = getattr(kitchen, "bc", None)
    if bc is not None:
        return [bc.getAABB(body) for body in kitchen.objects.values()]
    boxes = []
    for name in kitchen.objects:
        state = kitchen.object_state(name)
        half = np.abs(rotation_of(state.orientation)) @ (
            np.asarray(kitchen.specs[name].size, dtype=float) / 2
        )
        centre = np.asarray(state.position, dtype=float)
        boxes.append((centre - half, centre + half))
    return boxes


def perceived_context(
    target: str,
    detections: dict[str, Detection],
    frames: Sequence[Frame],
    kcfg: KitchenConfig,
) -> tuple[ExecutionContext, str, int | None]:
    """The target's context as the robot perceived it, with the shelf unit and nearest slot of its detection.

    `detections` and `frames` are what the robot acts on (calibration error included). The context is
    `execution_contexts` on them, the episode's function; an undetected target has none of it (detected False,
    every other field None) and no unit or slot.
    """
    if target not in detections:
        return ExecutionContext(detected=False), "", None
    det = detections[target]
    # Through the module, as ContextExtractor calls it: one function (a test counts the calls of both paths).
    context = perception_context.execution_contexts(
        [det], list(detections.values()), frames, kcfg.scene, kcfg.catalogue
    )[target]
    place = perception_context.shelf_place(kcfg.scene, det.position)
    slots = kcfg.scene.slots()
    p = det.position
    slot = int(np.argmin([np.hypot(s.position[0] - p[0], s.position[1] - p[1]) for s in slots]))
    return context, "" if place is None else place[0], slot


def _objects(
    profile: Profile,
    index: int,
    kitchen_cfg: KitchenConfig,
    target_name: str | None,
    pool: Sequence[ObjectSpec] | None,
) -> tuple[ObjectSpec, list[ObjectSpec]]:
    """The execution's target and distractors (`choose_objects`), with ``target_name`` forced if given."""
    pool = drawable_products(kitchen_cfg) if pool is None else pool
    target, others = choose_objects(profile, index, pool, kitchen_cfg.scene)
    if target_name is not None and target_name != target.name:
        forced = kitchen_cfg.catalogue.get(target_name)
        others = [o for o in [target, *others] if o.name != forced.name][: len(others)]
        target = forced
    return target, others


def _configs(
    profile: Profile, kitchen_cfg: KitchenConfig, robot_cfg: RobotConfig, injected: frozenset[str]
) -> tuple[KitchenConfig, RobotConfig]:
    """The kitchen and robot with the profile's overrides, and the gripper weakened for an injected grasp."""
    kcfg, rcfg = profile.apply(kitchen_cfg, robot_cfg)
    if "grasp" in injected:
        g = rcfg.gripper
        rcfg = dataclasses.replace(
            rcfg, gripper=dataclasses.replace(g, max_force=g.max_force * INJECTED_FORCE_FACTOR)
        )
    return kcfg, rcfg


@dataclass(frozen=True)
class _Perceived:
    """What the robot perceived in one execution (its calibration error included).

    Attributes:
        by_name: Product name → the detection the robot acts on.
        context: The target's perceived context (`perceived_context`).
        unit: The shelf unit of the target's detection ("" when not detected).
        slot: The nearest shelf slot of its detection, or None.
    """

    by_name: dict[str, Detection]
    context: ExecutionContext
    unit: str
    slot: int | None


def _perceive(
    kitchen: Any, kcfg: KitchenConfig, seed: int, profile: Profile, target: str, injected: frozenset[str]
) -> _Perceived:
    """Render and detect (looking again, as the tree does, when the target is seen nowhere); shift by the
    profile's calibration error; the target's context (hidden if injected)."""
    from scone_bt.perception.exposure import LOOK_AGAIN_EXPOSURES

    detections, frames = _look(kitchen, kcfg, seed)
    if target not in detections and "perception" not in injected:
        detections, frames = _look(kitchen, kcfg, seed, LOOK_AGAIN_EXPOSURES)
    # What the robot acts on: its camera-to-robot error moves every detection and every depth point alike.
    offset = profile.calibration_offset
    by_name = {n: _shifted(d, offset) for n, d in detections.items()}
    seen_frames = [_miscalibrated(f, offset) for f in frames]
    perceived = by_name if "perception" not in injected else {n: d for n, d in by_name.items() if n != target}
    ctx, unit, slot = perceived_context(target, perceived, seen_frames, kcfg)
    return _Perceived(by_name, ctx, unit, slot)


def _record(
    index: int, seed: int, target: ObjectSpec, seen: _Perceived, attempt: _Attempt
) -> ExecutionRecord:
    """The execution's row: its outcome, the target's perceived context, its true size and mass, and what the
    fingers felt when they hefted it (None: no probe ran)."""
    ctx, felt = seen.context, attempt.felt
    return ExecutionRecord(
        index=index,
        action=action_text(target.name),
        object=target.name,
        success=attempt.success,
        failure_stage=attempt.stage,
        seed=seed,
        detail=attempt.detail,
        family=target.family,
        shelf_unit=seen.unit,
        shelf_tier=ctx.shelf_tier,
        slot=seen.slot,
        clearance_m=ctx.clearance_m,
        neighbours=ctx.neighbours,
        detected=bool(ctx.detected),
        detected_width_m=ctx.detected_width_m,
        detected_height_m=ctx.detected_height_m,
        width_m=round(target.grasp_width, 4),
        height_m=round(target.height, 4),
        mass_kg=round(target.mass, 4),
        material=target.material,
        detected_depth_m=ctx.detected_depth_m,
        detected_fill=ctx.detected_fill,
        depth_m=round(max(target.size[0], target.size[1]), 4),
        shape=str(target.shape.value),
        probe_held=None if felt is None else bool(felt.held),
        probe_load_n=None if felt is None else felt.load_n,
        probe_load_first_n=None if felt is None else felt.load_first_n,
        probe_grip_n=None if felt is None else felt.grip_n,
        probe_s=None if felt is None else felt.seconds,
        probe_pressed=None if felt is None else bool(felt.pressed),
        probe_drift_mm=None if felt is None else felt.drift_mm,
        probe_drift_both_mm=None if felt is None else felt.drift_both_mm,
        probe_wrist_load_n=None if felt is None else felt.wrist_load_n,
        probe_wrist_load_first_n=None if felt is None else felt.wrist_load_first_n,
        probe_in_place=attempt.missed_in_place,
    )


@dataclass(frozen=True)
class _Attempt:
    """An attempt's outcome: success, failure stage (None: none), detail, the heft test's reading (None: the
    motion never hefted the product), and, after fingers that closed on nothing in it, whether the product still
    stood where it stood (None: no such miss)."""

    success: bool
    stage: str | None
    detail: str
    felt: ProbeReading | None = None
    missed_in_place: bool | None = None


def _attempt(
    kitchen: Any,
    rcfg: RobotConfig,
    catalogue: Catalogue,
    target: ObjectSpec,
    seen: _Perceived,
    seed: int,
    injected: frozenset[str],
    probe: ProbeSettings,
    look: Callable[[], Mapping[str, Detection]] | None = None,
) -> _Attempt:
    """Pick and place the target as perceived, hefting it first (``probe``), in simulated time; ``look``: the
    cameras looked through again after a flat pack's slide (`motion.slide`)."""
    by_name = seen.by_name
    if "perception" in injected:
        return _Attempt(False, "perception", "injected: target not detected")
    if target.name not in by_name:
        return _Attempt(False, "perception", f"target not detected ({len(by_name)} products seen)")
    if "planning" in injected:
        return _Attempt(False, "planning", "injected: no plan within the budget")
    obstacles = [(d, catalogue.get(n)) for n, d in by_name.items() if n != target.name]
    with _motion_system(kitchen, rcfg) as system:
        task = system.pick_and_place(by_name[target.name], target, obstacles, rng_seed=seed)
        task.probe = probe
        task.look = look
        task.start()
        settled = None
        while settled is None and kitchen.sim_time < _MAX_SIM_S:
            if task.is_planning():
                task.wait_planned()  # simulated time must not depend on the planning thread's speed
            kitchen.advance(_ADVANCE_S)
            settled = _settled(task)
        felt = task.probe_reading if isinstance(task.probe_reading, ProbeReading) else None
        in_place = task.missed_in_place
        if settled is None:
            task.cancel()
            return _Attempt(False, "timeout", f"not finished after {_MAX_SIM_S:.0f} simulated seconds", felt)
    success, stage, message = settled
    detail = ("injected weak grasp; " if "grasp" in injected else "") + message
    return _Attempt(success, stage, detail, felt, in_place)


def run_execution(
    profile: Profile,
    index: int,
    kitchen_cfg: KitchenConfig,
    robot_cfg: RobotConfig,
    target_name: str | None = None,
    pool: Sequence[ObjectSpec] | None = None,
    engine: str = "sim",
    probe: ProbeSettings = RECORDING_PROBE,
) -> tuple[ExecutionRecord, float]:
    """Run execution `index` of `profile`; returns the record and its wall time (s).

    Args:
        profile: The robot's proficiency.
        index: Execution number; with the profile's seed it fixes the products, their slots and every draw.
        kitchen_cfg: The kitchen before the profile's overrides.
        robot_cfg: The robot before the profile's overrides.
        target_name: Force this target instead of the seeded draw (for per-product sweeps).
        pool: Products to draw from (default: drawable_products of the kitchen's catalogue).
        engine: The backend the execution runs on (`ENGINES`: ``sim`` is PyBullet, ``mujoco``).
        probe: The heft test's settings (default: sensing only, always carrying on; with ``set_back`` a probe
            that sets the product back is recorded as a failure without a stage, its detail saying so).
    """
    t0 = time.perf_counter()
    seed = profile.execution_seed(index)
    target, others = _objects(profile, index, kitchen_cfg, target_name, pool)
    rng = np.random.default_rng([seed, 1])
    injected = profile.draw_injections(target, rng)
    kcfg, rcfg = _configs(profile, kitchen_cfg, robot_cfg, injected)
    kitchen = _WORKER.empty_kitchen(kcfg, rcfg, engine)
    kitchen.spawn([target, *others], rng)
    seen = _perceive(kitchen, kcfg, seed, profile, target.name, injected)
    offset = profile.calibration_offset

    def look() -> dict[str, Detection]:
        detections, _ = _look(kitchen, kcfg, seed, after_slide=True)
        return {n: _shifted(d, offset) for n, d in detections.items()}

    attempt = _attempt(kitchen, rcfg, kitchen_cfg.catalogue, target, seen, seed, injected, probe, look)
    return _record(index, seed, target, seen, attempt), time.perf_counter() - t0


def _settled(task: Any) -> tuple[bool, str | None, str] | None:
    """(success, failure stage, message) once the attempt's outcome is decided, else None.

    The outcome is decided when the arm heads home (after judging the placement, or after a failure); the homing
    motion changes nothing a record holds, and the next execution starts from a restored kitchen, so it is not
    simulated (about a fifth of an execution's physics).
    """
    verdict = task.verdict()
    if verdict is None:
        return None
    success, stage, message = verdict
    return success, None if stage is None else stage.value, message


@dataclass(frozen=True)
class ExecutionTask:
    """One execution as a work item for scone_bt.distributed: small to ship, self-seeded (profile and index).

    Attributes:
        profile: The robot's proficiency.
        index: Execution number (fixes the seed).
        kitchen: Kitchen file name or path, loaded in the worker.
        robot: Robot file name or path, loaded in the worker.
        catalogues: Extra product files (a user's own products), loaded in the worker.
        products: Restrict the draw to these products (None: the whole catalogue).
        engine: The backend it runs on (`ENGINES`).
    """

    profile: Profile
    index: int
    kitchen: str = "kitchen"
    robot: str = "panda"
    catalogues: tuple[str, ...] = ()
    products: tuple[str, ...] | None = None
    engine: str = "sim"


_POOLS: dict[tuple[object, ...], tuple[ObjectSpec, ...]] = {}


def execute_task(task: ExecutionTask) -> tuple[str, ExecutionRecord, float]:
    """Run one ExecutionTask (configs loaded once per worker process); (profile name, record, wall s)."""
    from scone_bt.config import load_kitchen, load_robot

    key = (task.kitchen, task.robot, task.catalogues)
    if key not in _WORKER.configs:
        _WORKER.configs[key] = (load_kitchen(task.kitchen, task.catalogues), load_robot(task.robot))
    kitchen_cfg, robot_cfg = _WORKER.configs[key]
    pool_key = (*key, task.products)
    if pool_key not in _POOLS:
        _POOLS[pool_key] = drawable_products(kitchen_cfg, task.products)
    record, wall = run_execution(
        task.profile, task.index, kitchen_cfg, robot_cfg, pool=_POOLS[pool_key], engine=task.engine
    )
    return task.profile.name, record, wall
