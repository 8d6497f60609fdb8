"""Another place spot while carrying: the planned one was taken during the carry.

The plan chose its place spot before the arm moved (plan before commit). A person may put something there while
the robot carries its product over (the `impatient-human` scenario: the olive oil on the crushed tomatoes' spot).
The execution looks at the spot while it carries (`ArmExecutor.products_at`); when something stands there, the arm
holds still and `plan_new_spot` plans, from where it holds, the rest of the motion to another spot among what
stands on the table now: transit, lowering, retreat and the way home, through the same steps as the first plan
(`placement_search.search_placements`, OMPL, ruckig), seeded, so a seeded run repeats exactly. A request that
named its spot keeps it: the rest of the motion goes to the same spot another way, around what was put down in
its way (motion.path_watch). Where there is no other spot (or something stands on the spot the request named), the
answer is the rest of the original transit, re-timed from rest: the robot goes on as planned, and the attempt says
what it knocked over.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from scone_bt.motion.collision import Obstacle
from scone_bt.motion.grasp_search import FeasibleGrasp
from scone_bt.motion.model import ArmModel
from scone_bt.motion.path_search import way_home
from scone_bt.motion.pick_request import PickPlaceRequest, PickScene
from scone_bt.motion.placement_search import find_spots, search_placements
from scone_bt.motion.plan_session import PlanSession, Segment
from scone_bt.motion.planner import PlannerOptions
from scone_bt.motion.timing import KinematicLimits
from scone_bt.motion.types import MotionPhase

__all__ = [
    "NEW_SPOT_SEED_OFFSET",
    "NewSpot",
    "SPOT_CHECK_S",
    "SPOT_MARGIN",
    "new_spot",
    "plan_new_spot",
    "resume_transit",
]

SPOT_CHECK_S = 0.1
"""Simulated seconds between two looks at the place spot while carrying."""
SPOT_MARGIN = 0.005
"""Gap (m) a product standing beside the place spot must keep from the placed product's footprint."""
NEW_SPOT_SEED_OFFSET = 7919
"""Added to the attempt's seed for the new spot's sampling, IK and OMPL (its own stream, the same every run)."""
RESUME_WAYPOINTS = 12
"""Samples of the rest of the original transit the re-timed path goes through."""


@dataclass(frozen=True, eq=False)
class NewSpot:
    """The rest of the motion from where the arm holds: its segments and where the product will stand.

    Attributes:
        segments: Transit, lower, retreat and home, timed.
        placed: The product's collision shape where it will stand after the release (world frame).
        place_spot: (x, y, table top z) where its centre goes.
        moved: True for a new plan (another spot, or another way to the spot the request named); False for the
            rest of the original plan (no other spot was found).
        why: Why no other spot was taken ("" when one was).
    """

    segments: tuple[Segment, ...]
    placed: Obstacle
    place_spot: tuple[float, float, float]
    moved: bool
    why: str = ""


def new_spot(
    arm: ArmModel,
    request: PickPlaceRequest,
    grasp: FeasibleGrasp,
    fingers: float | None,
    rest: np.ndarray,
    original: tuple[Segment, ...],
    placed: Obstacle,
    spot: tuple[float, float, float],
    blockers: tuple[Obstacle, ...],
    spot_taken: bool,
    options: PlannerOptions,
    limits: KinematicLimits,
    rate_hz: float,
) -> NewSpot:
    """The rest of the motion from where the arm holds (``rest[0]``): to another spot (`plan_new_spot`), or else
    the original plan resumed (`resume_transit`). Runs in the planning worker.

    Args:
        arm: The arm model.
        request: The attempt's request (its table obstacles are what the robot knew when it planned).
        grasp: The grasp that holds the product.
        fingers: The hand's pre-shape (m per finger), as planned.
        rest: (n, dof) the original transit's commanded samples from where the arm holds on, radians.
        original: The original plan's lower, retreat and home segments.
        placed: Where the original plan puts the product (its shape).
        spot: Where its centre goes there (x, y, table top z).
        blockers: What the plan did not know stands on the table now: on that spot, or in the carry's way (shapes
            where they stand).
        spot_taken: Something stands on the spot itself (not only in the way to it).
        options: OMPL's settings.
        limits: The robot's kinematic limits.
        rate_hz: Control rate of the timed segments.
    """
    session = PlanSession(arm, options, limits, rate_hz, request.rng_seed + NEW_SPOT_SEED_OFFSET)
    found = plan_new_spot(
        session, request, grasp, fingers, np.asarray(rest[0], dtype=float), blockers, spot_taken
    )
    if isinstance(found, NewSpot):
        return found
    return resume_transit(session, rest, original, placed, spot, found)


def resume_transit(
    session: PlanSession,
    rest: np.ndarray,
    original: tuple[Segment, ...],
    placed: Obstacle,
    spot: tuple[float, float, float],
    why: str,
) -> NewSpot:
    """The original plan from where the arm holds: the rest of its transit (``rest``, the commanded samples from
    the hold on) re-timed from rest, then its lowering, retreat and way home as planned."""
    idx = np.unique(np.linspace(0, len(rest) - 1, min(len(rest), RESUME_WAYPOINTS)).round().astype(int))
    path = rest[idx] if len(idx) > 1 else np.vstack([rest[0], rest[-1]])
    transit = session.timed(MotionPhase.TRANSIT, path)
    return NewSpot((transit, *original), placed, spot, False, why)


def plan_new_spot(
    session: PlanSession,
    request: PickPlaceRequest,
    grasp: FeasibleGrasp,
    fingers: float | None,
    q_hold: np.ndarray,
    blockers: tuple[Obstacle, ...],
    spot_taken: bool,
) -> NewSpot | str:
    """Transit, lower, retreat and home from ``q_hold`` to another spot, with ``blockers`` standing on the table
    (to the same spot another way where the request named it); or why there is none (a line). Arguments as
    `new_spot`."""
    named = bool(request.place_spots)  # find_spots then offers only the named spots
    if named and spot_taken:
        return "the request named its spot"
    taken = {b.name for b in blockers}
    req = replace(
        request,
        q_start=q_hold,
        table_obstacles=(*(o for o in request.table_obstacles if o.name not in taken), *blockers),
        rng_seed=session.seed,
    )
    scene = PickScene.of(req, session.arm)
    spots = find_spots(scene)
    if not spots.spots:
        return "no other free spot on the table"
    found = search_placements(session, scene, grasp, spots, fingers)
    if not found.placements or found.carry_world is None:
        return (
            "no way down to the spot the request named"
            if named
            else "no other spot the arm can put it down at"
        )
    goal = "the spot the request named" if named else "another spot"
    params = req.params
    goals = np.array([pl.q_pp for pl in found.placements])
    transit = session.plan(q_hold, goals, found.carry_world, params.path_retries)
    if not transit.success:
        return f"no way to {goal} from where the arm holds ({transit.status.value})"
    placement = found.placements[transit.goal_index]
    placed, home = way_home(session, scene, grasp, placement, fingers)
    if not home.success:
        return f"no way home from {goal} ({home.status.value})"
    segments = (
        session.timed(MotionPhase.TRANSIT, transit.waypoints),
        session.timed(MotionPhase.LOWER, placement.lower, slow=True),
        session.timed(MotionPhase.RETREAT, placement.retreat, slow=True),
        session.timed(MotionPhase.HOME, home.waypoints),
    )
    return NewSpot(segments, placed, placement.spot, True)
