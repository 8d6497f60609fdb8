"""The heft test: grasp, lift the product a little, hold it, feel its load and slip, then carry on or set it back.

A person hefts an unfamiliar item before carrying it; the robot does the same for an action κ̂ is unsure of
(gate.probe decides when). `ProbeController` is the pick-and-place controller with the plan's lift split in two:
first ``lift_m`` up (`MotionPhase.PROBE`), a hold of ``hold_s`` (`MotionPhase.PROBE_HOLD`) in which the fingers
sample what they feel (`ForceSensing.finger_forces`: the vertical load the fingers carry and how hard they squeeze;
`ForceSensing.wrist_load`: the vertical load the whole hand carries, palm included; `ForceSensing.pad_contacts`:
where on the fingers' pads the product touches), then `judge_probe` on the samples:

- it holds: the rest of the lift, and the plan goes on;
- it slips (the fingers no longer hold it, or the load they carry changes during the hold, the whole hand's too,
  while the product moves on the pads: it slides), it does not come up with them (their vertical force on it
  points down: `ProbeReading.pressed`) or the grip is near its friction limit (load over grip above
  ``max_traction``: the carry's accelerations would make it slip): the product is set down where it stood
  (`MotionPhase.SET_DOWN`, the probe's lift reversed), the fingers open, the hand leaves as it came (the descent
  reversed) and heads home. The outcome is *aborted*: no failure, since the product is where it was, but the
  person has to fetch it.

A probe whose fingers closed on nothing leaves the same way, then the outcome sensor looks: a product still
standing where it stood (within ``in_place_m``) makes it aborted too; one pushed away or over, a failed grasp.

Everything is sensed by the arm (joints, a wrist force sensor, the fingers' tactile pads), never read from the
simulator's state.
With ``set_back`` False the probe only senses and always carries on (the self-confidence generator records
readings that way, so one dataset serves both with and without the probe).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np

from scone_bt.config.ranges import Range
from scone_bt.config.tree_parameters import PROBE_RANGES, TREE_DEFAULTS
from scone_bt.motion.execution import PickPlaceController, Segment
from scone_bt.motion.types import FailureStage, MotionPhase, TimedTrajectory

__all__ = [
    "ForceSensing",
    "PadContacts",
    "ProbeController",
    "ProbeReading",
    "ProbeSettings",
    "judge_probe",
    "min_jerk",
]

_AS_TRACKED = {MotionPhase.PROBE: MotionPhase.LIFT, MotionPhase.SET_DOWN: MotionPhase.LOWER}
"""The probe's motions are watched for collisions as the lift and the lowering they are part of."""
_SAMPLE_S = 0.02
"""Simulated seconds between two samples of the finger forces during the hold."""
_G = 9.81

PadContacts = tuple[tuple[float, float, float] | None, ...]
"""Per finger, where the held product touches it: the contacts' mean position weighted by their normal force, in
that finger's own frame (metres); None where the finger does not touch it."""


@runtime_checkable
class ForceSensing(Protocol):
    """What the probe needs of the arm beyond `ArmExecutor`: a wrist force sensor and the fingers' tactile pads."""

    def finger_forces(self, held: str) -> tuple[float, float]:
        """(vertical load the fingers carry of ``held``, their summed grip (normal) force on it) in newtons:
        fingertip force sensors."""
        ...

    def wrist_load(self) -> float:
        """The vertical load all the hand's contacts carry (fingers, palm and the other hand links), newtons:
        a wrist force/torque sensor, tared for the hand's own weight."""
        ...

    def pad_contacts(self, held: str) -> PadContacts:
        """Where ``held`` touches each finger's pad (`PadContacts`)."""
        ...


_SHARED = ("lift_m", "hold_s", "max_unsteady", "max_traction")
"""The settings the gate's probe options carry too (read from them by `ProbeSettings.of`; ranges in PROBE_RANGES)."""

_OWN_RANGES = {
    "up_s": Range(0.1, 3.0, unit="seconds"),
    "max_drift_mm": Range(0.0, 20.0, low_open=True, unit="millimetres"),
    "max_pushed": Range(0.0, 1.0, low_open=True),
    "payload_kg": Range(0.0, 50.0, low_open=True, unit="kilograms"),
    "in_place_m": Range(0.0, 0.1, low_open=True, unit="metres"),
}
"""The intervals of the motion's own probe settings (those it shares with the gate are PROBE_RANGES)."""


