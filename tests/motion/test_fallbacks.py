"""Planning's fallbacks, in a scene built here (not from the kitchen file): side grasps when top grasps are
blocked, a free spot on a crowded table, typed failures, and planner errors that stop the run."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from scone_bt.config import ObjectSpec
from scone_bt.config.grasp import GraspParams
from scone_bt.errors import UnknownNameError
from scone_bt.motion import (
    FailureStage,
    GraspFamily,
    MotionSystem,
    Obstacle,
    PickPlaceFailure,
    PickPlacePlan,
    PickPlaceRequest,
    PlacementOptions,
    PlanFailureReason,
    PlannerOptions,
    TableRegion,
    limits_of,
    plan_pick_and_place,
)
from scone_bt.motion.model import pose_matrix
from scone_bt.perception.types import Detection


def _spec(name, shape, size):
    return ObjectSpec(name, (), shape, size, 0.3, 0.6, "test", (1, 1, 1, 1), 0)


def _box(name, center, size):
    return Obstacle(name, "box", size, pose_matrix(np.eye(3), center))


# A two-step shelf in front of the robot, the table to its right, the pedestal under it.
STATIC = (
    _box("step0", (0.37, 0.4, -0.3), (0.13, 0.52, 0.6)),
    _box("step1", (0.50, 0.4, -0.27), (0.13, 0.52, 0.66)),
    _box("table", (0.47, -0.43, -0.3), (0.44, 0.40, 0.6)),
    _box("pedestal", (0.0, 0.0, -0.3), (0.22, 0.22, 0.6)),
)
TABLE = TableRegion((0.47, -0.43), (0.44, 0.40), 0.0)
BOTTLE = _spec("bottle", "cylinder", (0.05, 0.05, 0.14))
TALL = _spec("tall", "box", (0.05, 0.05, 0.27))
WALL = _spec("wall", "box", (0.06, 0.22, 0.30))
JAR = _spec("jar", "cylinder", (0.06, 0.06, 0.10))


def _det(name, x, y, top):
    return Detection(name, 0, (x, y, top), 0.0, 1.0, (0, 0, 1, 1))


def make_planner(arm, robot_cfg):
    """plan(target, spec, shelf=(), table=(), seed=0, params=...) -> the plan or typed failure in this scene."""
    home = np.asarray(robot_cfg.home, dtype=float)
    y_axis = arm.fk(home)[:3, 1]
    params = GraspParams.from_section(robot_cfg.raw.get("grasp"), str(robot_cfg.source))
    p = robot_cfg.planner
    options = PlannerOptions(name=p.name, time_limit_s=p.time_limit_s, simplify=p.simplify)

    def plan(target, spec, shelf=(), table=(), **kw):
        request = PickPlaceRequest(
            q_start=home,
            target=target,
            spec=spec,
            obstacles=tuple(shelf),
            static=STATIC,
            home=home,
            rng_seed=kw.pop("seed", 0),
            table=TABLE,
            table_obstacles=tuple(table),
            params=kw.pop("params", params),
            preferred_yaw=float(np.arctan2(y_axis[1], y_axis[0])),
            opening=0.08,
            placement=kw.pop("placement", PlacementOptions()),
        )
        return plan_pick_and_place(arm, request, options, limits_of(robot_cfg), robot_cfg.control.rate_hz)

    return plan, params


@pytest.fixture(scope="module")
def setup(arm, robot_cfg):
    return make_planner(arm, robot_cfg)


@pytest.fixture(scope="module", params=["panda", "iiwa7"])
def either_arm(request):
    """The planner of each arm: both get the same abilities from their robot files."""
    from scone_bt.config import load_robot
    from scone_bt.motion import ArmModel

    robot_cfg = load_robot(request.param)
    return make_planner(ArmModel(robot_cfg), robot_cfg)


def _boxed_in(front: bool):
    """A bottle on the lowest step between two tall boxes, a wall behind it, and optionally one in front."""
    shelf = [
        (_det("left", 0.39, 0.20, TALL.height), TALL),
        (_det("right", 0.39, 0.40, TALL.height), TALL),
        (_det("wall", 0.47, 0.30, 0.06 + WALL.height), WALL),
    ]
    if front:
        shelf.append((_det("front", 0.30, 0.30, TALL.height), TALL))
    return _det("bottle", 0.37, 0.30, BOTTLE.height), shelf


def test_top_grasp_blocked_by_tall_neighbours_succeeds_from_the_side(setup):
    plan, params = setup
    target, shelf = _boxed_in(front=False)
    without_side = plan(target, BOTTLE, shelf, params=replace(params, side_grasps=False))
    assert isinstance(without_side, PickPlaceFailure)
    assert without_side.reason is PlanFailureReason.GRASPS_BLOCKED
    assert set(without_side.blockers) & {"left", "right", "wall"}
    result = plan(target, BOTTLE, shelf)
    assert isinstance(result, PickPlacePlan), result.message
    assert result.grasp.family is GraspFamily.SIDE
    assert abs(result.grasp.grasp[2, 2]) < 1e-9  # a horizontal approach


def test_a_crowded_table_still_takes_an_object(either_arm):
    plan, _ = either_arm
    # Every one of the nine marked spots of the old fixed scheme is taken, by jars and tall bottles.
    spots = [(x, y) for x in (0.37, 0.49, 0.61) for y in (-0.30, -0.42, -0.54)]
    table = [
        Obstacle(
            f"o{i}", "cylinder", (0.06, 0.06, 0.20 if i % 2 else 0.10), pose_matrix(np.eye(3), (x, y, 0.05))
        )
        for i, (x, y) in enumerate(spots)
    ]
    # This table is 12 cm narrower than the kitchen's: its rim has room for the jar only 1 cm from the edge, the
    # margin of a flat product (the shipped 1 cm + 0.1 × height leaves none; test_placement checks that margin).
    flat_margin = PlacementOptions(edge_margin_per_height=0.0)
    result = plan(_det("jar", 0.37, 0.30, JAR.height), JAR, table=table, placement=flat_margin)
    assert isinstance(result, PickPlacePlan), result.message
    x, y, z = result.place_spot
    assert z == TABLE.top_z
    for ob in table:
        assert np.hypot(x - ob.pose[0, 3], y - ob.pose[1, 3]) >= 0.03 + 0.03 + 0.02 - 1e-9
    assert result.placed is not None and np.allclose(result.placed.pose[:2, 3], (x, y), atol=1e-6)


RICE = _spec("rice", "box", (0.11, 0.05, 0.18))
CARTON = _spec("carton", "box", (0.095, 0.064, 0.176))


def test_fingers_pre_shaped_fit_between_close_lane_neighbours(setup):
    plan, params = setup
    # A 5 cm wide pack between two cartons 9.5 cm away on either side: the fully open fingers (8 cm apart)
    # would touch the cartons; opened only 1 cm beyond the pack on each side they fit in the gaps.
    shelf = [
        (_det(n, 0.37, 0.30 + dy, CARTON.height), CARTON) for n, dy in (("left", -0.095), ("right", 0.095))
    ]
    target = _det("rice", 0.37, 0.30, RICE.height)
    wide_open = plan(target, RICE, shelf, params=replace(params, preshape_margin=0.05))
    assert isinstance(wide_open, PickPlaceFailure) and wide_open.reason is PlanFailureReason.GRASPS_BLOCKED
    assert set(wide_open.blockers) & {"left", "right"}
    result = plan(target, RICE, shelf)
    assert isinstance(result, PickPlacePlan), result.message
    assert result.finger_position == pytest.approx(RICE.size[1] / 2 + params.preshape_margin)


def test_a_table_crowded_with_cartons_still_takes_a_box(either_arm):
    from scone_bt.motion.pick_place import obstacle_footprint
    from scone_bt.motion.placement import Footprint, clear_spots

    plan, _ = either_arm
    # Eight cartons square to the table in two rows: their bounding circles would cover the table.
    table = [
        Obstacle(
            f"c{i}",
            "box",
            (0.08, 0.095, 0.20),
            pose_matrix(np.eye(3), (0.29 + 0.105 * (i % 4), -0.32 - 0.12 * (i // 4), 0.10)),
        )
        for i in range(8)
    ]
    result = plan(_det("rice", 0.37, 0.30, RICE.height), RICE, table=table)
    assert isinstance(result, PickPlacePlan), result.message
    placed = result.placed
    yaw = float(np.arctan2(placed.pose[1, 0], placed.pose[0, 0]))
    free = clear_spots(
        TABLE, [obstacle_footprint(o) for o in table], Footprint.of(RICE), placed.pose[None, :2, 3], yaw, 0.02
    )
    assert free.free[0], f"placed at {placed.pose[:2, 3]} yaw {yaw:.2f} overlaps a carton"


def test_straight_moves_near_objects_stay_on_their_line(setup, arm):
    from scone_bt.motion import MotionPhase
    from scone_bt.motion.plan_session import LINE_TOLERANCE

    plan, _ = setup
    result = plan(_det("rice", 0.37, 0.30, RICE.height), RICE)
    assert isinstance(result, PickPlacePlan), result.message
    for seg in result.segments:
        if seg.phase not in (MotionPhase.DESCEND, MotionPhase.LIFT, MotionPhase.LOWER, MotionPhase.RETREAT):
            continue
        pts = np.array([arm.fk(q)[:3, 3] for q in seg.trajectory.positions[::4]])
        a, b = pts[0], pts[-1]
        axis = (b - a) / np.linalg.norm(b - a)
        off = pts - a
        drift = np.linalg.norm(off - np.outer(off @ axis, axis), axis=1)
        assert drift.max() < LINE_TOLERANCE + 0.002, f"{seg.phase} drifts {drift.max() * 1000:.1f} mm"


def test_a_boxed_in_object_fails_naming_what_blocks_it(either_arm):
    plan, _ = either_arm
    target, shelf = _boxed_in(front=True)
    result = plan(target, BOTTLE, shelf)
    assert isinstance(result, PickPlaceFailure)
    assert result.reason is PlanFailureReason.GRASPS_BLOCKED and result.stage is FailureStage.PLANNING
    assert result.blockers and set(result.blockers) <= {"left", "right", "wall", "front", "step0", "step1"}
    assert result.message.startswith("every grasp of bottle collides with ")


def test_an_object_out_of_reach_fails_at_ik(either_arm):
    plan, _ = either_arm
    result = plan(_det("jar", 1.3, 0.3, JAR.height), JAR)
    assert isinstance(result, PickPlaceFailure)
    assert result.reason is PlanFailureReason.NO_GRASP_IK and result.stage is FailureStage.IK


def test_a_full_table_fails_naming_what_fills_it(either_arm):
    plan, _ = either_arm
    tray = Obstacle("tray", "box", (0.44, 0.40, 0.02), pose_matrix(np.eye(3), (0.47, -0.43, 0.01)))
    result = plan(_det("jar", 0.37, 0.30, JAR.height), JAR, table=[tray])
    assert isinstance(result, PickPlaceFailure)
    assert result.reason is PlanFailureReason.NO_TABLE_SPACE and result.blockers == ("tray",)
    assert "tray" in result.message


def test_same_request_same_plan(setup):
    plan, _ = setup
    target, shelf = _boxed_in(front=False)
    a, b = plan(target, BOTTLE, shelf, seed=5), plan(target, BOTTLE, shelf, seed=5)
    assert a.place_spot == b.place_spot and a.grasp.label == b.grasp.label
    for sa, sb in zip(a.segments, b.segments, strict=True):
        assert np.array_equal(sa.trajectory.positions, sb.trajectory.positions)


def test_an_unknown_planner_is_a_configuration_error(kitchen):
    with pytest.raises(UnknownNameError, match="RRTConnect"):
        MotionSystem.build(kitchen, planner=PlannerOptions(name="Teleport"))


def test_a_planner_exception_stops_the_run_instead_of_becoming_an_outcome(kitchen, monkeypatch):
    import scone_bt.motion.system as system_module

    def broken(*args, **kwargs):
        raise RuntimeError("planner bug")

    monkeypatch.setattr(system_module, "plan_pick_and_place", broken)
    with MotionSystem.build(kitchen) as system:
        task = system.pick_and_place(_det("jar", 0.37, 0.30, JAR.height), JAR, [], rng_seed=0)
        task.start()
        with pytest.raises(RuntimeError, match="planner bug"):
            for _ in range(50):
                kitchen.advance(0.1)
        with pytest.raises(RuntimeError, match="planner bug"):
            task.outcome()  # nothing to store as experience


PACK = _spec("pack", "box", (0.11, 0.05, 0.04))
POST = _spec("post", "box", (0.04, 0.05, 0.12))


def test_a_neighbour_in_line_with_a_flat_box_is_passed_by_an_off_centre_grasp(either_arm):
    plan, params = either_arm
    # A 4 cm flat pack (too low for side grasps) with a taller post beside its robot-side half: a centred top grasp
    # puts the palm into the post, and a tilt away from the robot swings the palm towards it.
    target = _det("pack", 0.37, 0.30, PACK.height)
    shelf = [(_det("post", 0.33, 0.36, POST.height), POST)]
    centred = plan(target, PACK, shelf, params=replace(params, offsets=()))
    assert isinstance(centred, PickPlaceFailure) and centred.reason is PlanFailureReason.GRASPS_BLOCKED
    assert "post" in centred.blockers
    result = plan(target, PACK, shelf)
    assert isinstance(result, PickPlacePlan), result.message
    assert result.grasp.family is GraspFamily.TOP
    dx, dy = result.grasp.grasp[:2, 3] - np.array([0.37, 0.30])
    # Moved along the box, away from the post, by one of the robot file's offsets.
    assert abs(dy) < 1e-9 and min(abs(dx - o) for o in params.offsets) < 1e-9


def test_a_side_grasp_backs_out_along_its_approach_after_the_release(setup, arm):
    from scone_bt.motion import MotionPhase

    plan, _ = setup
    target, shelf = _boxed_in(front=False)
    result = plan(target, BOTTLE, shelf)
    assert isinstance(result, PickPlacePlan) and result.grasp.family is GraspFamily.SIDE, result
    retreat = next(s for s in result.segments if s.phase is MotionPhase.RETREAT)
    start, end = arm.fk(retreat.trajectory.positions[0]), arm.fk(retreat.trajectory.positions[-1])
    move = end[:3, 3] - start[:3, 3]
    # Straight up, the open fingers would stay around the bottle (or drag it); back along the approach they leave it.
    assert move @ -start[:3, 2] == pytest.approx(GraspParams().retreat, abs=0.01)
    assert abs(move[2]) < 0.01


def test_a_timed_out_query_is_retried_with_a_fresh_seed_before_no_path(arm, robot_cfg, monkeypatch):
    import scone_bt.motion.plan_session as plan_session
    from scone_bt.motion.types import PlanResult, PlanStatus

    seeds: list[int] = []
    answers: list[PlanStatus] = []

    def fake(start, goal, lower, upper, valid, options):
        seeds.append(options.rng_seed)
        status = answers.pop(0)
        return PlanResult(status, np.vstack([start, goal]) if status is PlanStatus.SUCCESS else None, 0.0)

    monkeypatch.setattr(plan_session, "plan_joint_path", fake)
    planner = plan_session.PlanSession(arm, PlannerOptions(), limits_of(robot_cfg), 240.0, seed=3)
    world = planner.world([])
    home = np.asarray(robot_cfg.home, dtype=float)
    answers[:] = [PlanStatus.TIMED_OUT, PlanStatus.SUCCESS]
    assert planner.plan(home, home + 0.1, world, retries=1).success
    assert len(seeds) == 2 and seeds[0] != seeds[1]  # another seed, not the same search again
    seeds.clear()
    answers[:] = [PlanStatus.TIMED_OUT, PlanStatus.SUCCESS]
    assert planner.plan(home, home + 0.1, world, retries=0).status is PlanStatus.TIMED_OUT
    seeds.clear()
    answers[:] = [PlanStatus.GOAL_INVALID, PlanStatus.SUCCESS]
    # Only a search that ran out of iterations is repeated; an invalid goal stays invalid whatever the seed.
    assert planner.plan(home, home + 0.1, world, retries=1).status is PlanStatus.GOAL_INVALID
    assert len(seeds) == 1


TUB = _spec("tub", "cylinder", (0.075, 0.075, 0.07))


def test_a_tight_fit_is_descended_on_with_less_drift_than_the_room_beside_it(setup, arm):
    from scone_bt.motion import MotionPhase
    from scone_bt.motion.plan_session import LINE_TOLERANCE

    plan, _ = setup
    # 7.5 cm in the 8 cm opening: 2.5 mm a side, less than the usual line tolerance.
    result = plan(_det("tub", 0.37, 0.30, TUB.height), TUB)
    assert isinstance(result, PickPlacePlan), result.message
    assert result.finger_position is None  # fully open: the pre-shape would need more than the opening
    room = (0.08 - TUB.size[0]) / 2
    descent = next(s for s in result.segments if s.phase is MotionPhase.DESCEND)
    pts = np.array([arm.fk(q)[:3, 3] for q in descent.trajectory.positions[::2]])
    axis = (pts[-1] - pts[0]) / np.linalg.norm(pts[-1] - pts[0])
    off = pts - pts[0]
    drift = np.linalg.norm(off - np.outer(off @ axis, axis), axis=1).max()
    assert drift < 2 * room / 3 < LINE_TOLERANCE, f"the descent drifts {drift * 1000:.2f} mm"


def test_a_carried_product_is_checked_at_a_finer_step_than_the_bare_hand(arm, robot_cfg):
    """A small block that what the hand holds sweeps through between two states of the default step is missed by
    that step and caught when the path found is checked again at the carry's (`segments.CARRY_RESOLUTION_SCALE`);
    a query planned through it goes around it."""
    from scone_bt.motion.collision import CollisionWorld, Obstacle, interpolated
    from scone_bt.motion.plan_session import PlanSession
    from scone_bt.motion.segments import CARRY_RESOLUTION_SCALE, motion_step, segment_times

    qa = np.asarray(robot_cfg.home, dtype=float)
    qb = qa.copy()
    qb[0] += 0.10  # the base turns: what the hand holds sweeps sideways
    options = PlannerOptions()
    coarse = segment_times(qa, qb, motion_step(arm.lower, arm.upper, options.resolution))
    fine = segment_times(
        qa, qb, motion_step(arm.lower, arm.upper, options.resolution * CARRY_RESOLUTION_SCALE)
    )
    between = fine[(fine > coarse[0]) & (fine < coarse[1])]
    t = float(between[len(between) // 2])  # a state the finer step checks and the default one does not
    # a thin stick held along the approach axis (its collision shape 5 mm smaller on every side: 2 mm thick)
    held = Obstacle("stick", "box", (0.012, 0.012, 0.20), np.eye(4))
    held.pose[2, 3] = 0.15
    block_pose = arm.fk(qa + t * (qb - qa)) @ held.pose
    block_pose[:3, :3] = np.eye(3)
    block_pose[:3, 3] += np.asarray(
        arm.config.base_position
    )  # fk is in the arm's frame, obstacles in the world's
    block = Obstacle("pepper", "box", (0.004, 0.004, 0.004), block_pose)
    session = PlanSession(arm, options, limits_of(robot_cfg), 240.0, seed=3)
    carrying = CollisionWorld(arm, [block], held, padding=0.0)
    bare = CollisionWorld(arm, [block], padding=0.0)
    assert all(
        carrying.is_valid(qa + c * (qb - qa)) for c in coarse
    )  # free at every state of the default step
    assert not carrying.is_valid(qa + t * (qb - qa))
    assert session.direct(qa, qb, carrying) is None  # the finer step finds it
    assert session.direct(qa, qb, bare) is not None  # the bare hand passes above it, at the default step
    around = session.plan(
        qa, qb, carrying
    )  # OMPL's straight answer grazes it: planned again at the finer step
    fine_step = motion_step(arm.lower, arm.upper, options.resolution * CARRY_RESOLUTION_SCALE)
    assert around.success and all(
        carrying.states_valid(interpolated(a, b, segment_times(a, b, fine_step)))
        for a, b in zip(around.path[:-1], around.path[1:], strict=False)
    )
