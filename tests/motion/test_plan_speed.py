"""The pick-and-place plan's fast paths give the answers of the plain computations they replace (issue 29).

Each cheaper step (numpy's LAPACK calls without their checks, joint limits on plain floats, a segment's states
checked as one batch, the hand's GJK calls skipped where bounding spheres miss) is compared with the computation
it replaced, and seeded plans are pinned to what they were before the steps were made cheaper.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from scone_bt.motion import Obstacle, PickPlacePlan, PlannerOptions
from scone_bt.motion.collision import CollisionWorld, HandModel, _geometry, interpolated
from scone_bt.motion.grasp import side_rotation, top_down_rotation
from scone_bt.motion.model import IKOptions, inverse_small, pose_matrix, solve_small
from scone_bt.motion.planner import plan_joint_path
from tests.motion.test_fallbacks import BOTTLE, JAR, STATIC, _boxed_in, _det, make_planner


def _random_pose(rng: np.random.Generator) -> np.ndarray:
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    return pose_matrix(q * np.sign(np.linalg.det(q)), rng.uniform(-1, 1, 3))


def test_small_linear_algebra_is_numpys_bit_for_bit():
    rng = np.random.default_rng(0)
    for _ in range(50):
        a = rng.normal(size=(6, 6))
        a = a @ a.T + 1e-4 * np.eye(6)
        b = rng.normal(size=(6, 8))
        assert np.array_equal(solve_small(a, b), np.linalg.solve(a, b))
        pose = _random_pose(rng)
        assert np.array_equal(inverse_small(pose), np.linalg.inv(pose))


def test_side_grasp_rotations_are_np_cross_bit_for_bit():
    for yaw in np.linspace(-7.0, 7.0, 1001):
        c, s = np.cos(yaw), np.sin(yaw)
        y, z = np.array([c, s, 0.0]), np.array([s, -c, 0.0])
        expected = np.column_stack([np.cross(y, z), y, z])
        got = side_rotation(float(yaw))
        assert np.array_equal(got, expected) and np.array_equal(np.signbit(got), np.signbit(expected))


def test_a_world_answers_a_state_asked_again_as_the_first_time(arm, robot_cfg):
    rng = np.random.default_rng(5)
    home = np.asarray(robot_cfg.home, dtype=float)
    states = [np.clip(home + rng.uniform(-2.0, 2.0, arm.dof), arm.lower, arm.upper) for _ in range(40)]
    world = CollisionWorld(arm, STATIC)
    first = [world.is_valid(q) for q in states]
    again = [world.is_valid(q.copy()) for q in states]  # answered from what the world kept
    fresh = CollisionWorld(arm, STATIC)
    assert first == again == [fresh.is_valid(q) for q in states]
    assert world.checks == 80 and True in first and False in first
    # A segment through states already asked about: the same verdict from the batch as from a fresh world.
    segment = interpolated(home, states[0], np.linspace(0.0, 1.0, 30))
    assert world.states_valid(segment) is CollisionWorld(arm, STATIC).states_valid(segment)


def test_joint_limits_on_floats_agree_with_the_array_comparison(arm):
    rng = np.random.default_rng(1)
    samples = [rng.uniform(arm.lower - 0.2, arm.upper + 0.2) for _ in range(300)]
    for k in range(arm.dof):
        for edge, sign in ((arm.lower, -1.0), (arm.upper, 1.0)):
            for off in (0.0, 0.5e-9, 2e-9):
                q = (arm.lower + arm.upper) / 2
                q[k] = edge[k] + sign * off
                samples.append(q)
    nan = (arm.lower + arm.upper) / 2
    nan[3] = np.nan
    samples.append(nan)
    verdicts = []
    for q in samples:
        expected = bool(((q >= arm.lower - 1e-9) & (q <= arm.upper + 1e-9)).all())
        assert arm.within_limits(q) is expected
        verdicts.append(expected)
    assert True in verdicts and False in verdicts


@pytest.mark.parametrize("carrying", [False, True])
def test_a_batch_of_states_is_checked_like_one_state_at_a_time(arm, robot_cfg, carrying):
    rng = np.random.default_rng(2)
    home = np.asarray(robot_cfg.home, dtype=float)
    # Upright in a downward-pointing hand: the object's z is the hand's approach axis reversed.
    held = Obstacle(
        "held", "cylinder", (0.05, 0.05, 0.12), pose_matrix(np.diag([1.0, -1.0, -1.0]), (0, 0, 0.03))
    )
    kwargs = {"attached": held, "max_tilt": 0.3} if carrying else {}
    batch, single = (CollisionWorld(arm, STATIC, **kwargs) for _ in range(2))
    verdicts = []
    for _ in range(60):
        spread = 0.5 if carrying else 3.0  # a carried object tilts beyond the limit far from home
        goal = np.clip(home + rng.uniform(-spread, spread, arm.dof), arm.lower - 0.1, arm.upper + 0.1)
        states = interpolated(home, goal, np.linspace(0.0, 1.0, 25))
        for k, q in enumerate(states):  # the same floats as the states computed one by one
            assert np.array_equal(q, home + (goal - home) * np.linspace(0.0, 1.0, 25)[k])
        one_by_one = all(single.is_valid(q) for q in states)  # stops at the first invalid state
        assert batch.states_valid(states) is one_by_one
        assert batch.checks == single.checks
        verdicts.append(one_by_one)
    assert True in verdicts and False in verdicts


def test_the_planner_checks_a_worlds_segment_as_any_checker(arm, robot_cfg):
    home = np.asarray(robot_cfg.home, dtype=float)
    world = CollisionWorld(arm, STATIC)
    goals = np.array([home + d for d in (0.3, -0.4, 0.8)])
    fast = plan_joint_path(home, goals, arm.lower, arm.upper, world.is_valid, PlannerOptions(rng_seed=3))
    other = CollisionWorld(arm, STATIC)
    plain = plan_joint_path(
        home, goals, arm.lower, arm.upper, lambda q: other.is_valid(q), PlannerOptions(rng_seed=3)
    )
    assert (fast.status, fast.goal_index, fast.message) == (plain.status, plain.goal_index, plain.message)
    assert np.array_equal(fast.path, plain.path) and world.checks == other.checks


def _every_pair(arm, obstacles, padding, fingers, ee_pose, ignore=()):
    """The hand's colliding obstacles with every (part, obstacle) pair given to GJK, in the hand's order."""
    import coal

    ee = arm.model.frames[arm.ee_frame]
    ee_from_joint = np.linalg.inv(ee.placement.homogeneous)
    parts = [
        (g.geometry, ee_from_joint @ g.placement.homogeneous)
        for g in arm.geometry_with_fingers(fingers).geometryObjects
        if g.parentJoint == arm.ee_joint
    ]
    hits = []
    for geom, local in parts:
        world = ee_pose @ local
        tf = coal.Transform3s(world[:3, :3].copy(), world[:3, 3].copy())
        for ob in obstacles:
            if ob.name in hits or ob.name in ignore:
                continue
            otf = coal.Transform3s(ob.pose[:3, :3].copy(), ob.pose[:3, 3].copy())
            geometry = _geometry(ob.shape, ob.size, padding)
            if coal.collide(geom, tf, geometry, otf, coal.CollisionRequest(), coal.CollisionResult()):
                hits.append(ob.name)
    return hits


def test_ik_draws_its_restart_seeds_as_one_draw_per_seed(arm):
    """IK draws every restart's seed before it starts (the same numbers as one `uniform` call per seed): a solve
    leaves the plan's generator where it was left before, whichever seed converges."""
    target = arm.fk((arm.lower + arm.upper) / 2)
    for restarts in (0, 1, 4, 12):
        rng, reference = np.random.default_rng(restarts), np.random.default_rng(restarts)
        seed = np.asarray(arm.config.home, dtype=float)
        arm.ik(target, seed, rng, IKOptions(restarts=restarts))
        for _ in range(restarts):
            reference.uniform(arm.lower, arm.upper)
        assert rng.bit_generator.state == reference.bit_generator.state
    draws = np.random.default_rng(9).uniform(arm.lower, arm.upper, size=(12, arm.dof))
    one_by_one = np.random.default_rng(9)
    assert all(np.array_equal(row, one_by_one.uniform(arm.lower, arm.upper)) for row in draws)


