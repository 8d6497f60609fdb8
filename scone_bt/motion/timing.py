"""Time-parameterisation with ruckig (adapter): jerk-limited, time-optimal segments through a path's waypoints.

The community ruckig has no intermediate waypoints, so the trajectory chains state-to-state segments that stop at
every waypoint. With zero boundary velocities and phase synchronisation every segment is a straight line in joint
space, so the executed motion stays on the path the planner checked for collisions.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

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
    from ruckig import InputParameter, Result, Ruckig, Synchronization, Trajectory

    path = np.asarray(path, dtype=float)
    dof = path.shape[1]
    otg = Ruckig(dof)
    segments = []
    t_calc = time.perf_counter()
    for a, b in zip(path[:-1], path[1:], strict=True):
        if np.max(np.abs(b - a)) < 1e-9:
            continue
        inp = InputParameter(dof)
        inp.current_position = a.tolist()
        inp.current_velocity = [0.0] * dof
        inp.current_acceleration = [0.0] * dof
        inp.target_position = b.tolist()
        inp.target_velocity = [0.0] * dof
        inp.target_acceleration = [0.0] * dof
        inp.max_velocity = limits.velocity.tolist()
        inp.max_acceleration = limits.acceleration.tolist()
        inp.max_jerk = limits.jerk.tolist()
        inp.synchronization = Synchronization.Phase
        traj = Trajectory(dof)
        result = otg.calculate(inp, traj)
        if result not in (Result.Working, Result.Finished):
            raise SconeError(f"ruckig could not time a segment ({result.name}); check the robot's limits")
        segments.append(traj)
    t_calc = time.perf_counter() - t_calc

    t_sample = time.perf_counter()
    dt = 1.0 / rate_hz
    times, pos, vel, acc = [0.0], [path[0]], [np.zeros(dof)], [np.zeros(dof)]
    offset = 0.0
    for traj in segments:
        duration = traj.duration
        n = int(np.ceil(duration / dt - 1e-9))
        for k in range(1, n + 1):
            t = min(k * dt, duration)
            p, v, a = traj.at_time(t)
            times.append(offset + t)
            pos.append(np.asarray(p))
            vel.append(np.asarray(v))
            acc.append(np.asarray(a))
        offset += duration
    t_sample = time.perf_counter() - t_sample
    trajectory = TimedTrajectory(np.asarray(times), np.asarray(pos), np.asarray(vel), np.asarray(acc))
    return trajectory, TimingReport(t_calc, t_sample)
