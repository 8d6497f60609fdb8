"""The motion stage's entry point: build the arm model once, then run non-blocking pick-and-place tasks.

    system = MotionSystem.build(cell, robot_cfg)          # heavy: Pinocchio + coal models (once, in setup())
    task = system.pick_and_place(detection, spec, obstacles, rng_seed=7, table_obstacles=seen_on_table)
    task.start()                                          # planning starts in the worker thread
    while not task.done():
        kitchen.advance(0.1)                              # execution advances only with the cell's steps
    outcome = task.outcome()

The cell is a `motion.executor.Workcell`: the arm's executor and the fixed boxes of its cell (`world.Kitchen` in
simulation). Planning (IK, OMPL, ruckig) runs in one worker thread and never touches the cell. Execution is a
controller of the executor (main thread, inside its step: `kitchen.advance` in simulation) that holds the arm until
the plan is ready, so what the arm does depends only
on the seed and the physics steps: the arm holds still for a fixed simulated time (ExecutionSettings.think_s) and
only blocks a physics step if the worker has not finished by then. `progress().is_planning` is true exactly while
the worker computes (a caller may pause simulated time meanwhile), then the phase is READY, then the motion phases
(`MotionPhase`).

What stands on the table comes from the caller (the table camera's detections) or, without them, from the
robot's memory of its own placements (`MotionSystem.placed`); never from the simulator's ground truth. An
exception in the planner (a bug, or a configuration error) is not an outcome of the attempt: it is raised from
the executor's step (`kitchen.advance`) and stops the run.

A flat pack wider than the gripper on a lowest tier is slid and pinched (`motion.slide`) when the task has a way
to look again (`PickAndPlaceTask.look`, the robot's cameras): the slide is planned and executed first, then the
task looks, and plans and executes the pinch and the rest of the pick-and-place as one more plan.
"""

from __future__ import annotations

import concurrent.futures as cf
import dataclasses
from collections.abc import Callable, Mapping, Sequence

import numpy as np

from scone_bt.config import ObjectSpec, RobotConfig
from scone_bt.config.grasp import PLANNERS, GraspParams
from scone_bt.errors import UnknownNameError
from scone_bt.motion.collision import Obstacle, fixed_obstacles
from scone_bt.motion.execution import ExecutionSettings, PickPlaceController
from scone_bt.motion.executor import Workcell
from scone_bt.motion.ledge import Ledge
from scone_bt.motion.model import ArmModel
from scone_bt.motion.new_spot import NewSpot, new_spot
from scone_bt.motion.path_watch import PathWatch
from scone_bt.motion.pick_place import (
    PickPlaceFailure,
    PickPlacePlan,
    PickPlaceRequest,
    Segment,
    detected_obstacle,
    plan_home,
    plan_pick_and_place,
)
from scone_bt.motion.placement import PlacementOptions, TableRegion
from scone_bt.motion.planner import PlannerOptions, silence_ompl
from scone_bt.motion.probe import ProbeReading, ProbeSettings
from scone_bt.motion.slide import (
    SlideFailure,
    SlidePlan,
    carried_size,
    plan_slide,
    slide_distance,
    slide_ledge,
)
from scone_bt.motion.slide_controller import SlideController
from scone_bt.motion.timing import KinematicLimits, limits_of
from scone_bt.motion.types import FailureStage, MotionOutcome, MotionPhase, MotionProgress
from scone_bt.perception.types import Detection

__all__ = ["MotionSystem", "PickAndPlaceTask"]


def _warm_up(arm: ArmModel, home: np.ndarray, static: Sequence[Obstacle]) -> None:
    """One IK step, a collision check of a state and of a segment, a hand check and a timed segment (their answers
    unused), so every compiled kernel is loaded (~0.1 s each the first time in a process)."""
    from scone_bt.motion.collision import CollisionWorld, HandModel
    from scone_bt.motion.model import IKOptions
    from scone_bt.motion.timing import time_path

    arm.ik(arm.fk(home), home, np.random.default_rng(0), IKOptions(restarts=0, max_iterations=1))
    world = CollisionWorld(arm, static)
    world.is_valid(home)
    world.states_valid(np.array([home, home]))
    HandModel(arm, static).colliding(arm.fk(home))
    ones = np.ones(arm.dof)
    time_path(np.array([home, home + 0.01]), KinematicLimits(ones, ones, ones), 100.0)