@pytest.mark.parametrize("robot", ["panda", "iiwa7"])
def test_the_bound_from_the_first_joint_holds_for_every_geometry(robot):
    """Collision worlds prune pairs with it: it must hold at every q, or a real collision would go unchecked."""
    import pinocchio as pin

    from scone_bt.config import load_robot
    from scone_bt.motion import ArmModel

    arm = ArmModel(load_robot(robot))
    data, gdata = arm.model.createData(), arm.geom_model.createData()
    rng = np.random.default_rng(6)
    worst = 0.0
    for _ in range(300):
        pin.updateGeometryPlacements(
            arm.model, data, arm.geom_model, gdata, rng.uniform(arm.lower, arm.upper)
        )
        for k, g in enumerate(arm.geom_model.geometryObjects):
            g.geometry.computeLocalAABB()
            centre = gdata.oMg[k].act(np.asarray(g.geometry.aabb_center, dtype=float))
            far = float(np.linalg.norm(centre - arm.first_joint_origin)) + float(g.geometry.aabb_radius)
            assert far <= arm.geometry_reach_from_first_joint[k] + 1e-9
            worst = max(worst, far / arm.geometry_reach_from_first_joint[k])
    assert worst > 0.5
    moving = [k for k, g in enumerate(arm.geom_model.geometryObjects) if g.parentJoint >= 1]
    assert np.all(arm.geometry_reach_from_first_joint[moving] <= arm.geometry_reach[moving] + 1e-12)


