"""The spheres' broad phase (motion.spheres): it encloses every geometry, and a world answers as Pinocchio's does."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from scone_bt.config import load_robot
from scone_bt.motion import ArmModel, CollisionWorld
from scone_bt.motion.collision import Obstacle
from scone_bt.motion.kernel_layout import ARM_F, ARM_I
from scone_bt.motion.model import pose_matrix
from scone_bt.motion.spheres import arm_spheres, cover_points


@pytest.fixture(scope="module", params=["panda", "iiwa7"])
def any_arm(request):
    return ArmModel(load_robot(request.param))


def _inside_some_sphere(points: np.ndarray, spheres: list[tuple[np.ndarray, float]]) -> np.ndarray:
    centres = np.array([c for c, _ in spheres])
    radii = np.array([r for _, r in spheres])
    gaps = np.linalg.norm(points[:, None, :] - centres[None], axis=2) - radii[None]
    return gaps.min(axis=1) <= 1e-12


def test_cover_points_holds_the_hull_of_an_l_shape():
    """Corners of an L (a bent link) and random points of its hull (convex combinations) lie in some sphere."""
    rng = np.random.default_rng(0)
    corners = np.array([[x, y, z] for x in (0, 0.3) for y in (0, 0.05) for z in (0, 0.05)])
    corners = np.vstack([corners, [[x, y, z] for x in (0.25, 0.3) for y in (0, 0.05) for z in (0.05, 0.25)]])
    spheres = cover_points(corners)
    weights = rng.dirichlet(np.ones(len(corners)) * 0.2, size=5000)
    assert _inside_some_sphere(np.vstack([corners, weights @ corners]), spheres).all()
    assert 1 < len(spheres) <= 8


def test_every_robot_geometry_lies_in_its_spheres(any_arm):
    """Vertices, random hull points and primitive samples of each geometry, at random joints, in its spheres."""
    spheres = arm_spheres(any_arm, None)
    assert spheres is not None
    sizes = {"nj": spheres.n_joints, "ns": spheres.n_spheres, "ng": len(spheres.shapes)}
    floats, ints = ARM_F.unpack(spheres.arm_f, sizes), ARM_I.unpack(spheres.arm_i, sizes)
    centres, radii = floats["sphere_local"], floats["radius"]
    first, count = ints["first"], ints["count"]
    rng = np.random.default_rng(1)
    for g, (shape, placement) in enumerate(zip(spheres.shapes, spheres.placements, strict=True)):
        kind = type(shape).__name__
        if kind.startswith("Convex"):
            pts = np.asarray(shape.points()).reshape(-1, 3)
            pts = np.vstack([pts, rng.dirichlet(np.ones(len(pts)) * 0.1, size=2000) @ pts])
        elif kind == "Box":
            pts = rng.uniform(-1, 1, size=(2000, 3)) * np.asarray(shape.halfSide)
            pts[:8] = [[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)] * np.asarray(
                shape.halfSide
            )
        elif kind == "Cylinder":
            angle, rad = rng.uniform(0, 2 * np.pi, 2000), shape.radius * np.sqrt(rng.uniform(0, 1, 2000))
            rad[:500] = shape.radius  # the curved side
            z = rng.uniform(-shape.halfLength, shape.halfLength, 2000)
            z[500:700] = shape.halfLength  # a rim
            pts = np.stack([rad * np.cos(angle), rad * np.sin(angle), z], axis=1)
        elif kind == "Sphere":
            d = rng.normal(size=(2000, 3))
            pts = d / np.linalg.norm(d, axis=1)[:, None] * shape.radius
        else:
            raise AssertionError(f"no samples for {kind}")
        in_joint = pts @ placement[:3, :3].T + placement[:3, 3]
        rows = slice(int(first[g]), int(first[g] + count[g]))
        mine = list(zip(centres[rows], radii[rows], strict=True))
        assert _inside_some_sphere(in_joint, mine).all(), spheres.names[g]


def _shelf_world(arm, attached=None, max_tilt=None, fingers=None, padding=0.01):
    rng = np.random.default_rng(7)
    obstacles = [
        Obstacle("tier", "box", (0.4, 0.9, 0.02), pose_matrix(np.eye(3), (0.55, 0.0, 0.25))),
        Obstacle("back", "box", (0.02, 0.9, 0.6), pose_matrix(np.eye(3), (0.78, 0.0, 0.3))),
    ]
    for k in range(8):
        yaw = rng.uniform(-np.pi, np.pi)
        rot = np.array([[np.cos(yaw), -np.sin(yaw), 0], [np.sin(yaw), np.cos(yaw), 0], [0, 0, 1]])
        shape = "cylinder" if k % 2 else "box"
        size = (0.07, 0.07 if shape == "cylinder" else 0.05, rng.uniform(0.08, 0.2))
        at = (rng.uniform(0.35, 0.7), rng.uniform(-0.4, 0.4), 0.26 + size[2] / 2)
        obstacles.append(Obstacle(f"p{k}", shape, size, pose_matrix(rot, at)))
    return CollisionWorld(
        arm,
        obstacles,
        attached,
        padding=padding,
        max_tilt=max_tilt,
        finger_position=fingers,
        ignore_for_hand=["p0"],
    )


def _pinocchio_answer(world: CollisionWorld, q: np.ndarray) -> tuple[bool, list[tuple[str, str]]]:
    spheres, world._spheres = world._spheres, None
    try:
        return world._free_pinocchio(q), world.colliding_pairs(q)
    finally:
        world._spheres = spheres


def _penetration(world: CollisionWorld, q: np.ndarray, pair: tuple[str, str]) -> float:
    """The pair's signed distance in Pinocchio's world (coal's distance), m."""
    data, gm, gd, _ = world._meshes()
    pin.computeDistances(world.model, data, gm, gd, q)
    names = [g.name for g in gm.geometryObjects]
    for k, cp in enumerate(gm.collisionPairs):
        if (names[cp.first], names[cp.second]) == pair:
            return gd.distanceResults[k].min_distance
    raise AssertionError(f"no pair {pair}")


@pytest.mark.parametrize("case", ["free", "held"])
def test_a_world_answers_as_pinocchios(any_arm, case):
    """Random states near a cluttered shelf (with a held, upright-kept object in one case): the same answer and
    the same colliding pairs, in the same order, as Pinocchio's world. Pinocchio asks coal for a yes or no without
    contacts, and that misses some shallow penetrations (the iiwa7's link 5 and 7 cylinders, 1.5-4.9 mm deep in
    51 of these 1,500 states; a Panda link in a product by 0.15 mm in one of 93,000 plan states) that coal's
    distance confirms; there, and only there, the spheres' world reports the collision coal measures."""
    held = None
    if case == "held":
        # Below the hand pointing down, its up axis against the hand's approach axis.
        held = Obstacle(
            "jar", "cylinder", (0.07, 0.07, 0.12), pose_matrix(np.diag([1.0, -1, -1]), (0, 0, 0.07))
        )
    world = _shelf_world(
        any_arm, held, max_tilt=0.6 if held else None, fingers=0.03 if case == "free" else None
    )
    assert world._spheres is not None
    rng = np.random.default_rng(11)
    home = np.asarray(any_arm.config.home, dtype=float)
    answers, shallow = [], 0
    for k in range(1500):
        scale = (0.3 if k % 2 else 0.6) if held else (0.7 if k % 2 else 1.5)
        q = any_arm.clamp(home + rng.normal(scale=scale, size=any_arm.dof))
        mine = world._free(q)
        theirs, their_pairs = _pinocchio_answer(world, q)
        pairs = world.colliding_pairs(q)
        answers.append(mine)
        if mine == theirs and pairs == their_pairs:
            continue
        extra = [p for p in pairs if p not in their_pairs]
        assert [p for p in pairs if p not in extra] == their_pairs
        assert extra and all(-0.01 < _penetration(world, q, p) < 0 for p in extra), (q, pairs, their_pairs)
        shallow += 1
    assert 0.2 < np.mean(answers) < 0.9  # both answers were compared
    assert shallow <= 100


def test_a_held_object_at_its_tilt_limit_is_left_to_pinocchio(arm):
    """Where the held object stands within rounding of the tilt limit the spheres do not decide."""
    held = Obstacle("jar", "cylinder", (0.07, 0.07, 0.12), pose_matrix(np.eye(3), (0.0, 0.0, 0.07)))
    q = np.asarray(arm.config.home, dtype=float) + 0.2
    loose = CollisionWorld(arm, [], held, max_tilt=1.5)
    data = arm.model.createData()
    pin.forwardKinematics(arm.model, data, q)
    up = float((data.oMi[arm.ee_joint].rotation @ loose._up_in_joint)[2])
    at_limit = CollisionWorld(arm, [], held, max_tilt=float(np.arccos(up)))
    assert at_limit._spheres.candidates(q) == -2
    assert at_limit._spheres.free(q) is None
    assert at_limit.is_valid(q) == _pinocchio_answer(at_limit, q)[0]
    checks = at_limit.checks
    assert at_limit.states_valid(np.array([q, q, q])) == at_limit.is_valid(q)  # a batch asks Pinocchio too
    assert at_limit.checks - checks == (4 if at_limit.is_valid(q) else 2)
    steeper = CollisionWorld(arm, [], held, max_tilt=float(np.arccos(up)) * 0.5)
    assert steeper._spheres.candidates(q) == -1 and not steeper.is_valid(q)


def test_an_arm_without_a_compiled_chain_is_checked_by_pinocchio(robot_cfg):
    arm = ArmModel(robot_cfg)
    arm.chain = None
    world = _shelf_world(arm)
    assert world._spheres is None
    rng = np.random.default_rng(3)
    for _ in range(50):
        q = arm.clamp(np.asarray(arm.config.home, dtype=float) + rng.normal(scale=1.0, size=arm.dof))
        assert world.is_valid(q) == world._free_pinocchio(q)


def test_the_kernel_checks_the_joint_limits_as_within_limits_does(arm):
    """A joint a hair beyond its limit (or NaN) is invalid in the same compiled call; at the limit it is not.
    Messages still name what collides there."""
    world = _shelf_world(arm)
    home = np.asarray(arm.config.home, dtype=float)
    for i in range(arm.dof):
        for bound, step in ((arm.upper, 2e-9), (arm.lower, -2e-9)):
            q = home.copy()
            q[i] = bound[i]
            assert world._spheres.candidates(q) >= 0 and arm.within_limits(q)
            assert world.is_valid(q) == _pinocchio_answer(world, q)[0]
            q[i] = bound[i] + step
            assert world._spheres.candidates(q) == -3 and not world.is_valid(q) and not arm.within_limits(q)
    q = home.copy()
    q[2] = np.nan
    assert world._spheres.candidates(q) == -3 and not world.is_valid(q)
    inside = home.copy()
    inside[1] = 1.2  # the arm reaching down into the shelf
    beyond = inside.copy()
    beyond[3] = arm.upper[3] + 0.01
    assert world.colliding_pairs(inside) and world.colliding_pairs(beyond)


def _hull_arrays(spheres):
    """The packed hull vertices, first vertex and count per geometry, and swept radii (`kernel_layout`)."""
    sizes = {"nj": spheres.n_joints, "ns": spheres.n_spheres, "ng": len(spheres.shapes)}
    floats, ints = ARM_F.unpack(spheres.arm_f, sizes), ARM_I.unpack(spheres.arm_i, sizes)
    return floats["hull"], ints["hull_first"], ints["hull_count"], floats["swept"]


def test_hulls_apart_proves_only_real_gaps(any_arm):
    """Two robot hulls at random poses: proven apart only where coal measures more than the margin, and proven
    for nearly every pair coal finds 5 mm apart or more (the Panda's meshes; the iiwa7's gripper boxes)."""
    import coal

    from scone_bt.motion import compiled

    spheres = arm_spheres(any_arm, 0.02)
    hull, first, count, swept = _hull_arrays(spheres)
    with_hull = [g for g in range(len(spheres.shapes)) if count[g] > 0]
    assert len(with_hull) >= 3
    for g in with_hull:  # the packed vertices are the shape's own: its support in every direction is coal's
        pts = hull[first[g] : first[g] + count[g]]
        shape = spheres.shapes[g]
        if type(shape).__name__ == "Box":
            assert np.allclose(np.abs(pts), np.asarray(shape.halfSide))
        else:
            assert np.array_equal(pts, np.asarray(shape.points()).reshape(-1, 3))
        assert swept[g] == 0.0
    rng = np.random.default_rng(5)
    ng = len(spheres.shapes)
    rotation, translation = np.zeros((ng, 3, 3)), np.zeros((ng, 3))
    proven_far = far = 0
    for _ in range(3000):
        a, b = rng.choice(with_hull, size=2, replace=False)
        for g in (a, b):
            rotation[g] = pin.Quaternion(*rng.normal(size=4)).normalized().matrix()
        translation[a] = 0.0
        translation[b] = rng.normal(size=3) * rng.uniform(0.02, 0.2)
        tf = [coal.Transform3s(rotation[g].copy(), translation[g].copy()) for g in (a, b)]
        gap = coal.distance(
            spheres.shapes[a], tf[0], spheres.shapes[b], tf[1], coal.DistanceRequest(), coal.DistanceResult()
        )
        v = translation[a] - translation[b] + rng.normal(size=3) * 0.01
        apart = compiled.hulls_apart(
            rotation, translation, hull, first, count, compiled.HULL_MARGIN_M, a, b, *v
        )
        if apart:
            assert gap > compiled.HULL_MARGIN_M, (a, b, gap)
        if gap > 0.005:
            far += 1
            proven_far += apart
    assert far > 500
    assert proven_far / far > 0.95


def test_a_folded_wrist_is_answered_as_pinocchio(arm):
    """States with the wrist folded (the Panda's link 5 a few centimetres from link 7 and the hand, their spheres
    meeting): the same answers and pairs as Pinocchio's world, with most of those pairs settled by the hulls'
    bound instead of GJK."""
    world = _shelf_world(arm, fingers=0.03)
    rng = np.random.default_rng(13)
    home = np.asarray(arm.config.home, dtype=float)
    states = []
    for _ in range(600):
        q = home + rng.normal(scale=0.3, size=arm.dof)
        q[5] = rng.uniform(1.2, 3.7) if arm.config.name == "panda" else q[5]
        q[6] = rng.uniform(-2.8, 2.8)
        states.append(arm.clamp(q))
    answers = [world._free(q) for q in states]
    narrow = world._spheres.narrow
    for q, mine in zip(states, answers, strict=True):
        theirs, their_pairs = _pinocchio_answer(world, q)
        assert mine == theirs and world.colliding_pairs(q) == their_pairs, q
    assert 0.2 < np.mean(answers) <= 1.0
    kept = world._spheres._spheres.arm_i[_hull_count_slice(world)].copy()
    world._spheres._spheres.arm_i[_hull_count_slice(world)] = 0
    try:
        before = world._spheres.narrow
        assert [world._free(q) for q in states] == answers
        without = world._spheres.narrow - before
    finally:
        world._spheres._spheres.arm_i[_hull_count_slice(world)] = kept
    assert narrow < 0.5 * without, (narrow, without)


def _hull_count_slice(world):
    spheres = world._spheres._spheres
    sizes = {"nj": spheres.n_joints, "ns": spheres.n_spheres, "ng": len(spheres.shapes)}
    return slice(*ARM_I.span("hull_count", sizes))


@pytest.mark.parametrize("held", [False, True])
def test_a_worlds_pairs_are_those_the_arm_can_bring_together(any_arm, held):
    """The compiled pair list, as Pinocchio's matrix, against the rule written out with numpy: self pairs; moving
    geometries with the obstacles their reach meets, less the hand with the ignored ones; the held object with
    the moving geometries outside the hand and with every obstacle."""
    arm = any_arm
    rng = np.random.default_rng(21)
    obstacles = [
        Obstacle(
            f"o{k}",
            "box" if k % 3 else "cylinder",
            tuple(rng.uniform(0.02, 0.3, 3)),
            pose_matrix(np.eye(3), rng.uniform([-1.5, -1.5, -0.2], [1.5, 1.5, 1.5])),
        )
        for k in range(40)
    ]
    attached = Obstacle("jar", "cylinder", (0.07, 0.07, 0.12), pose_matrix(np.eye(3), (0, 0, 0.07)))
    ignore = ["o1", "o2", "o7"]
    world = CollisionWorld(arm, obstacles, attached if held else None, padding=0.02, ignore_for_hand=ignore)
    n_robot, n_ob = len(arm.robot_geometry), len(obstacles)
    expected = np.zeros((n_robot + n_ob + held,) * 2, dtype=bool)
    expected[arm.self_pairs[:, 0], arm.self_pairs[:, 1]] = True
    centres = np.array([ob.pose[:3, 3] for ob in obstacles]) - np.asarray(arm.config.base_position)
    radii = 0.5 * np.linalg.norm(np.array([ob.size for ob in obstacles]) + 0.04, axis=1)
    near = np.linalg.norm(centres - arm.first_joint_origin, axis=1)[None, :] <= (
        arm.geometry_reach_from_first_joint[:, None] + radii[None, :]
    )
    ignored = np.array([ob.name in ignore for ob in obstacles])
    moving, in_hand = arm.moving_geometry, arm.hand_geometry
    expected[:n_robot, n_robot : n_robot + n_ob] = moving[:, None] & near & ~(in_hand[:, None] & ignored)
    if held:
        expected[:n_robot, -1] = moving & ~in_hand
        expected[n_robot:-1, -1] = True
    assert np.array_equal(world._check_matrix(), expected)
    assert 0 < near.sum() < near.size  # some obstacles out of reach, some within
