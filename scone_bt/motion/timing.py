"""Time-parameterisation with ruckig (adapter): jerk-limited, time-optimal segments through a path's waypoints.

The community ruckig has no intermediate waypoints, so the trajectory chains state-to-state segments that stop at
every waypoint. Each segment is timed as one degree of freedom, the path parameter s in [0, 1] of the straight
joint-space line a + s (b - a), with the tightest of the joints' limits divided by their travel: the motion is
exactly the straight line the planner checked for collisions, time-optimal along it, and within every joint's
velocity, acceleration and jerk limit. (Phase synchronisation of seven DoFs gives the same line only when ruckig
finds it feasible; otherwise it silently falls back to time synchronisation and leaves the line.)
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from scone_bt.config import RobotConfig
from scone_bt.errors import SconeError
from scone_bt.motion.types import TimedTrajectory

__all__ = ["KinematicLimits", "TimingReport", "time_path", "limits_of"]


@dataclass(frozen=True, eq=False)
class KinematicLimits:
    """Per-joint limits the trajectory must respect: rad/s, rad/s², rad/s³ (already scaled)."""

    velocity: np.ndarray
    acceleration: np.ndarray
    jerk: np.ndarray

    def scaled(self, factor: float) -> KinematicLimits:
        """Slower limits (e.g. for careful Cartesian moves): velocity × f, acceleration × f², jerk × f³."""
        return KinematicLimits(self.velocity * factor, self.acceleration * factor**2, self.jerk * factor**3)


def limits_of(robot: RobotConfig) -> KinematicLimits:
    """The robot's datasheet limits times the scales from its YAML."""
    lim = robot.limits
    return KinematicLimits(
        velocity=np.asarray(lim.velocity) * lim.velocity_scale,
        acceleration=np.asarray(lim.acceleration) * lim.acceleration_scale,
        jerk=np.asarray(lim.jerk) * lim.jerk_scale,
    )


@dataclass(frozen=True)
class TimingReport:
    """Wall time spent in ruckig's solver and in sampling, seconds."""

    calculation_s: float
    sampling_s: float


def time_path(
    path: np.ndarray, limits: KinematicLimits, rate_hz: float
) -> tuple[TimedTrajectory, TimingReport]:
    """Time a joint path (N, dof) with ruckig and sample it at rate_hz.

    Raises:
        SconeError: ruckig rejected the input (e.g. non-positive limits).
    """
    from ruckig import InputParameter, Result, Ruckig, Trajectory

    path = np.asarray(path, dtype=float)
    otg = Ruckig(1)
    segments = []
    t_calc = time.perf_counter()
    deltas = path[1:] - path[:-1]
    travel = np.abs(deltas)
    moving = travel > 1e-12
    # Each segment's limits on s: the tightest joint's limit over its travel (joints that do not move aside).
    with np.errstate(divide="ignore", invalid="ignore"):
        bounds = [
            np.where(moving, np.asarray(limit, dtype=float) / travel, np.inf).min(axis=1).tolist()
            for limit in (limits.velocity, limits.acceleration, limits.jerk)
        ]
    for k in np.flatnonzero(travel.max(axis=1) >= 1e-9).tolist():
        inp = InputParameter(1)
        inp.current_position = [0.0]
        inp.target_position = [1.0]
        inp.max_velocity = [bounds[0][k]]
        inp.max_acceleration = [bounds[1][k]]
        inp.max_jerk = [bounds[2][k]]
        traj = Trajectory(1)
        result = otg.calculate(inp, traj)
        if result not in (Result.Working, Result.Finished):
            raise SconeError(f"ruckig could not time a segment ({result.name}); check the robot's limits")
        segments.append((path[k], deltas[k], traj))
    t_calc = time.perf_counter() - t_calc

    t_sample = time.perf_counter()
    trajectory = _sampled(path[0], segments, 1.0 / rate_hz)
    t_sample = time.perf_counter() - t_sample
    return trajectory, TimingReport(t_calc, t_sample)


def _sampled(
    start: np.ndarray, segments: list[tuple[np.ndarray, np.ndarray, Any]], dt: float
) -> TimedTrajectory:
    """The chained segments (first state, delta, 1-DOF ruckig trajectory of s) sampled every `dt` seconds from
    rest at `start`: each segment's samples in one compiled call (`compiled.sample_segment`)."""
    from scone_bt.motion.compiled import sample_segment

    counts = [int(np.ceil(traj.duration / dt - 1e-9)) for _, _, traj in segments]
    rows = 1 + sum(counts)
    times, pos = np.zeros(rows), np.empty((rows, len(start)))
    vel, acc = np.zeros((rows, len(start))), np.zeros((rows, len(start)))
    pos[0] = start
    offset, row = 0.0, 1
    for (a, delta, traj), n in zip(segments, counts, strict=True):
        duration = traj.duration
        profile = traj.profiles[0][0]
        if profile.brake.duration > 0.0:  # never from rest: ruckig's own sampling
            ts = np.minimum(np.arange(1, n + 1) * dt, duration)
            sva = _sample(traj, ts)
            times[row : row + n] = offset + ts
            pos[row : row + n] = a + sva[:, :1] * delta
            vel[row : row + n] = sva[:, 1:2] * delta
            acc[row : row + n] = sva[:, 2:3] * delta
        else:
            phases = np.array(
                [profile.t, profile.j, profile.a[:7], profile.v[:7], profile.p[:7]], dtype=float
            )
            sample_segment(a, delta, phases, n, duration, dt, offset, row, times, pos, vel, acc)
        offset += duration
        row += n
    return TimedTrajectory(times, pos, vel, acc)


def _sample(traj: Any, ts: np.ndarray) -> np.ndarray:
    """(n, 3) position, velocity and acceleration of a 1-DOF ruckig trajectory at times ts (vectorised).

    A rest-to-rest profile is seven constant-jerk phases: each sample is the cubic of its phase, evaluated for
    all samples at once instead of one `at_time` call per control step. A profile with a braking pre-phase
    (never the case from rest) falls back to `at_time`.
    """
    profile = traj.profiles[0][0]
    if profile.brake.duration > 0.0:
        return np.array([[x[0] for x in traj.at_time(float(t))] for t in ts])
    durations = np.asarray(profile.t, dtype=float)
    starts = np.concatenate([[0.0], np.cumsum(durations)[:-1]])
    k = np.clip(np.searchsorted(starts, ts, side="right") - 1, 0, len(durations) - 1)
    d = ts - starts[k]
    j = np.asarray(profile.j, dtype=float)[k]
    a0 = np.asarray(profile.a, dtype=float)[k]
    v0 = np.asarray(profile.v, dtype=float)[k]
    p0 = np.asarray(profile.p, dtype=float)[k]
    pos = p0 + d * (v0 + d * (a0 / 2 + d * j / 6))
    vel = v0 + d * (a0 + d * j / 2)
    acc = a0 + d * j
    return np.column_stack([pos, vel, acc])