class MotionSystem:
    """The arm model, the static collision scene and the planning worker of one cell (`Workcell`).

    Build with `MotionSystem.build(cell, robot_cfg)`; call `close()` (or use it as a context manager) to stop the
    worker thread.
    """

    def __init__(
        self,
        cell: Workcell,
        arm: ArmModel,
        planner: PlannerOptions,
        limits: KinematicLimits,
        params: GraspParams,
        settings: ExecutionSettings,
        robot: RobotConfig | None = None,
        placement: PlacementOptions | None = None,
    ) -> None:
        self.cell = cell
        self.arm = arm
        # The robot in the cell (its gripper and control settings may differ from the file the model came from).
        self.robot = robot or cell.robot_config
        self.planner = planner
        self.limits = limits
        self.params = params
        self.settings = settings
        self.placement = placement or PlacementOptions()
        self.table = TableRegion.from_scene(cell.config.scene)
        self.static = fixed_obstacles(self.cell.static_boxes, self.cell.config.scene.floor_z)
        self._worker = cf.ThreadPoolExecutor(max_workers=1, thread_name_prefix="scone-motion")
        # The process's first IK and collision check load the compiled kernels (numba: about half a second): the
        # planning thread does that now, while the robot starts up, rather than in the first plan.
        self._worker.submit(_warm_up, arm, self.home, self.static)
        self._active: PickAndPlaceTask | None = None
        # Where this robot put objects on the table: what it knows stands there when the table is not observed.
        self.placed: dict[str, Obstacle] = {}
        y_axis = arm.fk(self.home)[:3, 1]  # the fingers' closing axis at home
        self.preferred_yaw = float(np.arctan2(y_axis[1], y_axis[0]))

    @classmethod
    def build(
        cls,
        cell: Workcell,
        robot: RobotConfig | None = None,
        *,
        planner: PlannerOptions | None = None,
        params: GraspParams | None = None,
        settings: ExecutionSettings | None = None,
        arm: ArmModel | None = None,
    ) -> MotionSystem:
        """Load the arm's Pinocchio and collision models (robot defaults to the cell's robot), or use ``arm``, a
        model of the same robot file built before (it holds nothing of a cell: episodes run in turn may share it).

        Grasp settings come from the robot file's `grasp:` section. Raises SconeError for a configuration error
        (unknown planner, bad grasp setting) before the robot acts.
        """
        silence_ompl()
        robot = robot or cell.robot_config
        p = robot.planner
        if planner is not None and planner.name not in PLANNERS:
            raise UnknownNameError("planner", planner.name, PLANNERS)
        options = planner or PlannerOptions.of(p)
        if options.backend == "vamp":
            from scone_bt.motion.vamp_planner import VampUnavailableError, vamp_available

            if not vamp_available():  # every plan would be OMPL's, without a word
                raise VampUnavailableError(
                    f"{robot.source}: planner.backend: vamp, but VAMP is not installed; build it with `make vamp` "
                    "or set backend: ompl"
                )
        if arm is not None and arm.config != robot:
            raise ValueError("MotionSystem.build: the arm model was built from another robot configuration")
        return cls(
            cell,
            arm or ArmModel(robot),
            options,
            limits_of(robot),
            params or GraspParams.of(robot),
            settings or ExecutionSettings(),
            robot,
        )

    @property
    def home(self) -> np.ndarray:
        return np.asarray(self.robot.home, dtype=float)

    @property
    def opening(self) -> float:
        """The gripper's full opening, metres."""
        g = self.robot.gripper
        return 2.0 * (g.open_position - g.closed_position)

    def pick_and_place(
        self,
        target: Detection,
        spec: ObjectSpec,
        obstacles: Sequence[tuple[Detection, ObjectSpec]],
        rng_seed: int,
        place_spot: tuple[float, float, float] | None = None,
        table_obstacles: Sequence[tuple[Detection, ObjectSpec]] | None = None,
    ) -> PickAndPlaceTask:
        """A task that moves `target` from the shelf to the table. Cheap; starts nothing.

        Args:
            target: The detected object.
            spec: Its catalogue model.
            obstacles: The other objects seen (on the shelf).
            rng_seed: Seeds planning.
            place_spot: Put it exactly there (x, y, table top z) instead of sampling a free spot.
            table_obstacles: What the table camera sees on the table; None when the table is not observed
                (then the robot knows only what it placed itself).
        """
        table = None if table_obstacles is None else tuple(table_obstacles)
        return PickAndPlaceTask(self, target, spec, tuple(obstacles), int(rng_seed), place_spot, table)

    def close(self) -> None:
        self._worker.shutdown(wait=True, cancel_futures=True)

    def __enter__(self) -> MotionSystem:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class PickAndPlaceTask:
    """One non-blocking pick-and-place: `start()`, then poll `done()` while the cell steps."""

    def __init__(
        self,
        system: MotionSystem,
        target: Detection,
        spec: ObjectSpec,
        obstacles: tuple[tuple[Detection, ObjectSpec], ...],
        rng_seed: int,
        place_spot: tuple[float, float, float] | None,
        table_obstacles: tuple[tuple[Detection, ObjectSpec], ...] | None = None,
    ) -> None:
        self.system = system
        self.table_obstacles = table_obstacles
        self.target = target
        self.spec = spec
        self.obstacles = obstacles
        self.rng_seed = rng_seed
        self.place_spot = place_spot
        self._future: cf.Future[PickPlacePlan | PickPlaceFailure | SlidePlan | SlideFailure] | None = None
        self._controller: PickPlaceController | None = None
        self._outcome: MotionOutcome | None = None
        self._q_start: np.ndarray | None = None
        self._request: PickPlaceRequest | None = None
        self.probe: ProbeSettings | None = None  # set before start(): heft the product first (motion.probe)
        self.judge: Callable[[ProbeReading], tuple[bool, str]] | None = (
            None  # the probe's decision (ProbeController)
        )
        # set before start(): the cameras, looked through again after a slide (by name: the detections seen);
        # None: a flat pack wider than the gripper is not slid (motion.slide), the usual grasps are planned
        self.look: Callable[[], Mapping[str, Detection]] | None = None
        self._ledge: Ledge | None = None  # the slide planned or under way
        self._distance = 0.0  # how far it slides the pack, metres
        self._pinch: Ledge | None = (
            None  # a flat pack's ledge: its front edge is pinched (after a slide or not)
        )
        self._slide: SlideController | None = None  # the slide done, once the pinch is planned

    # ------------------------------------------------------------------------------------- lifecycle
    def submit_plan(self) -> None:
        """Read the arm's joints and submit planning to the worker, without moving (plan before commit)."""
        if self._future is not None or self._outcome is not None:
            return
        sys_ = self.system
        self._q_start = q_start = sys_.arm.as_measured(sys_.cell.arm_joint_positions())
        seen = {d.name for d, _ in self.obstacles} | {self.target.name}
        on_table: dict[str, Obstacle] = {}
        if self.table_obstacles is not None:
            on_table = {d.name: detected_obstacle(d, s) for d, s in self.table_obstacles}
            seen |= set(on_table)
        for name in seen:
            sys_.placed.pop(name, None)  # seen again (or being moved): the detection is the truth now
        # Seen on the table, plus what the robot put there and the camera does not show now.
        table_objects = (*on_table.values(), *sys_.placed.values())
        request = PickPlaceRequest(
            q_start=q_start,
            target=self.target,
            spec=self.spec,
            obstacles=self.obstacles,
            static=sys_.static,
            home=sys_.home,
            rng_seed=self.rng_seed,
            table=sys_.table,
            table_obstacles=table_objects,
            place_spots=() if self.place_spot is None else (self.place_spot,),
            params=sys_.params,
            placement=sys_.placement,
            preferred_yaw=sys_.preferred_yaw,
            opening=sys_.opening,
            finger_closed=sys_.robot.gripper.closed_position,
        )
        rate = sys_.robot.control.rate_hz
        # the skill needs the cameras (to look again after a slide): a caller without them plans the usual grasps
        if self._pinch is None and self._slide is None and sys_.params.slide_pinch and self.look is not None:
            ledge = slide_ledge(self.target, self.spec, sys_.opening, sys_.cell.config.scene)
            distance = 0.0 if ledge is None else slide_distance(self.target, self.spec, ledge)
            if ledge is not None and distance == 0.0:
                self._pinch = ledge  # it sticks out far enough as it stands
            elif ledge is not None:  # slid first, seen again, then pinched
                self._ledge, self._distance = ledge, distance
        if self._pinch is not None:
            request = dataclasses.replace(request, pinch=self._pinch)
        self._request = request
        if self._ledge is not None:
            self._future = sys_._worker.submit(
                plan_slide, sys_.arm, request, self._ledge, self._distance, sys_.planner, sys_.limits, rate
            )
            return
        self._future = sys_._worker.submit(
            plan_pick_and_place, sys_.arm, request, sys_.planner, sys_.limits, rate
        )

    def start(self) -> None:
        """Plan (unless `submit_plan` already did) and register the execution controller: the arm moves."""
        if self._controller is not None or self._outcome is not None:
            return
        sys_ = self.system
        cell = sys_.cell
        if sys_._active is not None and not sys_._active.done():
            sys_._active._abandon()
        sys_._active = self
        self.submit_plan()
        q_start = self._q_start
        assert q_start is not None  # submit_plan read it, now or before
        args = (cell, self.target.name, q_start, self._poll_plan, self._request_home, sys_.settings)
        if self._ledge is not None:
            self._controller = SlideController(*args)
        elif self.probe is not None:
            from scone_bt.motion.probe import ProbeController

            arm = sys_.arm
            self._controller = ProbeController(
                *args,
                on_placed=self._remember,
                request_new_spot=self._request_new_spot,
                watch_path=self._path_watch,
                probe=self.probe,
                hand_z=lambda q: float(arm.fk(q)[2, 3]),
                judge=self.judge,
            )
        else:
            self._controller = PickPlaceController(
                *args,
                on_placed=self._remember,
                request_new_spot=self._request_new_spot,
                watch_path=self._path_watch,
            )
        if self._pinch is not None:
            how = (
                "slid towards me and pinched by its edge"
                if self._slide is not None
                else "pinched by its edge"
            )
            self._controller.spot_notes.append(how)
        cell.add_controller(self._controller)

    def _after_slide(self) -> None:
        """Once the slide has risen off the pack: look again, then plan and start the pinch (a slide that failed
        is the attempt's outcome, as a pick's failure is)."""
        c = self._controller
        if not isinstance(c, SlideController) or not c.finished or not c.slid or self._outcome is not None:
            return
        assert self.look is not None and c.slide is not None
        seen = self.look()
        found = seen.get(self.target.name)
        if found is None:
            start = c.exec_start if c.exec_start is not None else c.start_time
            self._outcome = MotionOutcome(
                False,
                FailureStage.PERCEPTION,
                f"the {self.target.name} was not seen again after sliding it ({len(seen)} products seen)",
                float(self.system.cell.sim_time - start),
                trajectories=tuple(c.executed),
            )
            return
        self._slide, self._pinch, self._ledge = c, c.slide.ledge, None
        self.target = found
        self.obstacles = tuple((d, s) for d, s in self.obstacles if d.name != found.name)
        self._future, self._controller = None, None
        self.start()

    def _poll_plan(self, block: bool) -> object | None:
        fut = self._future
        if fut is None or fut.cancelled():
            return None
        if not block and not fut.done():
            return None
        exc = fut.exception()
        return exc if exc is not None else fut.result()

    def _remember(self) -> None:
        c = self._controller
        placed = None if c is None else c.placed_at
        if placed is not None:
            self.system.placed[self.target.name] = placed

    def _path_watch(self, plan: PickPlacePlan) -> PathWatch:
        """The carry's watch (`motion.path_watch`): the held product as this plan grasps it, and what the request
        knew stood on the table."""
        request = self._request
        assert request is not None and plan.feasible is not None
        cand = plan.feasible.cand
        carried = Obstacle(
            self.target.name, self.spec.shape, carried_size(self.spec, cand), cand.object_in_ee
        )
        return PathWatch.of(self.system.arm, carried, plan.finger_position, request.table_obstacles)

    def _request_new_spot(
        self,
        rest: np.ndarray,
        original: tuple[Segment, ...],
        placed: Obstacle,
        spot: tuple[float, float, float],
        blockers: tuple[Obstacle, ...],
        spot_taken: bool,
    ) -> Callable[[bool], tuple[bool, NewSpot | None]]:
        """Ask the worker for the rest of the motion to another spot (`motion.new_spot`); returns a poll(block)."""
        sys_ = self.system
        plan = self.plan
        assert self._request is not None and isinstance(plan, PickPlacePlan) and plan.feasible is not None
        fut = sys_._worker.submit(
            new_spot,
            sys_.arm,
            self._request,
            plan.feasible,
            plan.finger_position,
            rest,
            original,
            placed,
            spot,
            blockers,
            spot_taken,
            sys_.planner,
            sys_.limits,
            sys_.robot.control.rate_hz,
        )

        def poll(block: bool) -> tuple[bool, NewSpot | None]:
            if not block and not fut.done():
                return False, None
            return True, fut.result()  # a planner exception is an error, raised into the cell's step

        return poll

    def _request_home(self, q: np.ndarray) -> Callable[[bool], tuple[bool, Segment | None]]:
        sys_ = self.system
        fut = sys_._worker.submit(
            plan_home,
            sys_.arm,
            q,
            sys_.home,
            sys_.static,
            sys_.planner,
            sys_.limits,
            sys_.robot.control.rate_hz,
            self.rng_seed + 1,
        )

        def poll(block: bool) -> tuple[bool, Segment | None]:
            if not block and not fut.done():
                return False, None
            return True, fut.result()  # a planner exception is an error, raised into the cell's step

        return poll

    def cancel(self) -> None:
        """The human takes over: hold, open the gripper, go home; the outcome's stage is CANCELLED."""
        if self._outcome is not None:
            return
        if self._controller is None:
            self._outcome = MotionOutcome(False, FailureStage.CANCELLED, "cancelled before it started", 0.0)
            return
        if self._future is not None:
            self._future.cancel()
        self._controller.fail(FailureStage.CANCELLED, "the human took over")

    def _abandon(self) -> None:
        """Another task takes the arm: stop this one where it is."""
        c = self._controller
        if c is not None and not c.finished:
            c.fail(FailureStage.CANCELLED, "superseded by another motion")
            c.finished = True
            self.system.cell.remove_controller(c)

    # ------------------------------------------------------------------------------------- polling
    def is_planning(self) -> bool:
        """True while the worker is still planning the pick-and-place."""
        return self._future is not None and not self._future.done()

    def wait_planned(self, timeout: float | None = None) -> bool:
        """Block until planning finished (tests and benchmarks only; behaviours poll instead)."""
        if self._future is None:
            return True
        try:
            self._future.exception(timeout=timeout)
        except cf.TimeoutError:
            return False
        except cf.CancelledError:
            return True
        return True

    @property
    def plan(self) -> PickPlacePlan | PickPlaceFailure | SlidePlan | SlideFailure | None:
        """The worker's result once it is ready (a flat pack's slide first, then its pinch: `look`)."""
        fut = self._future
        if fut is None or not fut.done() or fut.cancelled() or fut.exception() is not None:
            return None
        return fut.result()

    def done(self) -> bool:
        self._after_slide()  # progress() and verdict() pass through here first
        if self._outcome is not None:
            return True
        c = self._controller
        return c is not None and c.finished

    def progress(self) -> MotionProgress:
        """Current phase and the fraction of the planned motion executed so far."""
        if self.done():
            return MotionProgress(MotionPhase.DONE, 1.0)
        c = self._controller
        if c is None:
            return MotionProgress(MotionPhase.IDLE, 0.0)
        if c.phase is MotionPhase.PLANNING:
            # PLANNING only while the worker computes: a caller may pause simulated time during it.
            return MotionProgress(MotionPhase.PLANNING if self.is_planning() else MotionPhase.READY, 0.0)
        frac = c.done_exec_s / c.total_exec_s if c.total_exec_s > 0 else 0.0
        return MotionProgress(c.phase, float(min(1.0, frac)))

    HOMEWARD: frozenset[MotionPhase] = frozenset(
        {MotionPhase.HOME, MotionPhase.RECOVER, MotionPhase.RECOVER_HOME}
    )
    """Phases after the outcome is decided: the arm only heads home."""

    def verdict(self) -> tuple[bool, FailureStage | None, str] | None:
        """(success, failure stage, message) as soon as the outcome is decided, before the arm is back home.

        A batch that restores the kitchen after each attempt (the self-confidence generator) stops here: the
        homing motion changes nothing the outcome holds. None while the outcome is still open.
        """
        if self.done():
            out = self.outcome()
            assert out is not None
            return out.success, out.stage, out.message
        c = self._controller
        if c is None or c.phase not in self.HOMEWARD:
            return None
        if getattr(c, "aborted", False):
            return False, None, c.message
        return c.success, None if c.success else (c.stage or FailureStage.PLACE), c.message

    @property
    def probe_reading(self) -> object | None:
        """What the heft test felt (motion.probe.ProbeReading) once it held the product up; None before or
        without one."""
        return getattr(self._controller, "reading", None)

    @property
    def missed_in_place(self) -> bool | None:
        """After a heft test's fingers closed on nothing: whether the product still stood where it stood (the
        outcome sensor's look, once the hand had left); None otherwise."""
        return getattr(self._controller, "missed_in_place", None)

    def outcome(self) -> MotionOutcome | None:
        """How it ended, once `done()`; else None.

        Raises:
            Exception: the planner's own exception, if planning raised one (it is not an outcome).
        """
        self._after_slide()
        if self._outcome is not None:
            return self._outcome
        c = self._controller
        if c is None or not c.finished:
            return None
        if c.error is not None:
            raise c.error  # planning broke (a bug or a configuration error): there is no outcome to record
        first = self._slide or c  # a slid pack's attempt began with the slide
        start = first.exec_start if first.exec_start is not None else first.start_time
        end = c.end_time if c.end_time is not None else self.system.cell.sim_time
        slid = tuple(self._slide.executed) if self._slide is not None else ()
        ee = c.plan.ee_path(self.system.arm) if c.plan is not None else None
        aborted = bool(getattr(c, "aborted", False)) and c.stage is None
        stage = None if c.success or aborted else (c.stage or FailureStage.PLACE)
        self._outcome = MotionOutcome(
            success=c.success,
            stage=stage,
            message=c.message,
            duration=float(end - start),
            trajectories=(*slid, *c.executed),
            ee_path=ee,
            reason=c.reason,
            still_held=c.still_held,
            aborted=aborted,
            probe=getattr(c, "reading", None),
            probe_reason=getattr(c, "probe_reason", ""),
        )
        return self._outcome
