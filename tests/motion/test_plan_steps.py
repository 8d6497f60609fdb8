"""The steps of a pick-and-place plan on their own: rejection statistics, blame, and a resumable grasp search."""

from __future__ import annotations

import numpy as np

from scone_bt.motion import FailureStage, PlanFailureReason
from scone_bt.motion.grasp_search import prepare_grasps, search_grasps
from scone_bt.motion.path_search import PathSearch
from scone_bt.motion.pick_place import diagnose_failure
from scone_bt.motion.pick_request import PickPlaceRequest, PickScene
from scone_bt.motion.placement_search import PlacementSpots
from scone_bt.motion.plan_session import PlanSession
from scone_bt.motion.plan_stats import PlanStats
from tests.motion.test_fallbacks import BOTTLE, STATIC, _boxed_in


def test_stats_add_up_in_the_order_the_steps_ran():
    first = PlanStats().counted().blocked("a", ["left"]).blocked("b", ["wall", "left"])
    later = PlanStats().counted(2).reached().blocked("a", ["wall"]).blocked("c", ())
    both = first + later
    assert both.examined == 3 and both.reachable and not first.reachable
    assert both.reasons == ("a", "b", "a", "c")
    assert both.summary() == "a; b; c" and both.summary(2) == "a; b"
    # left and wall are blamed twice each: the one blamed first comes first.
    assert both.top() == ("left", "wall") and both.top(1) == ("left",)
    assert first.reasons == ("a", "b")  # adding made a new record; neither side changed


def _request(**kw):
    target, shelf = _boxed_in(front=False)
    home = np.zeros(7)
    return PickPlaceRequest(home, target, BOTTLE, tuple(shelf), STATIC, home, 0, **kw)


def test_failures_blame_the_latest_stage_that_ran_out():
    req = _request()
    spots = PlacementSpots((((0.4, -0.4, 0.0), ()),) * 5)
    blocked = PlanStats().reached().blocked("lowering to (0.40, -0.40): collides", ["tray"])
    grasps = PlanStats().blocked("top grasps: the hand collides with wall", ["wall"])

    home = diagnose_failure(
        req, 9, spots, PathSearch(None, grasps, blocked, ("approach: x",), True, "home: y")
    )
    assert (home.reason, home.message) == (PlanFailureReason.NO_PATH, "home: y")
    placed = diagnose_failure(req, 9, spots, PathSearch(None, grasps, blocked, ("approach: x",), True))
    assert placed.reason is PlanFailureReason.PLACEMENTS_BLOCKED and placed.blockers == ("tray",)
    assert placed.message == "no placement of bottle clears tray: lowering to (0.40, -0.40): collides"
    unreachable = diagnose_failure(
        req, 9, spots, PathSearch(None, grasps, PlanStats().blocked("far", ()), (), True)
    )
    assert unreachable.reason is PlanFailureReason.NO_PLACEMENT_IK and unreachable.stage is FailureStage.IK
    assert "(5 spots tried)" in unreachable.message
    path = diagnose_failure(
        req, 9, spots, PathSearch(None, grasps, PlanStats(), ("approach: a", "transit: b"))
    )
    assert path.reason is PlanFailureReason.NO_PATH and path.message.endswith(": transit: b")
    grasp = diagnose_failure(req, 9, spots, PathSearch(None, grasps, PlanStats()))
    assert grasp.reason is PlanFailureReason.GRASPS_BLOCKED and grasp.stage is FailureStage.PLANNING
    assert grasp.message.startswith("every grasp of bottle collides with wall (9 tried): top grasps")
    reach = diagnose_failure(
        req, 9, spots, PathSearch(None, PlanStats().blocked("out of reach", ()), PlanStats())
    )
    assert reach.reason is PlanFailureReason.NO_GRASP_IK and reach.stage is FailureStage.IK
    table = diagnose_failure(req, 9, PlacementSpots((), ("tray",)), None)
    assert table.reason is PlanFailureReason.NO_TABLE_SPACE and table.message.endswith("none clears tray")


def test_the_grasp_search_resumes_where_it_stopped(arm, robot_cfg):
    from scone_bt.motion import PlannerOptions, limits_of

    home = np.asarray(robot_cfg.home, dtype=float)
    req = _request()
    req = PickPlaceRequest(home, req.target, req.spec, req.obstacles, req.static, home, 3, opening=0.08)

    def search(step):
        session = PlanSession(arm, PlannerOptions(), limits_of(robot_cfg), 240.0, req.rng_seed)
        scene = PickScene.of(req, arm)
        site = prepare_grasps(session, scene)
        found, stats, cursor = [], PlanStats(), 0
        while len(found) < 3:
            batch = search_grasps(session, scene, site, cursor, min(step, 3 - len(found)))
            found += batch.grasps
            cursor, stats = batch.next_index, stats + batch.stats
            if not batch.grasps:
                break
        return found, stats, cursor

    whole, whole_stats, whole_cursor = search(3)
    # Boxed in on three sides: most candidates are rejected before three feasible ones are found.
    assert len(whole) == 3 and whole_stats.examined == whole_cursor > 3 and whole_stats.blockers
    one_by_one, stats, cursor = search(1)
    assert [g.cand.label for g in one_by_one] == [g.cand.label for g in whole] and cursor == whole_cursor
    assert stats == whole_stats
    for a, b in zip(whole, one_by_one, strict=True):
        assert np.array_equal(a.descend, b.descend) and np.array_equal(a.lift, b.lift)