@dataclass(frozen=True)
class ProbeSettings:
    """How far and how long the robot hefts a product, and when it sets it back.

    Attributes:
        lift_m: How far the product is lifted, metres, in [0.005, 0.05].
        hold_s: How long it is held there while the fingers feel it, seconds, in [0.1, 3].
        up_s: Time for the little lift (and for setting it down), seconds.
        max_traction: Set back when the carried load over the grip force exceeds this (near the friction limit).
        max_unsteady: Set back when the fingers' load changes by more than this share between the hold's halves
            (a product held fast weighs the same throughout, to a tenth of a percent; one sliding in the fingers
            does not), the wrist's load too (the same share: else another part of the hand pushes on it, not its
            weight that moved) and the contacts moved on the pads (``max_drift_mm``).
        max_drift_mm: The contacts moved on the pads when their centre on some finger lies farther than this
            (millimetres) from where it was as the probe began. A product held fast moves with the fingers and
            its contacts stay put (0.0-0.2 mm on 31 of the 33 products the motion benchmark carries on; a
            contact patch that changes shape on one pad reads more, which only falls back to the load's
            verdict); one sliding along the pads, or left behind as they rise, carries its contacts with it on
            both fingers (the olive oil in an 8 N grip: 1.3 and 1.4 mm). A load that changes while the contacts
            stay put is something else pushing on the product (a leaning neighbour), not a slip, as long as it
            changes by no more than ``max_pushed``; the traction test still judges how close the grip is to
            sliding.
        max_pushed: The largest change of the load (share, as ``max_unsteady``) that still counts as a push when
            the contacts stay put. A neighbour leaning on a product shifts its load by a few percent (the grits:
            1.6 %); a product pivoting out of the grip changes it by a tenth or more with the contacts' centre
            still (on the development streams regenerated with the pads read, tools/data/sc_probe's profiles:
            the 6 failures whose contacts stayed put changed by 8.7 % to 52 %, the one success by 5.7 %).
        set_back: False: only sense, always carry on (the generator's recording mode).
        payload_kg: The heaviest load the reason quotes as a mass, kilograms (the arm's payload: 3 kg for a
            Panda); a heavier reading is something else pulling on the product, not its weight.
        in_place_m: A probe whose fingers closed on nothing ended with the product back in its place when it
            stands upright within this distance (metres) of where it stood before the hand came: an aborted
            attempt, not a failure (the fingers brushed it; a product pushed farther, or over, is a failure).
    """

    lift_m: float = TREE_DEFAULTS.probe.lift_m
    hold_s: float = TREE_DEFAULTS.probe.hold_s
    up_s: float = 0.4
    max_traction: float = 0.3
    max_unsteady: float = 0.01
    max_drift_mm: float = 0.5
    max_pushed: float = 0.05
    set_back: bool = True
    payload_kg: float = 3.0
    in_place_m: float = 0.02

    @classmethod
    def of(cls, options: object) -> ProbeSettings:
        """The motion's settings from the gate's probe options (gate.probe.ProbeOptions, read by attributes)."""
        return cls(**{n: getattr(options, n) for n in _SHARED})

    def __post_init__(self) -> None:
        for name in _SHARED:
            PROBE_RANGES[name].check(f"probe.{name}", getattr(self, name))
        for name, allowed in _OWN_RANGES.items():
            allowed.check(f"probe.{name}", getattr(self, name))


