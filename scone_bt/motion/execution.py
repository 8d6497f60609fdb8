"""Executing a planned pick-and-place: a controller of the arm's executor, driven only by its control steps.

The controller runs before every control step (a physics step in simulation; main thread). It tracks the timed
trajectories with position control and velocity feed-forward, closes the gripper with the YAML's force limit, and
watches the arm's own sensors through the executor (`motion.executor.ArmExecutor`): finger contacts and finger gap
(is the object still held?), arm contacts and tracking error (collision). While carrying it looks at the place
spot and at the rest of its way over the table, and plans the rest of the motion anew when a person put something
there (`motion.new_spot`, `motion.path_watch`). No simulator is imported here.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from scone_bt.motion.collision import Obstacle
from scone_bt.motion.executor import ArmExecutor
from scone_bt.motion.new_spot import SPOT_CHECK_S, SPOT_MARGIN, NewSpot
from scone_bt.motion.path_watch import PathWatch
from scone_bt.motion.pick_place import PickPlacePlan, Segment
from scone_bt.motion.types import PLACED, FailureStage, MotionPhase, PlanFailureReason, TimedTrajectory

__all__ = ["ExecutionSettings", "PickPlaceController"]

_WAITS = frozenset({MotionPhase.CLOSE, MotionPhase.RELEASE, MotionPhase.SETTLE, MotionPhase.ALIGN})
"""Phases in which the arm holds still for a while (no trajectory)."""
_NEAR_OBJECTS = frozenset({MotionPhase.DESCEND, MotionPhase.LIFT, MotionPhase.LOWER, MotionPhase.RETREAT})
"""Phases in which the gripper may touch things (the object, its neighbours, the table)."""
_CARRYING = frozenset({MotionPhase.LIFT, MotionPhase.TRANSIT, MotionPhase.LOWER})
_HOMING = frozenset({MotionPhase.HOME, MotionPhase.RECOVER_HOME})
CONTACT_CHECK_S = 1.0 / 60.0
"""Simulated seconds between two collision checks while a segment is tracked."""
SLIP_CHECK_S = 0.1
"""Simulated seconds between two checks that the carried object is still between the fingers."""


WATCH_S = 1.0 / 30.0
"""Simulated seconds between two notes of what the arm or the carried product touches (knocked-over products)."""
MAX_NEW_SPOTS = 2
"""Most times one attempt moves to another place spot (a person may take the next one too)."""

NewSpotRequest = Callable[
    [np.ndarray, tuple[Segment, ...], Obstacle, tuple[float, float, float], tuple[Obstacle, ...], bool],
    Callable[[bool], tuple[bool, NewSpot | None]],
]
"""request(rest of the transit, lower/retreat/home segments, placed shape, spot, blockers, something stands on the
spot) -> poll(block)."""


def _every(seconds: float, time_step: float) -> int:
    """Control steps in `seconds` (at least one): checks run at the same simulated rate whatever the physics step."""
    return max(1, round(seconds / time_step))


@dataclass(frozen=True)
class ExecutionSettings:
    """Durations (simulated seconds) and sensor thresholds of execution.

    Attributes:
        close_s: Time given to the fingers to close on the object.
        open_s: Time given to the fingers to open before retreating.
        settle_s: Wait after retreating before judging the placement.
        align_s: Longest wait above the object for the arm to catch up with its command before descending.
        align_tolerance: Joint error (rad) at which the arm counts as caught up.
        min_gap: Finger opening (m, both fingers together) below which nothing is between the fingers.
        max_tracking_error: Joint error (rad) that means the arm is blocked.
        min_contact_force: Normal force (N) for a contact to count.
        max_duration_s: Simulated time after which the attempt is a timeout (planning wait included).
        think_s: Simulated time the arm holds still while the worker plans (half of it to plan a way home).
    """

    close_s: float = 0.6
    open_s: float = 0.4
    settle_s: float = 0.3
    align_s: float = 0.6
    align_tolerance: float = 0.005
    min_gap: float = 0.004
    max_tracking_error: float = 0.2
    min_contact_force: float = 0.5
    max_duration_s: float = 45.0
    think_s: float = 0.3


class PickPlaceController:
    """The per-step state machine of one pick-and-place. Register with `arm.add_controller`.

    Args:
        arm: The arm's executor (the simulated kitchen, or a real arm's backend).
        target_name: Catalogue name of the object (only for the final outcome sensor, `arm.is_on_table`).
        hold: (dof,) joints to hold while the plan is not ready.
        plan_ready: plan_ready(block) returns the finished plan (or a failure), else None; block=True waits for it.
        request_home: Asks the worker for a way home from given joints; returns a poll(block) function.
        settings: Durations and thresholds.
        on_placed: Called once when the object is seen resting on the table after the release.
        request_new_spot: Asks the worker for the rest of the motion to another spot when the planned one is
            taken during the carry (`motion.new_spot`); None: the spot is not looked at again.
        watch_path: The plan's `PathWatch` (`motion.path_watch`): a product put down in the carry's way is looked
            for too, and the rest of the motion planned anew with it known; None: only the spot is looked at.
    """

    def __init__(
        self,
        arm: ArmExecutor,
        target_name: str,
        hold: np.ndarray,
        plan_ready: Callable[[bool], object | None],
        request_home: Callable[[np.ndarray], Callable[[bool], tuple[bool, Segment | None]]],
        settings: ExecutionSettings = ExecutionSettings(),
        on_placed: Callable[[], None] | None = None,
        request_new_spot: NewSpotRequest | None = None,
        watch_path: Callable[[PickPlacePlan], PathWatch] | None = None,
    ) -> None:
        self.arm = arm
        self._request_new_spot = request_new_spot
        self._watch_path = watch_path
        self._path_watch: PathWatch | None = None
        self._on_placed = on_placed
        self.target_name = target_name
        self.settings = settings
        self.cfg = arm.robot_config
        self._plan_ready = plan_ready
        self._request_home = request_home
        self.hold_q = np.asarray(hold, dtype=float)
        self.phase = MotionPhase.PLANNING
        self.phase_steps = 0
        self.start_time = arm.sim_time
        self.exec_start: float | None = None
        self.plan: PickPlacePlan | None = None
        self.queue: list[tuple[MotionPhase, Segment | None]] = []
        self.current: Segment | None = None
        self.executed: list[TimedTrajectory] = []
        self.held: str | None = None  # what the fingers closed on
        self.still_held: str | None = None  # what the fingers still grip when the attempt ends (stuck)
        self.stage: FailureStage | None = None
        self.reason: PlanFailureReason | None = None
        self.error: BaseException | None = None  # a planner exception: the run stops, no outcome
        self.message = ""
        self.success = False
        self.finished = False
        self.end_time: float | None = None
        self._home_poll: Callable[[bool], tuple[bool, Segment | None]] | None = None
        self.total_exec_s = 0.0
        self.done_exec_s = 0.0
        # From the transit on, every product the arm or the carried one touched (directly or through another
        # product), and those of them that stood upright on the table when first touched: one of those that stands
        # there no more when the attempt ends was knocked over by it.
        self.watching = False
        self.touched: set[str] = set()
        self.stood: set[str] = set()
        # Where the product goes (the plan's spot, or another one taken during the carry), and the look at it.
        self.placed_at: Obstacle | None = None
        self.place_spot: tuple[float, float, float] | None = None
        self.spot_changes = 0
        self.spot_notes: list[str] = []
        self.spot_taken_by: tuple[str, ...] = ()
        self.in_the_way: tuple[str, ...] = ()  # products put down in the carry's way (`motion.path_watch`)
        self._looking = request_new_spot is not None
        self._spot_poll: Callable[[bool], tuple[bool, NewSpot | None]] | None = None

    # ------------------------------------------------------------------------------------- commands
    def _command(self, q: np.ndarray, qd: np.ndarray | None = None) -> None:
        self.arm.command_arm(q, qd)

    def _gripper(self, closed: bool, release: bool = False) -> None:
        """Close with the force limit, or open as far as the plan's pre-shape (fully without a plan).

        Opening to release (`release`) never moves a finger inwards: a light object is often held off-centre (one finger pushed it across
        while closing), and a pre-shape narrower than where that finger stands would shove the released object
        sideways and topple it.
        """
        g = self.cfg.gripper
        opened = g.open_position
        if self.plan is not None and self.plan.finger_position is not None:
            opened = self.plan.finger_position
            if release:
                widest = float(np.max(self.arm.gripper_positions()))
                opened = float(min(g.open_position, max(opened, widest)))
        self.arm.set_gripper_target(g.closed_position if closed else opened, g.max_force)

    # ------------------------------------------------------------------------------------- state machine
    def _enter(self, phase: MotionPhase) -> None:
        self.phase = phase
        self.phase_steps = 0

    def _next(self) -> None:
        if not self.queue:
            self._finish()
            return
        phase, seg = self.queue.pop(0)
        self.current = seg
        self._enter(phase)
        if phase is MotionPhase.TRANSIT:
            self.watching = True
        if phase is MotionPhase.CLOSE:
            self._gripper(True)
        elif phase is MotionPhase.RELEASE:
            self._gripper(False, release=True)

    def fail(self, stage: FailureStage, message: str) -> None:
        """Stop what the arm is doing, open the hand and go home; the outcome keeps this stage."""
        if self.stage is not None or self.finished:
            return
        self.stage, self.message = stage, message
        self._knocked_over()
        self._gripper(False, release=True)
        self.queue = []
        if self.phase is MotionPhase.PLANNING or self.exec_start is None:
            self._finish()
            return
        self.hold_q = self.arm.arm_joint_positions()
        self._home_poll = self._request_home(self.hold_q)
        self._enter(MotionPhase.RECOVER)

    def _finish(self) -> None:
        self.still_held = self._stuck()
        self.finished = True
        self.end_time = self.arm.sim_time
        self.phase = MotionPhase.DONE
        self._command(self.hold_q)
        self.arm.remove_controller(self)

    def __call__(self, arm: ArmExecutor) -> None:
        if self.finished:
            return
        s = self.settings
        dt = arm.time_step
        if arm.sim_time - self.start_time > s.max_duration_s and self.stage is None:
            self.fail(FailureStage.TIMEOUT, f"not finished after {s.max_duration_s:.0f} s")
        phase = self.phase
        # Thinking takes a fixed simulated time: the arm starts moving at the same physics step however long the
        # worker needed in wall time (it blocks here only if the worker is slower than that), so a seeded attempt
        # repeats exactly.
        if phase is MotionPhase.PLANNING:
            self._command(self.hold_q)
            if self.phase_steps * dt >= s.think_s:
                self._start_plan(self._plan_ready(True))
        elif phase is MotionPhase.NEW_SPOT:
            self._command(self.hold_q)
            assert self._spot_poll is not None
            # Taken up at a fixed simulated time, as the first plan and the way home are: a seeded run repeats.
            if self.phase_steps * dt >= s.think_s / 2:
                done, spot = self._spot_poll(True)
                if done:
                    assert spot is not None
                    self._take_new_spot(spot)
        elif phase is MotionPhase.RECOVER:
            self._command(self.hold_q)
            assert self._home_poll is not None
            # As for the first plan: the way home is taken up at a fixed simulated time, never earlier because the
            # worker happened to be fast, so a seeded run repeats exactly.
            done, seg = (False, None)
            if self.phase_steps * dt >= s.think_s / 2:
                done, seg = self._home_poll(True)
            if done:
                if seg is None:
                    self.message += "; the arm could not plan its way home"
                    self._finish()
                else:
                    self.queue = []
                    self.current = seg
                    self._enter(MotionPhase.RECOVER_HOME)
        elif phase in _WAITS:
            self._command(self.hold_q)
            duration = {
                MotionPhase.CLOSE: s.close_s,
                MotionPhase.RELEASE: s.open_s,
                MotionPhase.SETTLE: s.settle_s,
                MotionPhase.ALIGN: s.align_s,
            }[phase]
            # Aligning ends early once the arm has caught up with its command (tracking lags during motion).
            aligned = (
                phase is MotionPhase.ALIGN
                and np.max(np.abs(arm.arm_joint_positions() - self.hold_q)) < s.align_tolerance
            )
            if self.phase_steps * dt >= duration or aligned:
                self._after_wait(phase)
        else:
            self._track(arm)
        if self.watching and not self.finished and self.phase_steps % _every(WATCH_S, dt) == 0:
            self._watch_table(arm)
        self.phase_steps += 1

    def _watch_table(self, arm: ArmExecutor) -> None:
        """Note the products touched now and, of those touched for the first time, which stood on the table."""
        new = arm.products_touched(self.held) - self.touched - {self.target_name}
        if new:
            self.touched |= new
            self.stood.update(n for n in new if arm.is_on_table(n))

    def _knocked_over(self) -> None:
        """Products this attempt knocked over or off the table: the arm or the carried product touched them
        (directly or through another product) while they stood upright there, and they stand there no more. A
        placement that did so is not a success (the person sees the damage); a failed attempt's message says it
        too. Judged once, when the outcome is decided (after the settle, or at a failure), before the way home."""
        if not self.watching:
            return
        self.watching = False
        if not self.stood:
            return
        lost = self.stood - self.arm.objects_on_table()
        if not lost:
            return
        what = f"knocked {', '.join(sorted(lost))} over or off the table"
        if self.success:
            self.success = False
            self.stage = FailureStage.COLLISION
            self.message = f"{self.message}, but {what}"
        else:
            self.message = f"{self.message}; it {what}" if self.message else what

    def _start_plan(self, ready: object) -> None:
        from scone_bt.motion.pick_place import PickPlaceFailure

        if ready is None:
            self.fail(FailureStage.PLANNING, "planning was cancelled")
            return
        if isinstance(ready, BaseException):
            # A bug or a configuration error, not an outcome of the attempt: stop here and let it end the run
            # (it propagates out of the executor's step, e.g. kitchen.advance) instead of being stored as experience.
            self.error = ready
            self._finish()
            raise ready
        if isinstance(ready, PickPlaceFailure):
            self.reason = ready.reason
            self.fail(ready.stage, ready.message)
            return
        assert isinstance(ready, PickPlacePlan)
        self.plan = ready
        self.placed_at, self.place_spot = ready.placed, ready.place_spot
        self._looking = self._looking and ready.placed is not None and ready.feasible is not None
        if self._looking and self._watch_path is not None:
            self._path_watch = self._watch_path(ready)
        seg = {s.phase: s for s in ready.segments}
        self.queue = [
            (MotionPhase.APPROACH, seg[MotionPhase.APPROACH]),
            (MotionPhase.ALIGN, None),
            (MotionPhase.DESCEND, seg[MotionPhase.DESCEND]),
            (MotionPhase.CLOSE, None),
            (MotionPhase.LIFT, seg[MotionPhase.LIFT]),
            (MotionPhase.TRANSIT, seg[MotionPhase.TRANSIT]),
            (MotionPhase.LOWER, seg[MotionPhase.LOWER]),
            (MotionPhase.RELEASE, None),
            (MotionPhase.RETREAT, seg[MotionPhase.RETREAT]),
            (MotionPhase.SETTLE, None),
            (MotionPhase.HOME, seg[MotionPhase.HOME]),
        ]
        self.total_exec_s = (
            sum(x.trajectory.duration for x in ready.segments) + self.settings.close_s + self.settings.open_s
        )
        self.exec_start = self.arm.sim_time
        self.arm.couple_fingers()
        self._gripper(False)  # pre-shaped while approaching: the fingers fit between close neighbours
        self._next()

    def _after_wait(self, phase: MotionPhase) -> None:
        if phase is MotionPhase.CLOSE:
            self.held = self.arm.held_object(self.settings.min_contact_force)
            if self.held is None or self._finger_gap() < self.settings.min_gap:
                self.fail(FailureStage.GRASP, "the fingers closed without holding the object")
                return
        elif phase is MotionPhase.SETTLE:
            if self.arm.is_on_table(self.target_name):
                self.success = True
                self.message = PLACED + "".join(f" ({n})" for n in self.spot_notes)
                if self._on_placed is not None:
                    self._on_placed()
            else:
                self.stage = FailureStage.PLACE
                stuck = self._stuck()
                self.message = (
                    f"released, but the {stuck} stuck between the open fingers"
                    if stuck is not None
                    else "released, but the object is not resting upright on the table"
                )
            self._knocked_over()
        self.hold_q = self.current.trajectory.positions[-1] if self.current is not None else self.hold_q
        self._next()

    def _track(self, arm: ArmExecutor) -> None:
        seg = self.current
        assert seg is not None
        traj = seg.trajectory
        k = min(int(round(self.phase_steps * arm.time_step * self.cfg.control.rate_hz)), len(traj.times) - 1)
        self._command(traj.positions[k], traj.velocities[k])
        self.hold_q = traj.positions[k]
        self.done_exec_s += arm.time_step
        phase = self.phase
        if self.stage is None and self._check(phase, traj.positions[k]):
            return
        if phase is MotionPhase.TRANSIT and self._spot_taken(arm, k):
            return
        if k >= len(traj.times) - 1:
            self.executed.append(traj)
            if phase is MotionPhase.RECOVER_HOME:
                self._finish()
                return
            if phase in (MotionPhase.LIFT, MotionPhase.LOWER) and self.stage is None and not self._holding():
                lifting = phase is MotionPhase.LIFT
                self.fail(
                    FailureStage.GRASP if lifting else FailureStage.TRANSIT,
                    f"the object slipped out of the gripper while {'lifting' if lifting else 'lowering'}",
                )
                return
            self._next()

    def _spot_taken(self, arm: ArmExecutor, k: int) -> bool:
        """While carrying, look at the place spot and, with a `PathWatch`, at the carry's way; if something stands
        on the spot or in the way now, hold and ask the worker for the rest of the motion from here, with what
        the plan did not know on the table known (True: the arm holds from now on)."""
        if not self._looking or self.stage is not None or self.placed_at is None:
            return False
        if self.phase_steps % _every(SPOT_CHECK_S, arm.time_step):
            return False
        if self._request_new_spot is None or self.current is None:
            return False
        mine = {self.target_name} | ({self.held} if self.held is not None else set())
        rest = self.current.trajectory.positions[k:]
        on_spot = tuple(b for b in arm.products_at(self.placed_at, SPOT_MARGIN) if b.name not in mine)
        unknown: tuple[Obstacle, ...] = ()
        in_way: tuple[Obstacle, ...] = ()
        if self._path_watch is not None:
            unknown = self._path_watch.unknown(arm.table_products(), mine)
            if unknown and not on_spot:
                in_way = self._path_watch.in_the_way(rest, self._lowering(), unknown)
        if not on_spot and not in_way:
            return False
        assert self.place_spot is not None
        original = tuple(seg for _, seg in self.queue if seg is not None)  # lower, retreat, home
        self.spot_taken_by = tuple(sorted(b.name for b in on_spot))
        self.in_the_way = tuple(sorted(b.name for b in in_way))
        # What the plan did not know, all of it (and all learnt at earlier re-plans): the rest of the motion avoids it.
        blockers = tuple({b.name: b for b in (*unknown, *on_spot)}.values())
        if self._path_watch is not None:
            blockers = self._path_watch.learn(blockers)
        self._spot_poll = self._request_new_spot(
            rest, original, self.placed_at, self.place_spot, blockers, bool(on_spot)
        )
        self.hold_q = rest[0]
        self._enter(MotionPhase.NEW_SPOT)
        return True

    def _lowering(self) -> np.ndarray | None:
        """The queued lowering's commanded samples (None when none is queued)."""
        for phase, seg in self.queue:
            if phase is MotionPhase.LOWER and seg is not None:
                return seg.trajectory.positions
        return None

    def _take_new_spot(self, spot: NewSpot) -> None:
        """Carry on with the worker's answer: to another spot, or the original plan resumed (none was found)."""
        self._spot_poll = None
        if self.spot_taken_by:
            taken = ", ".join(self.spot_taken_by)
            moved, kept = (
                f"at another spot: {taken} stood on the one planned",
                f"{taken} stood on the planned spot",
            )
        else:
            taken = ", ".join(self.in_the_way)
            moved, kept = f"another way: {taken} was put down in its way", f"{taken} was put down in its way"
        if spot.moved:
            self.spot_changes += 1
            self._looking = self.spot_changes < MAX_NEW_SPOTS
            self.spot_notes.append(moved)
        else:
            self._looking = False  # going on as planned: looking again would only stop it again
            self.spot_notes.append(f"{kept}, and {spot.why}")
        self.placed_at, self.place_spot = spot.placed, spot.place_spot
        transit, lower, retreat, home = spot.segments
        self.queue = [
            (MotionPhase.LOWER, lower),
            (MotionPhase.RELEASE, None),
            (MotionPhase.RETREAT, retreat),
            (MotionPhase.SETTLE, None),
            (MotionPhase.HOME, home),
        ]
        self.total_exec_s = (
            self.done_exec_s + sum(x.trajectory.duration for x in spot.segments) + self.settings.open_s
        )
        self.current = transit
        self._enter(MotionPhase.TRANSIT)

    def _finger_gap(self) -> float:
        """Both fingers' opening together, metres."""
        return float(np.sum(self.arm.gripper_positions()))

    def _stuck(self) -> str | None:
        """What the fingers closed on, if both still touch it though they were told to open (stuck between them)."""
        gripped = self.arm.held_object(self.settings.min_contact_force * 0.2)
        return gripped if self.held is not None and gripped == self.held else None

    def _holding(self) -> bool:
        held = self.arm.held_object(self.settings.min_contact_force * 0.2)
        return held is not None and held == self.held and self._finger_gap() >= self.settings.min_gap

    def _check(self, phase: MotionPhase, q_cmd: np.ndarray) -> bool:
        """Collision and slip monitoring during a tracked segment; True if the attempt just failed."""
        s = self.settings
        dt = self.arm.time_step
        if self.phase_steps % _every(CONTACT_CHECK_S, dt):
            return False
        near_objects = phase in _NEAR_OBJECTS
        link = self.arm.unexpected_contact(
            near_objects, self.held if phase in _CARRYING else None, s.min_contact_force
        )
        if link is not None and phase not in _HOMING:
            self.fail(FailureStage.COLLISION, f"{link} during {phase}")
            return True
        if not near_objects and phase not in _HOMING:
            err = float(np.max(np.abs(self.arm.arm_joint_positions() - q_cmd)))
            if err > s.max_tracking_error:
                self.fail(
                    FailureStage.COLLISION, f"the arm was blocked during {phase} (joint error {err:.2f} rad)"
                )
                return True
        if (
            phase is MotionPhase.TRANSIT
            and self.phase_steps % _every(SLIP_CHECK_S, dt) == 0
            and not self._holding()
        ):
            self.fail(FailureStage.TRANSIT, "the object dropped out of the gripper while carrying it")
            return True
        return False
