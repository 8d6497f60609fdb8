"""Path search: OMPL paths for the approach, the transit and the way home, falling back over grasps.

The approach's goal set is built grasp by grasp: each feasible grasp's straight joint-space segment from the start
is checked as it is found, and the first one free ends the search (`PlanSession.direct`); only where none of the
first `GraspParams.max_goal_grasps` is reached that way does OMPL plan to them all at once and report which grasp it
reached. OMPL tries the straight segments in goal order first, so the grasp is the one a set built whole gives, and
fewer candidates are examined. A query that runs out of iterations is repeated with a fresh seed
(`GraspParams.path_retries`) before it counts as no path. Placements for that grasp form the transit's goal set the
same way; then the way home. A grasp without a feasible placement or transit is dropped and the
approach is planned again to the other grasps (more candidates are examined as the set empties); a way home that
does not exist ends the search, as it is the same for every grasp.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from scone_bt.motion.collision import CollisionWorld, Obstacle
from scone_bt.motion.grasp_search import FeasibleGrasp, GraspSite, search_grasps
from scone_bt.motion.pick_request import PickScene
from scone_bt.motion.placement_search import Placement, PlacementSpots, search_placements
from scone_bt.motion.plan_session import PlanSession
from scone_bt.motion.plan_stats import PlanStats
from scone_bt.motion.types import PlanResult

__all__ = ["Paths", "PathSearch", "search_paths", "way_home"]


@dataclass(frozen=True, eq=False)
class Paths:
    """The OMPL paths of one whole pick-and-place and the grasp and placement they join.

    Attributes:
        grasp: The grasp the approach reached.
        placement: The placement the transit reached.
        approach: Start to the pre-grasp.
        transit: Lifted to above the spot.
        home: After the retreat, back home.
        placed: The object's collision shape where it will stand after the release (world frame).
        goal_set_sizes: Number of goals handed to OMPL for the approach and the transit.
    """

    grasp: FeasibleGrasp
    placement: Placement
    approach: PlanResult
    transit: PlanResult
    home: PlanResult
    placed: Obstacle
    goal_set_sizes: tuple[int, int]


@dataclass(frozen=True, eq=False)
class PathSearch:
    """The paths found, or what ran out; and every step's statistics either way.

    Attributes:
        paths: The paths; None when no grasp led to a whole plan.
        grasps: Why grasp candidates were rejected (`examined`: how many were examined).
        placements: Why placements were rejected, over every grasp tried.
        path_failures: One line per OMPL query that failed, in order.
        placement_failed: Whether some grasp's placement search ran and found no placement.
        home_failure: Why the way home failed (that ends the search); None if it did not.
    """

    paths: Paths | None
    grasps: PlanStats
    placements: PlanStats
    path_failures: tuple[str, ...] = ()
    placement_failed: bool = False
    home_failure: str | None = None


def way_home(
    session: PlanSession, scene: PickScene, grasp: FeasibleGrasp, placement: Placement, fingers: float | None
) -> tuple[Obstacle, PlanResult]:
    """The product's shape where ``placement`` puts it (held by ``grasp``), and OMPL's way home from the retreat
    among the fixed obstacles and it."""
    req = scene.request
    placed = Obstacle(scene.name, req.spec.shape, req.spec.size, placement.ee_place @ grasp.cand.object_in_ee)
    # The hand has just retreated straight up from the object: the near-object margin, as for the retreat.
    w_after = session.world([*scene.fixed, placed], padding=0.004, finger_position=fingers)
    home = session.plan(placement.q_ret, np.asarray(req.home, dtype=float), w_after, req.params.path_retries)
    return placed, home


def search_paths(
    session: PlanSession, scene: PickScene, site: GraspSite, spots: PlacementSpots
) -> PathSearch:
    """Grasps, placements and OMPL paths for the whole motion, falling back to other grasps as they fail."""
    req, params = scene.request, scene.request.params
    fingers = site.finger_position
    pool: list[FeasibleGrasp] = []
    grasps = placements = PlanStats()
    path_failures: list[str] = []
    placement_failed = False
    cursor = 0
    while True:
        # The goal set is built grasp by grasp and ends at the first grasp reached in a straight line (most are):
        # OMPL, with the whole set, runs only where none is; it would have taken the same grasp with the set
        # built up front, as it tries the straight segments in order (`planner.direct_path`).
        approach = None
        while approach is None and len(pool) < params.max_goal_grasps:
            batch = search_grasps(session, scene, site, cursor, 1)
            cursor, grasps = batch.next_index, grasps + batch.stats
            if not batch.grasps:
                break  # no candidate left
            pool.append(batch.grasps[0])
            direct = session.direct(req.q_start, pool[-1].q_pre, site.free_world)
            if direct is not None:
                approach = replace(direct, goal_index=len(pool) - 1)
        if not pool:
            break
        approach_set = len(pool)
        if approach is None:
            approach = session.plan(
                req.q_start, np.array([g.q_pre for g in pool]), site.free_world, params.path_retries
            )
        if not approach.success:
            path_failures.append(f"approach: {approach.status.value} ({approach.message})")
            pool = []  # none of these grasps can be reached: examine the next candidates
            continue
        chosen = pool[approach.goal_index]
        # The transit's goal set likewise ends at the first placement reached in a straight line.
        straight: list[PlanResult] = []
        found = search_placements(
            session, scene, chosen, spots, fingers, until=_straight_to(session, chosen.q_lift, straight)
        )
        grasps, placements = grasps + found.grasp_stats, placements + found.stats
        if not found.placements or found.carry_world is None:
            placement_failed = placement_failed or found.carry_world is not None
            pool.remove(chosen)
            continue
        goals = np.array([pl.q_pp for pl in found.placements])
        transit = (
            straight[0]
            if straight
            else session.plan(chosen.q_lift, goals, found.carry_world, params.path_retries)
        )
        if not transit.success:
            path_failures.append(f"transit: {transit.status.value} ({transit.message})")
            pool.remove(chosen)
            continue
        placed = found.placements[transit.goal_index]
        placed_obstacle, home = way_home(session, scene, chosen, placed, fingers)
        if not home.success:
            # Home is the same for every grasp; another grasp would not change the way back.
            why = f"return home: {home.status.value} ({home.message})"
            return PathSearch(None, grasps, placements, tuple(path_failures), placement_failed, why)
        paths = Paths(
            grasp=chosen,
            placement=placed,
            approach=approach,
            transit=transit,
            home=home,
            placed=placed_obstacle,
            goal_set_sizes=(approach_set, len(found.placements)),
        )
        return PathSearch(paths, grasps, placements, tuple(path_failures), placement_failed)
    return PathSearch(None, grasps, placements, tuple(path_failures), placement_failed)


def _straight_to(
    session: PlanSession, q_from: np.ndarray, direct: list[PlanResult]
) -> Callable[[Placement, CollisionWorld], bool]:
    """A `search_placements` stop: true at the first placement the straight segment from `q_from` reaches (that
    segment goes into `direct`, as the query it replaces, with the placement's index as its goal)."""
    seen = 0

    def reached(placement: Placement, world: CollisionWorld) -> bool:
        nonlocal seen
        straight = session.direct(q_from, placement.q_pp, world)
        seen += 1
        if straight is not None:
            direct.append(replace(straight, goal_index=seen - 1))
        return straight is not None

    return reached