@dataclass(frozen=True)
class ProbeReading:
    """What the hand felt while holding the product up (newtons; the samples' means over the hold's halves).

    Attributes:
        held: Both fingers still held it at the end of the hold.
        load_n: Vertical load the fingers carried over the hold's second half (the datasets' ``probe_load_n``).
        load_first_n: The same over its first half.
        grip_n: Summed grip (normal) force over the second half.
        seconds: Simulated seconds the probe took (lift, hold and, if it set back, the set-down).
        pressed: The fingers' vertical force pointed down over the second half: they pressed on the product
            (a fingertip on its top) or rose past it instead of carrying it; ``load_n`` is then the size of that
            push, not a weight. The datasets' ``probe_pressed`` (False in files recorded before it).
        drift_mm: How far the contacts moved on the pads (millimetres, the farther finger): their centre over the
            hold's second half from where it was as the probe began. None: not measured (the datasets); an
            unsteady load then counts as a slip, as it did before the pads were read.
        drift_both_mm: How far the contacts moved on the nearer finger (millimetres): the least any pad saw them
            move. Recorded, not judged: a product sliding along the pads moves on both, but so do many that are
            then carried (weak or greasy grips: up to 16 mm on the development streams), so it tells no slip
            the load, the wrist and `pressed` do not. None: not measured.
        wrist_load_n: Vertical load the whole hand carried over the second half (the wrist's reading: fingers,
            palm and the other hand links, on whatever they touch). None: not measured (the datasets).
        wrist_load_first_n: The same over the first half.
    """

    held: bool
    load_n: float
    load_first_n: float
    grip_n: float
    seconds: float = 0.0
    pressed: bool = False
    drift_mm: float | None = None
    drift_both_mm: float | None = None
    wrist_load_n: float | None = None
    wrist_load_first_n: float | None = None

    @property
    def traction(self) -> float:
        """Load over grip: how close the grip is to sliding (a product slips past the friction coefficient)."""
        return self.load_n / self.grip_n if self.grip_n > 1e-6 else math.inf

    @property
    def lift_traction(self) -> float | None:
        """`traction` where the fingers carried the product up; None where they pressed it down (a fingertip on
        its top: the load is a push, no measure of how fast it is held)."""
        return None if self.pressed else self.traction

    @property
    def unsteady(self) -> float:
        """Share by which the load changed between the hold's halves (0: steady; a sliding product's varies)."""
        return _changed(self.load_n, self.load_first_n)

    @property
    def wrist_unsteady(self) -> float | None:
        """Share by which the whole hand's load changed between the hold's halves; None: not measured."""
        if self.wrist_load_n is None or self.wrist_load_first_n is None:
            return None
        return _changed(self.wrist_load_n, self.wrist_load_first_n)

    @property
    def mass_kg(self) -> float:
        """The mass the load stands for (kilograms)."""
        return max(0.0, self.load_n) / _G


def _changed(now: float, first: float) -> float:
    """Share by which a load (newtons, ≥ 0: the hold's mean size) changed from ``first`` to ``now``; 1 when it
    started at nothing."""
    if first <= 1e-6:
        return 1.0
    return abs(now - first) / first


def judge_probe(reading: ProbeReading, settings: ProbeSettings) -> tuple[bool, str]:
    """(carry on, why) from a probe's reading: why is the robot's words for setting it back, or ""."""
    if not reading.held:
        return False, "slips out of my fingers"
    # Pressed: the fingers' vertical force on it points down, so they do not carry it up; it stays behind as they
    # rise, or a fingertip pushes on its top. On the development streams re-recorded with the sign (2026-12-06),
    # of the 723 probes the rest of this judge carries on, the 10 pressed ones all slipped out in the lift.
    # Written as "not ≤" so that a NaN reading (a sensor fault) sets back rather than carries on.
    if reading.pressed or _slides(reading, settings) or not reading.traction <= settings.max_traction:
        return False, _why(reading, settings)
    return True, ""


def _slides(reading: ProbeReading, settings: ProbeSettings) -> bool:
    """The fingers' load changed during the hold (or cannot be read), the whole hand's too (or it was not
    measured), and not as a push: the contacts did not stay put on the pads (or were not measured), or it changed
    by more than a push does (``max_pushed``)."""
    if reading.unsteady <= settings.max_unsteady:
        return False
    # What the whole hand carries stayed the same: the product's weight did not move; the fingers' share changed
    # because another part of the hand pushes on it too (the palm on a box's top). A NaN is not "the same".
    wrist = reading.wrist_unsteady
    if wrist is not None and wrist <= settings.max_unsteady:
        return False
    # Held fast, the product moves with the pads; a small change of the load then comes from something else
    # pushing on it (a neighbour leaning on it), not from a slip. A NaN drift is not "stayed put".
    stayed = reading.drift_mm is not None and reading.drift_mm <= settings.max_drift_mm
    return not (stayed and reading.unsteady <= settings.max_pushed)