def test_hand_checks_skip_only_pairs_that_cannot_touch(arm):
    rng = np.random.default_rng(4)
    target, shelf = _boxed_in(front=True)
    obstacles = [
        *STATIC,
        *(
            Obstacle(
                d.name,
                s.shape,
                s.size,
                pose_matrix(np.eye(3), (*d.position[:2], d.position[2] - s.height / 2)),
            )
            for d, s in shelf
        ),
    ]
    hand = HandModel(arm, obstacles, padding=0.004, finger_position=0.02)
    answers = []
    for _ in range(150):
        centre = np.array(target.position) + rng.uniform([-0.12, -0.15, -0.12], [0.12, 0.15, 0.15])
        pose = pose_matrix(top_down_rotation(rng.uniform(-np.pi, np.pi), rng.uniform(-0.6, 0.6)), centre)
        ignore = ("wall",) if rng.random() < 0.3 else ()
        expected = _every_pair(arm, obstacles, 0.004, 0.02, pose, ignore)
        assert hand.colliding(pose, ignore=ignore) == expected
        answers.append(len(expected))
    assert 0 in answers and max(answers) >= 2


# Seeded plans as they were before the steps were made cheaper (grasp, spot, checks, waypoint counts and sum).
# Since the goal sets are built goal by goal (ending at the first goal reached in a straight line) the same plans
# examine fewer candidates (iiwa7 boxed: 49 of the 84 before) and count the straight segments OMPL's query asks
# again (answered from the world's memory); grasps, spots and waypoints are what they were. The compiled IK
# (`motion.compiled`) answers to rounding of Pinocchio's: Panda boxed counts 2 checks more (12,078 before) with the
# same grasp, spot and waypoints. Since the placer keeps a product 1 cm + 0.1 × its height from the table's edge
# (0.41, -0.27 was 1 cm from it for the 10 cm jar) every spot is (0.39, -0.29), 2 cm farther in along each axis, with the same
# grasps and waypoint counts. Since a path found for a carry is checked again at a quarter of the step, the plans
# are the same with more checks (Panda 12,067 and 741 before, iiwa7 3,146 and 330).
PINNED = {
    "panda": {
        "boxed": ("side grasp at yaw -96°", 86, (0.39, -0.29, 0.0), 12810, [3, 2, 2, 7, 2, 2, 2], -56.227224),
        "open": ("top grasp at yaw -94°", 3, (0.39, -0.29, 0.0), 862, [3, 2, 5, 2, 2, 2, 2], 22.862576),
    },
    "iiwa7": {
        "boxed": ("side grasp at yaw 62°", 49, (0.39, -0.29, 0.0), 3545, [2, 2, 5, 4, 2, 2, 3], -1.67021),
        "open": ("top grasp at yaw 86°", 2, (0.39, -0.29, 0.0), 431, [3, 2, 3, 2, 2, 2, 2], 7.575802),
    },
}


@pytest.mark.parametrize("robot", sorted(PINNED))
def test_seeded_plans_are_what_they_were(robot):
    from scone_bt.config import load_robot
    from scone_bt.motion import ArmModel

    cfg = load_robot(robot)
    plan, _ = make_planner(ArmModel(cfg), cfg)
    target, shelf = _boxed_in(front=False)
    table = [Obstacle("o1", "cylinder", (0.06, 0.06, 0.2), pose_matrix(np.eye(3), (0.45, -0.40, 0.1)))]
    results = {
        "boxed": plan(target, BOTTLE, shelf, seed=5),
        "open": plan(_det("jar", 0.40, 0.35, JAR.height), JAR, shelf[:1], table, seed=2),
    }
    for case, result in results.items():
        assert isinstance(result, PickPlacePlan), result.message
        label, tried, spot, checks, counts, total = PINNED[robot][case]
        assert result.grasp.label == label and result.grasps_tried == tried
        assert result.place_spot == pytest.approx(spot, abs=1e-6)
        assert result.collision_checks == checks
        assert [len(s.waypoints) for s in result.segments] == counts
        assert float(np.concatenate([s.waypoints for s in result.segments]).sum()) == pytest.approx(
            total, abs=1e-5
        )
    front_target, front_shelf = _boxed_in(front=True)
    blocked = plan(front_target, BOTTLE, front_shelf, seed=1)
    assert not isinstance(blocked, PickPlacePlan)
    assert blocked.reason.value == "grasps_blocked" and blocked.blockers == ("front", "left", "wall")
    assert "(86 tried)" in blocked.message


