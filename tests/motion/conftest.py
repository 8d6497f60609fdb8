"""Motion fixtures: the Panda's model, the kitchen's static obstacles, and detections for placed objects.

Detections here come from the simulator's ground truth, because these tests exercise motion, not perception.
"""

from __future__ import annotations

import numpy as np
import pytest

from scone_bt.motion import KinematicLimits, TimedTrajectory
from scone_bt.perception.types import Detection


@pytest.fixture(scope="session")
def arm(robot_cfg):
    from scone_bt.motion import ArmModel

    return ArmModel(robot_cfg)


@pytest.fixture(scope="session")
def static_obstacles(kitchen_cfg, robot_cfg):
    from scone_bt.motion.collision import Obstacle
    from scone_bt.motion.model import pose_matrix
    from scone_bt.world import Kitchen

    with Kitchen(kitchen_cfg, robot_cfg) as k:
        return [Obstacle(b.name, "box", b.size, pose_matrix(np.eye(3), b.center)) for b in k.static_boxes]


def _detect(kitchen, name: str) -> Detection:
    """A perfect detection of a spawned object: its top-face centre and yaw."""
    st = kitchen.object_state(name)
    spec = kitchen.specs[name]
    yaw = kitchen.bc.getEulerFromQuaternion(st.orientation)[2]
    x, y, z = st.position
    return Detection(name, 0, (x, y, z + spec.height / 2), yaw, 1.0, (0, 0, 1, 1))


def _run_to_end(kitchen, task, max_sim_s: float = 60.0):
    """Advance the kitchen in 0.1 s ticks (like the episode loop) until the task is done."""
    task.start()
    start = kitchen.sim_time
    while not task.done():
        assert kitchen.sim_time - start < max_sim_s, "pick-and-place never finished"
        kitchen.advance(0.1)
    return task.outcome()


TOL = 1e-6


def _assert_within_limits(
    traj: TimedTrajectory, lower: np.ndarray, upper: np.ndarray, limits: KinematicLimits
) -> None:
    """Positions within joint limits; velocities and accelerations (reported and finite-differenced) within limits."""
    assert traj.positions.shape == traj.velocities.shape == traj.accelerations.shape
    assert np.all(np.diff(traj.times) > 0)
    assert np.all(traj.positions >= lower - TOL) and np.all(traj.positions <= upper + TOL)
    assert np.all(np.abs(traj.velocities) <= limits.velocity + TOL)
    assert np.all(np.abs(traj.accelerations) <= limits.acceleration + TOL)
    # The samples themselves (what the controller is sent) must agree: finite differences stay within limits.
    dt = np.diff(traj.times)[:, None]
    fd_vel = np.diff(traj.positions, axis=0) / dt
    assert np.all(np.abs(fd_vel) <= limits.velocity * 1.001 + TOL)
    fd_acc = np.diff(traj.velocities, axis=0) / dt
    assert np.all(np.abs(fd_acc) <= limits.acceleration * 1.001 + TOL)
    fd_jerk = np.diff(traj.accelerations, axis=0) / dt
    assert np.all(np.abs(fd_jerk) <= limits.jerk * 1.001 + TOL)


@pytest.fixture
def assert_within_limits():
    return _assert_within_limits


@pytest.fixture
def detect():
    """detect(kitchen, name) -> a perfect Detection of a spawned object."""
    return _detect


@pytest.fixture
def run_to_end():
    """run_to_end(kitchen, task) -> the MotionOutcome, ticking the kitchen in 0.1 s steps."""
    return _run_to_end


@pytest.fixture
def task_for(detect):
    """task_for(kitchen, system, name, seed, place_spot) -> a PickAndPlaceTask of that object, the others as
    obstacles (``place_spot``: the spot the request names, None: sampled)."""

    def make(kitchen, system, name, seed=3, place_spot=None):
        others = [(detect(kitchen, n), kitchen.specs[n]) for n in kitchen.objects if n != name]
        spec = kitchen.specs[name]
        return system.pick_and_place(
            detect(kitchen, name), spec, others, rng_seed=seed, place_spot=place_spot
        )

    return make


@pytest.fixture
def stocked(kitchen_cfg, robot_cfg):
    """salt, sugar and honey on the shelving (slots drawn with seed 1)."""
    from scone_bt.motion import MotionSystem
    from scone_bt.world import Kitchen

    with Kitchen(kitchen_cfg, robot_cfg) as k:
        k.spawn([kitchen_cfg.catalogue.get(n) for n in ("salt", "sugar", "honey")], np.random.default_rng(1))
        with MotionSystem.build(k) as system:
            yield k, system
