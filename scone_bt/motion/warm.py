"""Compile the motion stage's kernels into numba's on-disk cache before the first run needs them.

numba compiles `motion.compiled`'s kernels on their first call in a fresh install (about 18 s on 2 cores) and
caches them beside the module; every later process loads them in milliseconds. Without this step the first
episode after an install waits that long for its first plan. `make` runs it once after installing:

    python -m scone_bt.motion.warm            # plans one pick-and-place in a scene built here; prints one line

The scene needs no simulator: a bottle on a shelf step in front of the arm and a table beside it, planned with
the robot file's own planner, grasp and limits, so the kernels compile for the array types the robot uses.
"""

from __future__ import annotations

import sys
import time

import numpy as np

__all__ = ["warm_kernels"]


def warm_kernels(robot: str = "panda") -> tuple[bool, float]:
    """Plan one pick-and-place for ``robot`` (a robot file name) in a scene built here: (whether it found a plan,
    wall seconds). A plan found ran every kernel a plan runs (IK, state, segment and hand checks, timing).

    Raises:
        SconeError: the robot file is unknown or malformed (its one-line message).
    """
    from scone_bt.config import ObjectSpec, load_robot
    from scone_bt.config.catalogue import Shape
    from scone_bt.config.grasp import GraspParams
    from scone_bt.motion.collision import Obstacle
    from scone_bt.motion.model import ArmModel, pose_matrix
    from scone_bt.motion.pick_place import PickPlacePlan, plan_pick_and_place
    from scone_bt.motion.pick_request import PickPlaceRequest
    from scone_bt.motion.placement import TableRegion
    from scone_bt.motion.planner import PlannerOptions, silence_ompl
    from scone_bt.motion.timing import limits_of
    from scone_bt.perception.types import Detection

    t0 = time.perf_counter()
    silence_ompl()
    cfg = load_robot(robot)
    arm = ArmModel(cfg)
    home = np.asarray(cfg.home, dtype=float)
    # A shelf step in front of the arm, a table to its right and the pedestal under it (arm base frame, metres).
    static = tuple(
        Obstacle(name, "box", size, pose_matrix(np.eye(3), center))
        for name, center, size in (
            ("step", (0.45, 0.4, -0.3), (0.2, 0.52, 0.6)),
            ("table", (0.47, -0.43, -0.3), (0.44, 0.40, 0.6)),
            ("pedestal", (0.0, 0.0, -0.3), (0.22, 0.22, 0.6)),
        )
    )
    bottle = ObjectSpec(
        name="bottle",
        aliases=(),
        shape=Shape.CYLINDER,
        size=(0.05, 0.05, 0.14),  # m
        mass=0.3,  # kg
        friction=0.6,
        material="warm-up",
        rgba=(1, 1, 1, 1),
        marker_id=0,
    )
    closing = arm.fk(home)[:3, 1]
    request = PickPlaceRequest(
        q_start=home,
        target=Detection(
            "bottle", 0, position=(0.42, 0.35, 0.14), yaw=0.0, confidence=1.0, bbox=(0, 0, 1, 1)
        ),
        spec=bottle,
        obstacles=(),
        static=static,
        home=home,
        rng_seed=0,
        table=TableRegion((0.47, -0.43), (0.44, 0.40), 0.0),
        params=GraspParams.of(cfg),
        preferred_yaw=float(np.arctan2(closing[1], closing[0])),
        opening=2.0 * (cfg.gripper.open_position - cfg.gripper.closed_position),
    )
    result = plan_pick_and_place(
        arm, request, PlannerOptions.of(cfg.planner), limits_of(cfg), cfg.control.rate_hz
    )
    return isinstance(result, PickPlacePlan), time.perf_counter() - t0


def main(argv: list[str] | None = None) -> int:
    from scone_bt.errors import SconeError

    args = sys.argv[1:] if argv is None else argv
    robot = args[0] if args else "panda"
    try:
        planned, seconds = warm_kernels(robot)
    except SconeError as exc:
        print(f"scone_bt.motion.warm: {exc}", file=sys.stderr)
        return 2
    # No plan still compiled what it ran; the rest compiles on first use, as without this step.
    what = "compiled and cached" if planned else "partly compiled (no plan found in the warm-up scene)"
    print(f"motion kernels {what} for {robot} ({seconds:.1f} s)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
