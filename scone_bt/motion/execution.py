"""Executing a planned pick-and-place in PyBullet (adapter): a Kitchen controller driven only by physics steps.

The controller runs before every physics step (main thread). It tracks the timed trajectories with position
control and velocity feed-forward, closes the gripper with the YAML's force limit, and watches its own sensors:
finger contacts and finger gap (is the object still held?), arm contacts and tracking error (collision). Grasp
success comes from contacts and friction only; nothing attaches the object to the hand.
"""

from __future__ import annotations

import weakref
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from scone_bt.motion.pick_place import PickPlacePlan, Segment
from scone_bt.motion.types import FailureStage, MotionPhase, PlanFailureReason, TimedTrajectory

if TYPE_CHECKING:
    from scone_bt.world import Kitchen

__all__ = ["ExecutionSettings", "ArmSensors", "PickPlaceController"]

_WAITS = frozenset({MotionPhase.CLOSE, MotionPhase.RELEASE, MotionPhase.SETTLE, MotionPhase.ALIGN})
"""Phases in which the arm holds still for a while (no trajectory)."""
_NEAR_OBJECTS = frozenset({MotionPhase.DESCEND, MotionPhase.LIFT, MotionPhase.LOWER, MotionPhase.RETREAT})
"""Phases in which the gripper may touch things (the object, its neighbours, the table)."""
_CARRYING = frozenset({MotionPhase.LIFT, MotionPhase.TRANSIT, MotionPhase.LOWER})
_HOMING = frozenset({MotionPhase.HOME, MotionPhase.RECOVER_HOME})


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


FINGER_COUPLING_FORCE = 50.0
"""Largest force (N) of the coupling that keeps the two fingers symmetric (the gearing of a parallel gripper)."""

_COUPLINGS: weakref.WeakKeyDictionary[Kitchen, int] = weakref.WeakKeyDictionary()
"""The finger coupling of each kitchen's robot, made once and kept for the kitchen's life."""


def couple_fingers(kitchen: Kitchen) -> int | None:
    """Couple the two fingers so that they move symmetrically, as a parallel gripper's gearing does; the id.

    Both grippers are parallel grippers whose fingers one drive moves together (the Franka Hand through a rack,
    the iiwa7's primitive gripper by design), but the URDFs give each finger its own joint: closed with equal
    forces, a held object and both fingers then slide sideways together under the carry's accelerations until a
    finger meets its limit, and a light object is shoved across while closing and released off-centre. A gear
    constraint (PyBullet's way to model that gearing) keeps the joints equal. None without exactly two fingers.
    """
    import pybullet as p

    bc, rid = kitchen.bc, kitchen.robot_id
    known = _COUPLINGS.get(kitchen)
    if known is not None:
        try:
            bc.getConstraintInfo(known)
            return known
        except Exception:  # noqa: BLE001 (pybullet raises a plain error for a removed constraint)
            pass
    joints = [kitchen.joint_index[n] for n in kitchen.robot_config.gripper.joints]
    if len(joints) != 2:
        return None
    cid = bc.createConstraint(
        rid, joints[0], rid, joints[1], p.JOINT_GEAR, [1.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]
    )
    # Both finger joints open with a positive position along mirrored axes: equal joint positions are symmetric.
    bc.changeConstraint(cid, gearRatio=-1.0, erp=0.1, maxForce=FINGER_COUPLING_FORCE)
    _COUPLINGS[kitchen] = cid
    return cid


class ArmSensors:
    """What the robot can sense about itself in the simulator: joint states, finger contacts, arm contacts."""

    def __init__(self, kitchen: Kitchen) -> None:
        self.kitchen = kitchen
        bc = kitchen.bc
        rid = kitchen.robot_id
        cfg = kitchen.robot_config
        self.arm_ids = [kitchen.joint_index[n] for n in cfg.arm_joints]
        self.finger_ids = [kitchen.joint_index[n] for n in cfg.gripper.joints]
        # Links at or below the last arm joint's child that are not on the arm chain: hand and fingers.
        last = self.arm_ids[-1]
        self.gripper_links = set(self.finger_ids)
        for j in range(bc.getNumJoints(rid)):
            if j > last and j not in self.arm_ids:
                self.gripper_links.add(j)

    def held_body(self, min_force: float) -> int | None:
        """A body touched by every finger with at least min_force newtons, else None."""
        bc, rid = self.kitchen.bc, self.kitchen.robot_id
        common: set[int] | None = None
        for f in self.finger_ids:
            bodies = {
                c[2]
                for c in bc.getContactPoints(bodyA=rid, linkIndexA=f)
                if c[2] != rid and c[9] >= min_force
            }
            common = bodies if common is None else common & bodies
        return min(common) if common else None

    def finger_gap(self) -> float:
        return float(np.sum(self.kitchen.gripper_positions()))

    def unexpected_contact(self, allow_gripper: bool, held: int | None, min_force: float) -> str | None:
        """Name of the first robot link pushing on something it should not touch, else None."""
        bc, rid = self.kitchen.bc, self.kitchen.robot_id
        for c in bc.getContactPoints(bodyA=rid):
            body, link, force = c[2], c[3], c[9]
            if body == rid or link < 0 or force < min_force:
                continue
            if link in self.gripper_links and (allow_gripper or body == held):
                continue
            return f"{bc.getJointInfo(rid, link)[12].decode()} hit {self._body_name(body)}"
        return None

    def _body_name(self, body: int) -> str:
        k = self.kitchen
        for name, bid in (*k.objects.items(), *k.static_body_ids.items()):
            if bid == body:
                return name
        return "the floor" if body == k.floor_id else f"body {body}"


