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
    dof = path.shape[1]
    otg = Ruckig(1)
    segments = []
    t_calc = time.perf_counter()
    for a, b in zip(path[:-1], path[1:], strict=True):
        delta = b - a
        travel = np.abs(delta)
        if np.max(travel) < 1e-9:
            continue
        moving = travel > 1e-12
        inp = InputParameter(1)
        inp.current_position = [0.0]
        inp.target_position = [1.0]
        inp.max_velocity = [float(np.min(limits.velocity[moving] / travel[moving]))]
        inp.max_acceleration = [float(np.min(limits.acceleration[moving] / travel[moving]))]
        inp.max_jerk = [float(np.min(limits.jerk[moving] / travel[moving]))]
        traj = Trajectory(1)
        result = otg.calculate(inp, traj)
        if result not in (Result.Working, Result.Finished):
            raise SconeError(f"ruckig could not time a segment ({result.name}); check the robot's limits")
        segments.append((a, delta, traj))
    t_calc = time.perf_counter() - t_calc

    t_sample = time.perf_counter()
    dt = 1.0 / rate_hz
    times, pos, vel, acc = [np.zeros(1)], [path[:1]], [np.zeros((1, dof))], [np.zeros((1, dof))]
    offset = 0.0
    for a, delta, traj in segments:
        duration = traj.duration
        n = int(np.ceil(duration / dt - 1e-9))
        ts = np.minimum(np.arange(1, n + 1) * dt, duration)
        sva = np.array([[x[0] for x in traj.at_time(float(t))] for t in ts])  # (n, 3): s, ds/dt, d2s/dt2
        times.append(offset + ts)
        pos.append(a + sva[:, :1] * delta)
        vel.append(sva[:, 1:2] * delta)
        acc.append(sva[:, 2:3] * delta)
        offset += duration
    t_sample = time.perf_counter() - t_sample
    trajectory = TimedTrajectory(np.concatenate(times), np.vstack(pos), np.vstack(vel), np.vstack(acc))
    return trajectory, TimingReport(t_calc, t_sample)