def test_a_straight_segment_takes_the_place_of_its_query(arm, robot_cfg):
    from scone_bt.motion.plan_session import PlanSession
    from scone_bt.motion.planner import direct_path
    from scone_bt.motion.timing import limits_of

    home = np.asarray(robot_cfg.home, dtype=float)
    world = CollisionWorld(arm, STATIC)
    near = home + np.array([0.3, -0.2, 0.1, 0.2, 0.0, 0.1, 0.3])
    assert world.is_valid(near)
    options = PlannerOptions()
    whole = plan_joint_path(home, near, arm.lower, arm.upper, world.is_valid, options)
    assert whole.success and whole.message.startswith("direct")
    straight = direct_path(home, near, arm.lower, arm.upper, world.is_valid, options)
    assert straight is not None and np.array_equal(straight.path, whole.path)
    assert straight.message == whole.message
    # A box where the hand passes half way: both ends stay free, the segment is blocked, nothing stands in.
    far = home + np.array([1.2, 0.4, 0.0, 0.3, 0.0, 0.0, 0.0])
    box = Obstacle("box", "box", (0.06, 0.06, 0.06), pose_matrix(np.eye(3), arm.fk((home + far) / 2)[:3, 3]))
    blocked = CollisionWorld(arm, [*STATIC, box])
    assert blocked.is_valid(home) and blocked.is_valid(far) and not blocked.is_valid((home + far) / 2)
    assert direct_path(home, far, arm.lower, arm.upper, blocked.is_valid, options) is None

    session = PlanSession(arm, options, limits_of(robot_cfg), robot_cfg.control.rate_hz, seed=3)
    assert session.direct(home, far, blocked) is None and session.queries == 0 and session.plans == []
    got = session.direct(home, near, world)
    assert got is not None and np.array_equal(got.path, whole.path)
    # It used up the query it replaced: the next query is seeded as the second of the plan.
    assert session.queries == 1 and session.plans == [got]
    no_direct = PlanSession(arm, replace(options, try_direct=False), limits_of(robot_cfg), 240.0, seed=3)
    assert no_direct.direct(home, near, world) is None and no_direct.queries == 0


@pytest.mark.parametrize("robot", sorted(PINNED))
def test_goal_sets_built_goal_by_goal_give_the_plans_of_whole_sets(robot, monkeypatch):
    """The path search stops a goal set at the first goal reached in a straight line; without that stop (every
    set built whole up front, OMPL trying the straight segments in order: the search before) the plans are the
    same, and more candidates are examined."""
    from scone_bt.config import load_robot
    from scone_bt.motion import ArmModel
    from scone_bt.motion.plan_session import PlanSession

    cfg = load_robot(robot)
    plan, _ = make_planner(ArmModel(cfg), cfg)
    target, shelf = _boxed_in(front=False)
    table = [Obstacle("o1", "cylinder", (0.06, 0.06, 0.2), pose_matrix(np.eye(3), (0.45, -0.40, 0.1)))]
    cases = [
        lambda: plan(target, BOTTLE, shelf, seed=5),
        lambda: plan(_det("jar", 0.40, 0.35, JAR.height), JAR, shelf[:1], table, seed=2),
        lambda: plan(_det("jar", 0.38, 0.25, JAR.height), JAR, (), table, seed=7),
    ]
    stopped = [case() for case in cases]
    monkeypatch.setattr(PlanSession, "direct", lambda self, qa, qb, world: None)
    whole = [case() for case in cases]
    for a, b in zip(stopped, whole, strict=True):
        assert isinstance(a, PickPlacePlan) and isinstance(b, PickPlacePlan)
        assert a.grasp.label == b.grasp.label and a.place_spot == b.place_spot
        assert all(
            np.array_equal(x.waypoints, y.waypoints) for x, y in zip(a.segments, b.segments, strict=True)
        )
        assert a.grasps_tried <= b.grasps_tried
        assert a.goal_set_sizes[0] <= b.goal_set_sizes[0] and a.goal_set_sizes[1] <= b.goal_set_sizes[1]
    assert sum(a.goal_set_sizes[0] + a.goal_set_sizes[1] for a in stopped) < sum(
        b.goal_set_sizes[0] + b.goal_set_sizes[1] for b in whole
    )