class PickPlaceController:
    """The per-step state machine of one pick-and-place. Register with `kitchen.add_controller`.

    Args:
        kitchen: The simulated world.
        target_name: Catalogue name of the object (only for the final outcome sensor, `kitchen.is_on_table`).
        hold: (dof,) joints to hold while the plan is not ready.
        plan_ready: plan_ready(block) returns the finished plan (or a failure), else None; block=True waits for it.
        request_home: Asks the worker for a way home from given joints; returns a poll(block) function.
        settings: Durations and thresholds.
        on_placed: Called once when the object is seen resting on the table after the release.
    """

    def __init__(
        self,
        kitchen: Kitchen,
        target_name: str,
        hold: np.ndarray,
        plan_ready: Callable[[bool], object | None],
        request_home: Callable[[np.ndarray], Callable[[bool], tuple[bool, Segment | None]]],
        settings: ExecutionSettings = ExecutionSettings(),
        on_placed: Callable[[], None] | None = None,
    ) -> None:
        self.kitchen = kitchen
        self._on_placed = on_placed
        self.target_name = target_name
        self.settings = settings
        self.sensors = ArmSensors(kitchen)
        self.cfg = kitchen.robot_config
        self._plan_ready = plan_ready
        self._request_home = request_home
        self.hold_q = np.asarray(hold, dtype=float)
        self.phase = MotionPhase.PLANNING
        self.phase_steps = 0
        self.start_time = kitchen.sim_time
        self.exec_start: float | None = None
        self.plan: PickPlacePlan | None = None
        self.queue: list[tuple[MotionPhase, Segment | None]] = []
        self.current: Segment | None = None
        self.executed: list[TimedTrajectory] = []
        self.held: int | None = None
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

    # ------------------------------------------------------------------------------------- commands
    def _command(self, q: np.ndarray, qd: np.ndarray | None = None) -> None:
        import pybullet as p

        ctl = self.cfg.control
        n = len(q)
        self.kitchen.bc.setJointMotorControlArray(
            self.kitchen.robot_id,
            self.sensors.arm_ids,
            p.POSITION_CONTROL,
            targetPositions=list(map(float, q)),
            targetVelocities=list(map(float, qd)) if qd is not None else [0.0] * n,
            forces=[ctl.max_joint_force] * n,
            positionGains=[ctl.position_gain] * n,
        )

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
                widest = float(np.max(self.kitchen.gripper_positions()))
                opened = float(min(g.open_position, max(opened, widest)))
        self.kitchen.set_gripper_target(g.closed_position if closed else opened, g.max_force)

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
        if phase is MotionPhase.CLOSE:
            self._gripper(True)
        elif phase is MotionPhase.RELEASE:
            self._gripper(False, release=True)

    def fail(self, stage: FailureStage, message: str) -> None:
        """Stop what the arm is doing, open the hand and go home; the outcome keeps this stage."""
        if self.stage is not None or self.finished:
            return
        self.stage, self.message = stage, message
        self._gripper(False, release=True)
        self.queue = []
        if self.phase is MotionPhase.PLANNING or self.exec_start is None:
            self._finish()
            return
        self.hold_q = self.kitchen.arm_joint_positions()
        self._home_poll = self._request_home(self.hold_q)
        self._enter(MotionPhase.RECOVER)

    def _finish(self) -> None:
        self.finished = True
        self.end_time = self.kitchen.sim_time
        self.phase = MotionPhase.DONE
        self._command(self.hold_q)
        self.kitchen.remove_controller(self)

    def __call__(self, kitchen: Kitchen) -> None:
        if self.finished:
            return
        s = self.settings
        dt = kitchen.time_step
        if kitchen.sim_time - self.start_time > s.max_duration_s and self.stage is None:
            self.fail(FailureStage.TIMEOUT, f"not finished after {s.max_duration_s:.0f} s")
        phase = self.phase
        # Thinking takes a fixed simulated time: the arm starts moving at the same physics step however long the
        # worker needed in wall time (it blocks here only if the worker is slower than that), so a seeded attempt
        # repeats exactly.
        if phase is MotionPhase.PLANNING:
            self._command(self.hold_q)
            if self.phase_steps * dt >= s.think_s:
                self._start_plan(self._plan_ready(True))
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
                and np.max(np.abs(kitchen.arm_joint_positions() - self.hold_q)) < s.align_tolerance
            )
            if self.phase_steps * dt >= duration or aligned:
                self._after_wait(phase)
        else:
            self._track(kitchen)
        self.phase_steps += 1

    def _start_plan(self, ready: object) -> None:
        from scone_bt.motion.pick_place import PickPlaceFailure

        if ready is None:
            self.fail(FailureStage.PLANNING, "planning was cancelled")
            return
        if isinstance(ready, BaseException):
            # A bug or a configuration error, not an outcome of the attempt: stop here and let it end the run
            # (it propagates out of kitchen.advance) instead of being stored as experience.
            self.error = ready
            self._finish()
            raise ready
        if isinstance(ready, PickPlaceFailure):
            self.reason = ready.reason
            self.fail(ready.stage, ready.message)
            return
        assert isinstance(ready, PickPlacePlan)
        self.plan = ready
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
        self.exec_start = self.kitchen.sim_time
        couple_fingers(self.kitchen)
        self._gripper(False)  # pre-shaped while approaching: the fingers fit between close neighbours
        self._next()

    def _after_wait(self, phase: MotionPhase) -> None:
        if phase is MotionPhase.CLOSE:
            self.held = self.sensors.held_body(self.settings.min_contact_force)
            if self.held is None or self.sensors.finger_gap() < self.settings.min_gap:
                self.fail(FailureStage.GRASP, "the fingers closed without holding the object")
                return
        elif phase is MotionPhase.SETTLE:
            if self.kitchen.is_on_table(self.target_name):
                self.success = True
                self.message = "placed upright on the table"
                if self._on_placed is not None:
                    self._on_placed()
            else:
                self.stage = FailureStage.PLACE
                self.message = "released, but the object is not resting upright on the table"
        self.hold_q = self.current.trajectory.positions[-1] if self.current is not None else self.hold_q
        self._next()

    def _track(self, kitchen: Kitchen) -> None:
        seg = self.current
        assert seg is not None
        traj = seg.trajectory
        k = min(
            int(round(self.phase_steps * kitchen.time_step * self.cfg.control.rate_hz)), len(traj.times) - 1
        )
        self._command(traj.positions[k], traj.velocities[k])
        self.hold_q = traj.positions[k]
        self.done_exec_s += kitchen.time_step
        phase = self.phase
        if self.stage is None and self._check(phase, traj.positions[k]):
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

    def _holding(self) -> bool:
        held = self.sensors.held_body(self.settings.min_contact_force * 0.2)
        return held is not None and held == self.held and self.sensors.finger_gap() >= self.settings.min_gap

    def _check(self, phase: MotionPhase, q_cmd: np.ndarray) -> bool:
        """Collision and slip monitoring during a tracked segment; True if the attempt just failed."""
        s = self.settings
        if self.phase_steps % 4:
            return False
        near_objects = phase in _NEAR_OBJECTS
        link = self.sensors.unexpected_contact(
            near_objects, self.held if phase in _CARRYING else None, s.min_contact_force
        )
        if link is not None and phase not in _HOMING:
            self.fail(FailureStage.COLLISION, f"{link} during {phase}")
            return True
        if not near_objects and phase not in _HOMING:
            err = float(np.max(np.abs(self.kitchen.arm_joint_positions() - q_cmd)))
            if err > s.max_tracking_error:
                self.fail(
                    FailureStage.COLLISION, f"the arm was blocked during {phase} (joint error {err:.2f} rad)"
                )
                return True
        if phase is MotionPhase.TRANSIT and self.phase_steps % 24 == 0 and not self._holding():
            self.fail(FailureStage.TRANSIT, "the object dropped out of the gripper while carrying it")
            return True
        return False