def _why(reading: ProbeReading, settings: ProbeSettings) -> str:
    """What the fingers sensed, in words; a mass is quoted only when the load can be a weight: steady, carried up
    by the fingers, no more than a friction grip could hold (load ≤ grip), and within the arm's payload."""
    if not (math.isfinite(reading.unsteady) and math.isfinite(reading.traction)):
        return "cannot be felt: my finger sensors give no reading"
    if reading.pressed and reading.traction > settings.max_traction:
        # pushing down about as hard as they squeeze: the contacts' normals are vertical, a fingertip on its top
        return "does not come up: my fingers press on it"
    slides = _slides(reading, settings)
    if reading.pressed and not slides:
        return "does not come up with my fingers"  # they rise past it: a light push down, no carry
    if reading.unsteady > settings.max_unsteady and not slides:
        return "is caught on something"  # a changing load while held fast: something else pushes on it
    if slides:
        # Rising or falling: on the development streams 30 of the 31 products whose load rose during the hold
        # (and did not trip the traction test) slipped out of the gripper while lifting.
        return "slips in my fingers"
    if reading.traction > 1.0 or reading.mass_kg > settings.payload_kg:
        return "is caught on something"
    return f"is too heavy for my grip (about {reading.mass_kg * 1000:.0f} g)"


def min_jerk(q0: np.ndarray, q1: np.ndarray, duration_s: float, rate_hz: float) -> TimedTrajectory:
    """A rest-to-rest joint motion from q0 to q1 along the straight joint line (minimum-jerk timing)."""
    q0, q1 = np.asarray(q0, dtype=float), np.asarray(q1, dtype=float)
    n = max(2, int(math.ceil(duration_s * rate_hz)) + 1)
    t = np.linspace(0.0, duration_s, n)
    s = t / duration_s
    pos = 10 * s**3 - 15 * s**4 + 6 * s**5
    vel = (30 * s**2 - 60 * s**3 + 30 * s**4) / duration_s
    acc = (60 * s - 180 * s**2 + 120 * s**3) / duration_s**2
    d = q1 - q0
    return TimedTrajectory(t, q0 + pos[:, None] * d, vel[:, None] * d, acc[:, None] * d)


def _reversed(traj: TimedTrajectory) -> TimedTrajectory:
    """The same motion backwards in time (rest to rest stays rest to rest)."""
    return TimedTrajectory(
        traj.duration - traj.times[::-1],
        traj.positions[::-1].copy(),
        -traj.velocities[::-1],
        traj.accelerations[::-1].copy(),
    )


