"""ruckig timing: limit compliance from the commanded samples, and path following."""

from __future__ import annotations

import numpy as np
import pytest

from scone_bt.motion import limits_of, time_path


@pytest.fixture
def path(arm, robot_cfg):
    rng = np.random.default_rng(3)
    home = np.asarray(robot_cfg.home)
    pts = [home] + [np.clip(home + rng.normal(0, 0.6, arm.dof), arm.lower, arm.upper) for _ in range(4)]
    return np.array(pts)


def test_trajectory_respects_position_velocity_acceleration_and_jerk_limits(
    arm, robot_cfg, path, assert_within_limits
):
    limits = limits_of(robot_cfg)
    traj, report = time_path(path, limits, robot_cfg.control.rate_hz)
    assert_within_limits(traj, arm.lower, arm.upper, limits)
    assert report.calculation_s >= 0
    assert np.max(np.diff(traj.times)) <= 1.0 / robot_cfg.control.rate_hz + 1e-9


def test_trajectory_starts_and_ends_at_rest_on_the_path(robot_cfg, path):
    traj, _ = time_path(path, limits_of(robot_cfg), robot_cfg.control.rate_hz)
    assert np.allclose(traj.positions[0], path[0]) and np.allclose(traj.positions[-1], path[-1], atol=1e-9)
    assert np.allclose(traj.velocities[[0, -1]], 0.0, atol=1e-9)


def test_samples_stay_on_the_straight_segments(robot_cfg, path):
    """With phase synchronisation each segment is a straight joint-space line (what the planner checked)."""
    traj, _ = time_path(path, limits_of(robot_cfg), robot_cfg.control.rate_hz)
    for q in traj.positions:
        dist = []
        for a, b in zip(path[:-1], path[1:], strict=True):
            t = np.clip((q - a) @ (b - a) / ((b - a) @ (b - a)), 0, 1)
            dist.append(np.linalg.norm(q - (a + t * (b - a))))
        assert min(dist) < 1e-6


def test_lower_scale_gives_a_slower_trajectory(robot_cfg, path):
    limits = limits_of(robot_cfg)
    fast, _ = time_path(path, limits, 240)
    slow, _ = time_path(path, limits.scaled(0.5), 240)
    assert slow.duration > fast.duration * 1.5


def test_vectorised_sampling_matches_ruckigs_own():
    from ruckig import InputParameter, Ruckig, Trajectory

    from scone_bt.motion.timing import _sample

    rng = np.random.default_rng(0)
    for _ in range(50):
        inp = InputParameter(1)
        inp.current_position, inp.target_position = [0.0], [1.0]
        inp.max_velocity = [float(rng.uniform(0.1, 5))]
        inp.max_acceleration = [float(rng.uniform(0.1, 20))]
        inp.max_jerk = [float(rng.uniform(1, 500))]
        traj = Trajectory(1)
        Ruckig(1).calculate(inp, traj)
        ts = np.linspace(0.0, traj.duration, 97)
        ref = np.array([[x[0] for x in traj.at_time(float(t))] for t in ts])
        assert np.allclose(_sample(traj, ts), ref, atol=1e-9)


def test_compiled_sampling_gives_the_floats_of_the_vectorised_expressions(arm, robot_cfg):
    """Each segment's samples from the compiled kernel equal `_sample`'s numpy evaluation bit for bit (so plans
    executed before and after the kernel command the same joints)."""
    from ruckig import InputParameter, Ruckig, Trajectory

    from scone_bt.motion.timing import _sample

    limits = limits_of(robot_cfg)
    rng = np.random.default_rng(8)
    home = np.asarray(robot_cfg.home, dtype=float)
    for trial in range(30):
        path = np.array(
            [home] + [arm.clamp(home + rng.normal(0, 0.5, arm.dof)) for _ in range(1 + trial % 3)]
        )
        if trial % 5 == 0:
            path = np.vstack([path, path[-1]])  # a segment without motion is skipped
        scaled = limits.scaled(0.3) if trial % 2 else limits
        rate = (240.0, 1000.0)[trial % 2]
        traj, _ = time_path(path, scaled, rate)
        times, pos, vel, acc = [np.zeros(1)], [path[:1]], [np.zeros((1, arm.dof))], [np.zeros((1, arm.dof))]
        offset = 0.0
        for a, b in zip(path[:-1], path[1:], strict=True):
            delta = b - a
            travel = np.abs(delta)
            if np.max(travel) < 1e-9:
                continue
            moving = travel > 1e-12
            inp = InputParameter(1)
            inp.current_position, inp.target_position = [0.0], [1.0]
            inp.max_velocity = [float(np.min(scaled.velocity[moving] / travel[moving]))]
            inp.max_acceleration = [float(np.min(scaled.acceleration[moving] / travel[moving]))]
            inp.max_jerk = [float(np.min(scaled.jerk[moving] / travel[moving]))]
            one = Trajectory(1)
            Ruckig(1).calculate(inp, one)
            n = int(np.ceil(one.duration / (1.0 / rate) - 1e-9))
            ts = np.minimum(np.arange(1, n + 1) * (1.0 / rate), one.duration)
            sva = _sample(one, ts)
            times.append(offset + ts)
            pos.append(a + sva[:, :1] * delta)
            vel.append(sva[:, 1:2] * delta)
            acc.append(sva[:, 2:3] * delta)
            offset += one.duration
        assert np.array_equal(traj.times, np.concatenate(times))
        assert np.array_equal(traj.positions, np.vstack(pos))
        assert np.array_equal(traj.velocities, np.vstack(vel))
        assert np.array_equal(traj.accelerations, np.vstack(acc))