class ProbeController(PickPlaceController):
    """PickPlaceController with the heft test between the grasp and the lift (module docstring).

    Args (besides PickPlaceController's, passed through):
        probe: The probe's settings.
        hand_z: Height of the hand (metres) at given joints, from the arm's kinematic model.
        judge: Decides from the reading: (carry on, the robot's full words for setting it back, "the jar slips
            in my fingers") (the tree's: behaviours.probe_judge.ProbeJudge, gate.after_probe); None:
            `judge_probe` alone.
    """

    def __init__(
        self,
        *args: object,
        probe: ProbeSettings,
        hand_z: Callable[[np.ndarray], float],
        judge: Callable[[ProbeReading], tuple[bool, str]] | None = None,
        **kwargs: object,
    ) -> None:
        super().__init__(*args, **kwargs)  # type: ignore[arg-type]
        self.probe = probe
        self._hand_z = hand_z
        self.judge = judge
        self.reading: ProbeReading | None = None
        self.aborted = False
        self.probe_reason = ""
        self._samples: list[tuple[float, float, float]] = []  # the fingers' load and grip, the wrist's load
        self._pads: list[PadContacts] = []  # where the pads touch it: as the probe began, then each sample's
        self._probe_start: float | None = None
        self._descend: Segment | None = None
        self._up: TimedTrajectory | None = None
        self._rest: list[tuple[MotionPhase, Segment | None]] = []
        # Where the product stood before the hand came (the outcome sensor's look, as the controller is made at
        # the attempt's start), and whether the fingers closed on nothing: then the attempt ends aborted if it
        # still stands there (`_back_in_place`).
        self._stood_at = self.arm.standing_position(self.target_name)
        self._missed = False
        self.missed_in_place: bool | None = None  # after the fingers closed on nothing: it still stood there

    # ------------------------------------------------------------------------------------- the plan, split
    def _start_plan(self, ready: object) -> None:
        super()._start_plan(ready)
        if self.plan is None or self.stage is not None:
            return
        i = next((k for k, (ph, _) in enumerate(self.queue) if ph is MotionPhase.LIFT), None)
        d = next((seg for ph, seg in self.queue if ph is MotionPhase.DESCEND), None)
        if i is None or d is None:
            return
        lift = self.queue[i][1]
        assert lift is not None
        traj = lift.trajectory
        q0 = traj.positions[0]
        # The first straight piece of the lift (its waypoints are rest points): the probe lifts along it.
        way = (
            lift.waypoints
            if lift.waypoints is not None and len(lift.waypoints) >= 2
            else traj.positions[[0, -1]]
        )
        q1 = np.asarray(way[1], dtype=float)
        rise = self._hand_z(q1) - self._hand_z(q0)
        if rise <= self.probe.lift_m * 1.5:
            return  # too short a lift to heft within it: no probe
        f = self.probe.lift_m / rise
        q_probe = q0 + f * (q1 - q0)
        rate = self.cfg.control.rate_hz
        self._up = min_jerk(q0, q_probe, self.probe.up_s, rate)
        # The rest of the lift from rest at the probe's height through the lift's own waypoints, timed as the
        # plan timed the lift (ruckig, the robot's limits at the Cartesian pace): no slower than without the probe.
        from scone_bt.motion.plan_session import CARTESIAN_SPEED
        from scone_bt.motion.timing import limits_of, time_path

        rest_path = np.vstack([q_probe, np.asarray(way[1:], dtype=float)])
        rest, _ = time_path(rest_path, limits_of(self.cfg).scaled(CARTESIAN_SPEED), rate)
        self._descend = d
        self.queue[i : i + 1] = [
            (MotionPhase.PROBE, Segment(MotionPhase.PROBE, self._up)),
            (MotionPhase.PROBE_HOLD, None),
            (MotionPhase.LIFT, Segment(MotionPhase.LIFT, rest)),
        ]
        self.total_exec_s += self._up.duration + self.probe.hold_s + rest.duration - traj.duration

    # ------------------------------------------------------------------------------------- a missed grasp
    def fail(self, stage: FailureStage, message: str) -> None:
        missed = stage is FailureStage.GRASP and self.phase is MotionPhase.CLOSE
        if missed and self.stage is None and self._descend is not None:
            # The fingers closed on nothing: nothing is held up, so leave as the hand came and then look whether
            # the product still stands where it stood (`_after_miss`), instead of heading home from here.
            self._missed, self.message = True, message
            self.queue = [
                (MotionPhase.RELEASE, None),
                (MotionPhase.RETREAT, Segment(MotionPhase.RETREAT, _reversed(self._descend.trajectory))),
            ]
            self._next()
            return
        super().fail(stage, message)

    def _after_miss(self) -> None:
        """Back above the shelf after the fingers closed on nothing: the issue's rule makes a probe that ends with
        the product back in its place an aborted attempt; a product pushed away or over is a failed grasp (and, in
        the generator's sensing-only mode, every miss: it records `missed_in_place` beside the failure)."""
        self._missed = False
        self.missed_in_place = self._back_in_place()
        if self.missed_in_place and self.probe.set_back:
            self.aborted = True
            self.probe_reason = f"the {self.target_name} is not in my fingers when they close"
            self.message = f"{self.message}; it stands where it stood: {self.probe_reason}"
        else:
            self.stage = FailureStage.GRASP
        self.hold_q = self.arm.arm_joint_positions()
        self._home_poll = self._request_home(self.hold_q)
        self._enter(MotionPhase.RECOVER)

    def _back_in_place(self) -> bool:
        """The product stands upright within ``in_place_m`` of where it stood before the hand came."""
        now = self.arm.standing_position(self.target_name)
        if now is None or self._stood_at is None:
            return False
        return float(np.linalg.norm(np.subtract(now, self._stood_at))) <= self.probe.in_place_m

    # ------------------------------------------------------------------------------------- the hold
    def __call__(self, arm: object) -> None:
        if self.finished or self.phase is not MotionPhase.PROBE_HOLD:
            if self.phase is MotionPhase.PROBE and self._probe_start is None:
                self._probe_start = self.arm.sim_time
                if self.held is not None and isinstance(self.arm, ForceSensing):
                    self._pads.append(self.arm.pad_contacts(self.held))
            super().__call__(arm)  # type: ignore[arg-type]
            return
        dt = self.arm.time_step
        self._command(self.hold_q)
        every = max(1, round(_SAMPLE_S / dt))
        if self.phase_steps % every == 0 and self.held is not None and isinstance(self.arm, ForceSensing):
            self._samples.append((*self.arm.finger_forces(self.held), self.arm.wrist_load()))
            if self._pads:
                self._pads.append(self.arm.pad_contacts(self.held))
        if self.phase_steps * dt >= self.probe.hold_s:
            self._decide()
        self.phase_steps += 1

    def _decide(self) -> None:
        half = max(1, len(self._samples) // 2)
        first, second = self._samples[:half], self._samples[half:] or self._samples[:half]

        def mean(xs: list[tuple[float, float, float]], i: int) -> float:
            return float(np.mean([abs(x[i]) for x in xs])) if xs else 0.0

        # The recorded datasets hold the load's size; its sign says whether the fingers carried it or pushed it.
        pressed = bool(second) and float(np.mean([x[0] for x in second])) < 0.0

        started = self._probe_start if self._probe_start is not None else self.arm.sim_time
        self.reading = ProbeReading(
            held=self._holding(),
            load_n=round(mean(second, 0), 4),
            load_first_n=round(mean(first, 0), 4),
            grip_n=round(mean(second, 1), 4),
            seconds=round(self.arm.sim_time - started, 4),
            pressed=pressed,
            drift_mm=_drift_mm(self._pads[0], self._pads[1 + half :]) if self._pads else None,
            drift_both_mm=_drift_mm(self._pads[0], self._pads[1 + half :], on_both=True)
            if self._pads
            else None,
            wrist_load_n=round(mean(second, 2), 4) if second else None,
            wrist_load_first_n=round(mean(first, 2), 4) if first else None,
        )
        if self.judge is not None:
            carry, reason = self.judge(self.reading)
        else:
            carry, why = judge_probe(self.reading, self.probe)
            reason = f"the {self.target_name} {why}"
        if carry or not self.probe.set_back:
            self._next()
            return
        self._set_back(reason)

    def _set_back(self, reason: str) -> None:
        """Lower it where it stood, open, leave as the hand came, and head home: an aborted attempt."""
        assert self._up is not None and self._descend is not None
        self.aborted = True
        self.probe_reason = reason
        self.message = f"set back after the probe: {self.probe_reason}"
        self.queue = [
            (MotionPhase.SET_DOWN, Segment(MotionPhase.SET_DOWN, _reversed(self._up))),
            (MotionPhase.RELEASE, None),
            (MotionPhase.RETREAT, Segment(MotionPhase.RETREAT, _reversed(self._descend.trajectory))),
        ]
        self._next()

    def _next(self) -> None:
        if self._missed and not self.queue and self.phase is MotionPhase.RETREAT:
            self._after_miss()
            return
        if self.aborted and not self.queue and self.phase is MotionPhase.RETREAT:
            # back above the shelf with an empty hand: the way home is planned from here, as after a failure
            if self.reading is not None and self._probe_start is not None:
                self.reading = _with_seconds(self.reading, self.arm.sim_time - self._probe_start)
            self.hold_q = self.arm.arm_joint_positions()
            self._home_poll = self._request_home(self.hold_q)
            self._enter(MotionPhase.RECOVER)
            return
        super()._next()

    def _check(self, phase: MotionPhase, q_cmd: np.ndarray) -> bool:
        return super()._check(_AS_TRACKED.get(phase, phase), q_cmd)


def _drift_mm(start: PadContacts, late: list[PadContacts], on_both: bool = False) -> float | None:
    """How far the contacts' centre moved on the farther finger (mm; ``on_both``: on the nearer one, so on both):
    from ``start`` to its mean over ``late``; None where a finger touched nothing then (nothing to compare)."""
    if not late:
        return None
    moved: list[float] = []
    for k, p0 in enumerate(start):
        now = [c for pads in late if k < len(pads) and (c := pads[k]) is not None]
        if not now or p0 is None:
            return None
        moved.append(float(np.linalg.norm(np.mean(now, axis=0) - np.asarray(p0))))
    if not moved:
        return None
    return round((min(moved) if on_both else max(moved)) * 1000.0, 3)


def _with_seconds(reading: ProbeReading, seconds: float) -> ProbeReading:
    from dataclasses import replace

    return replace(reading, seconds=round(seconds, 4))
