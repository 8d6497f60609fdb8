"""Placement search: where on the table a grasped object can be put down, and why other spots were rejected.

Spots are seeded samples of the observed free table area (`placement.sample_placements`; a box's spot comes with
the yaws its rectangle fits at, which fix the hand's turn), or the request's explicit spots. For one grasp they are
filtered by IK above the spot with the object in the hand, a collision-free lowering and a retreat (back up the
lowering path; a side grasp backs out along its approach instead, as its fingers straddle the object below its
top); the first `GraspParams.max_goal_placements` feasible ones form the transit's goal set, or fewer where the
caller stops at one the transit reaches in a straight line (`search_placements`'s `until`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace

import numpy as np

from scone_bt.config.catalogue import Shape
from scone_bt.geometry import wrap_angle
from scone_bt.motion.collision import CollisionWorld, HandModel, Obstacle
from scone_bt.motion.grasp import GraspCandidate, GraspFamily, lifted, place_pose
from scone_bt.motion.grasp_search import FeasibleGrasp
from scone_bt.motion.pick_request import PickScene
from scone_bt.motion.placement import Footprint, sample_placements
from scone_bt.motion.plan_session import PlanSession, blockers_at, collision_pair
from scone_bt.motion.plan_stats import PlanStats, format_point
from scone_bt.motion.slide import carried_size

__all__ = [
    "CARRY_PADDING",
    "Placement",
    "PlacementSearch",
    "PlacementSpots",
    "find_spots",
    "obstacle_footprint",
    "search_placements",
]

CARRY_PADDING = 0.006
"""Safety margin (m) around obstacles while carrying: the lifted object starts close to its neighbours."""


@dataclass(frozen=True)
class PlacementSpots:
    """The spots to try, in order, and what ruled out the rest of the table.

    Attributes:
        spots: ((x, y, table top z), yaws) per spot, metres and radians; no yaws: any orientation fits.
        blockers: What stands on the table and ruled out the most sampled spots.
    """

    spots: tuple[tuple[tuple[float, float, float], tuple[float, ...]], ...]
    blockers: tuple[str, ...] = ()


@dataclass(frozen=True, eq=False)
class Placement:
    """A spot the object can be put down at with one grasp.

    Attributes:
        spot: (x, y, table top z) where the object's centre goes, metres.
        ee_place: (4, 4) end-effector pose at the release, world frame.
        q_pp: (dof,) joints above the spot (the transit's goal), radians.
        lower: (k, dof) joint path from above the spot down to the release.
        retreat: (k, dof) joint path from the release away.
    """

    spot: tuple[float, float, float]
    ee_place: np.ndarray
    q_pp: np.ndarray
    lower: np.ndarray
    retreat: np.ndarray

    @property
    def q_ret(self) -> np.ndarray:
        """(dof,) joints after the retreat."""
        return self.retreat[-1]


@dataclass(frozen=True, eq=False)
class PlacementSearch:
    """What one `search_placements` call found for a grasp.

    Attributes:
        placements: Feasible placements, at most `max_goal_placements`.
        carry_world: The arm carrying the object among the fixed obstacles (the transit's world); None when the
            lifted object already collides, and no spot was tried.
        stats: Why spots were rejected.
        grasp_stats: Why the grasp itself turned out unusable (the lifted object collides); counted with the
            grasps' rejections.
    """

    placements: tuple[Placement, ...]
    carry_world: CollisionWorld | None
    stats: PlanStats
    grasp_stats: PlanStats = PlanStats()


def obstacle_footprint(ob: Obstacle) -> Footprint:
    """The table footprint of an obstacle standing upright: a box's rectangle at its yaw, else a circle."""
    sx, sy, sz = ob.size
    x, y = float(ob.pose[0, 3]), float(ob.pose[1, 3])
    if ob.shape == Shape.BOX:
        yaw = float(np.arctan2(ob.pose[1, 0], ob.pose[0, 0]))
        half = (float(sx) / 2, float(sy) / 2)
        return Footprint(ob.name, x, y, float(np.hypot(*half)), float(sz), half, yaw)
    return Footprint(ob.name, x, y, float(sx) / 2, float(sz))


def _xyz(spot: tuple[float, float, float]) -> tuple[float, float, float]:
    """A spot as a tuple of its three values (a caller's spot may be any sequence of three)."""
    x, y, z = spot
    return (x, y, z)


def find_spots(scene: PickScene) -> PlacementSpots:
    """The request's spots, or spots sampled on the observed free table area; none without a table."""
    req = scene.request
    if req.place_spots:
        return PlacementSpots(tuple((_xyz(s), ()) for s in req.place_spots))
    if req.table is None:
        return PlacementSpots(())
    sampled = sample_placements(
        req.table,
        [obstacle_footprint(o) for o in scene.table_objects],
        Footprint.of(req.spec),
        req.spec.height,
        replace(req.placement, rng_seed=req.rng_seed),
        tuple(scene.base[:2]),
        arrival_yaw=req.target.yaw - scene.target_dir,
    )
    return PlacementSpots(tuple((s.xyz, s.yaws) for s in sampled.spots), sampled.blockers)


@dataclass(frozen=True, eq=False)
class _PlaceWorlds:
    """The collision checks one grasp's placements go through.

    Attributes:
        carry: The arm carrying the object among the fixed obstacles (the transit's world).
        lower: The same with a tighter padding, for the lowering.
        hand: The hand alone among the fixed obstacles: a first look at each release pose.
    """

    carry: CollisionWorld
    lower: CollisionWorld
    hand: HandModel


class _IkSeeds:
    """Where IK above a spot starts, learnt over one grasp's spots (what has worked so far)."""

    def __init__(self) -> None:
        self.last: np.ndarray | None = None  # the last posture found above the table
        self.searched = False  # the one full search from home is spent
        # how often the turned lifted posture seeded IK above a spot, or did not
        self.misses = self.hits_rotated = 0

    def above(
        self,
        session: PlanSession,
        scene: PickScene,
        grasp: FeasibleGrasp,
        pose: np.ndarray,
        radial: float,
        turn: float,
    ) -> np.ndarray | None:
        """(dof,) joints at `pose` above a spot, or None out of reach."""
        rotated = _turned_lift(session, grasp, radial, turn)
        # Seeds in the order that has worked: the turned lifted posture, or the last posture found above the
        # table once the turned one stops carrying over (e.g. from a shelf behind the robot).
        last = self.last
        seeds = (
            [rotated]
            if last is None
            else ([last, rotated] if self.misses > self.hits_rotated else [rotated, last])
        )
        q_pp = None
        for s0 in seeds:
            q_pp = session.ik(pose, s0, restarts=0)
            if q_pp is not None:
                if s0 is rotated:
                    self.hits_rotated += 1
                break
            if s0 is rotated:
                self.misses += 1
        if q_pp is None and not self.searched:
            # The lifted posture does not carry over: one full search from home, whose answer seeds every
            # later spot.
            self.searched = True
            q_pp = session.ik(pose, np.asarray(scene.request.home, dtype=float), restarts=4)
        if q_pp is not None:
            self.last = q_pp
        return q_pp


def _turned_lift(session: PlanSession, grasp: FeasibleGrasp, radial: float, turn: float) -> np.ndarray:
    """The lifted arm turned by the base joint, and a top-down hand's extra turn by the wrist (the last joint
    turns a downward-pointing hand the other way about world z)."""
    arm = session.arm
    rotated = grasp.q_lift.copy()
    # The base turns the way its joint limits allow (the short way round may cross them).
    rotated[0] += min(
        (radial + k * 2 * np.pi for k in (-1, 0, 1)),
        key=lambda r: (not arm.lower[0] <= grasp.q_lift[0] + r <= arm.upper[0], abs(r)),
    )
    if grasp.cand.family is GraspFamily.TOP:
        rotated[-1] -= turn - radial
    return rotated


def search_placements(
    session: PlanSession,
    scene: PickScene,
    grasp: FeasibleGrasp,
    spots: PlacementSpots,
    fingers: float | None,
    until: Callable[[Placement, CollisionWorld], bool] | None = None,
) -> PlacementSearch:
    """The first feasible placements of the object held by `grasp`, in spot order (one per spot at most).

    `until` is shown each placement as it is found, with the carry world; the search ends early once it answers
    True (the path search stops at a spot the transit reaches in a straight line).
    """
    arm, req = session.arm, scene.request
    params, name, cand = req.params, scene.name, grasp.cand
    carried = Obstacle(name, req.spec.shape, req.spec.size, cand.object_in_ee)
    # the transit's held shape allows for a pinched pack's droop (motion.slide.carried_size)
    in_transit = Obstacle(name, req.spec.shape, carried_size(req.spec, cand), cand.object_in_ee)
    w_carry = session.world(
        scene.fixed,
        in_transit,
        padding=CARRY_PADDING,
        max_tilt=params.max_carry_tilt,
        finger_position=fingers,
    )
    if not w_carry.is_valid(grasp.q_lift):
        why = f"lifted {name} collides ({collision_pair(w_carry, grasp.q_lift)})"
        return PlacementSearch(
            (), None, PlanStats(), PlanStats().blocked(why, blockers_at(w_carry, grasp.q_lift))
        )
    w_lower = session.world(
        scene.fixed, carried, padding=0.004, max_tilt=params.max_carry_tilt, finger_position=fingers
    )
    worlds = _PlaceWorlds(
        w_carry, w_lower, HandModel(arm, scene.fixed, padding=0.004, finger_position=fingers)
    )
    out: list[Placement] = []
    stats = PlanStats()
    seeds = _IkSeeds()
    for spot, turns in _spots_and_turns(scene, cand, spots):
        if len(out) >= params.max_goal_placements:
            break
        stats = stats.counted()
        radial = float(np.arctan2(spot[1] - scene.base[1], spot[0] - scene.base[0])) - scene.target_dir
        radial = wrap_angle(radial)
        for turn in turns:
            placement, stats = _place_at(
                session, scene, grasp, worlds, seeds, spot, radial, turn, stats, fingers
            )
            if placement is None:
                continue
            out.append(placement)
            if until is not None and until(placement, w_carry):
                return PlacementSearch(tuple(out), w_carry, stats)
            break
    return PlacementSearch(tuple(out), w_carry, stats)


def _spots_and_turns(
    scene: PickScene, cand: GraspCandidate, spots: PlacementSpots
) -> list[tuple[tuple[float, float, float], list[float]]]:
    """Each spot with the hand's turns to try there: a pinched flat pack's at the table's edges
    (`motion.slide.pinch_placements`), any other's from the spots found (its turns worked out per spot)."""
    req = scene.request
    if cand.family is GraspFamily.PINCH:
        from scone_bt.motion.slide import pinch_placements

        if req.table is None:
            return []
        return [(spot, [turn]) for spot, turn in pinch_placements(req.table, req.spec, cand, scene.base)]
    out: list[tuple[tuple[float, float, float], list[float]]] = []
    for spot, yaws in spots.spots:
        radial = wrap_angle(
            float(np.arctan2(spot[1] - scene.base[1], spot[0] - scene.base[0])) - scene.target_dir
        )
        out.append((spot, _place_turns(radial, yaws, req.target.yaw, cand.family is GraspFamily.TOP)))
    return out


def _place_at(
    session: PlanSession,
    scene: PickScene,
    grasp: FeasibleGrasp,
    worlds: _PlaceWorlds,
    seeds: _IkSeeds,
    spot: tuple[float, float, float],
    radial: float,
    turn: float,
    stats: PlanStats,
    fingers: float | None,
) -> tuple[Placement | None, PlanStats]:
    """The placement at `spot` with the hand turned by `turn`, or None; `stats` with why not (or the reach)."""
    req, params, cand = scene.request, scene.request.params, grasp.cand
    ee_place = place_pose(spot, req.spec, cand.object_in_ee, cand.grasp, turn, params)
    where = format_point(spot[:2])
    hits = worlds.hand.colliding(ee_place) or worlds.hand.colliding(lifted(ee_place, params.retreat))
    if hits:
        return None, stats.blocked(f"at {where} the hand collides with {hits[0]}", hits)
    q_pp = seeds.above(session, scene, grasp, lifted(ee_place, params.approach), radial, turn)
    if q_pp is None:
        return None, stats.blocked(f"above {where} out of reach", ())
    stats = stats.reached()
    if not worlds.carry.is_valid(q_pp):
        why = f"above {where} collides ({collision_pair(worlds.carry, q_pp)})"
        return None, stats.blocked(why, blockers_at(worlds.carry, q_pp))
    lower, why, names = session.line(q_pp, ee_place, worlds.lower, f"lowering to {where}")
    if lower is None:
        return None, stats.blocked(why, names)
    back, why, names = _retreat(session, scene, grasp, ee_place, lower, fingers)
    if back is None:
        return None, stats.blocked(why, names)
    return Placement(_xyz(spot), ee_place, q_pp, lower, back), stats


def _retreat(
    session: PlanSession,
    scene: PickScene,
    grasp: FeasibleGrasp,
    ee_place: np.ndarray,
    lower: np.ndarray,
    fingers: float | None,
) -> tuple[np.ndarray | None, str, list[str]]:
    """The hand's way out after the release (as `PlanSession.line` answers)."""
    req, params, cand = scene.request, scene.request.params, grasp.cand
    if cand.family in (GraspFamily.SIDE, GraspFamily.PINCH):
        # A side grasp's fingers straddle the object below its top (a pinch's lower finger is under it): straight
        # up they would drag it along (or stay around it); they back out along the approach, the way they came in.
        placed_here = Obstacle(scene.name, req.spec.shape, req.spec.size, ee_place @ cand.object_in_ee)
        w_back = session.world(
            [*scene.fixed, placed_here], ignore_for_hand=[scene.name], padding=0.004, finger_position=fingers
        )
        out_pose = ee_place.copy()
        out_pose[:3, 3] -= ee_place[:3, 2] * params.retreat
        return session.line(lower[-1], out_pose, w_back, "retreat")
    if abs(params.retreat - params.approach) < 1e-9:
        # Straight back up the way it came down: free for the hand if it was with the object held.
        return lower[::-1].copy(), "", []
    w_other = session.world(list(scene.fixed), padding=0.004, finger_position=fingers)
    return session.line(lower[-1], lifted(ee_place, params.retreat), w_other, "retreat")


def _place_turns(radial: float, yaws: Sequence[float], object_yaw: float, top: bool) -> list[float]:
    """Turns (rad about world z) of the hand from its grasp to a placement, most natural first.

    The hand turned with the base first (`radial`): then the carry is close to a pure rotation of the first joint
    (vertical for both arms), which keeps the object upright and at its lifted height. A round object may also
    be turned by the wrist; a box must arrive at one of the yaws its footprint fits at (`yaws`, modulo a half
    turn). A top-down hand turns freely about its approach axis; other hands turn at most an eighth of a turn
    from the base's direction.
    """
    limit = np.pi / 2 if top else np.pi / 4
    if not yaws:
        steps = (0.0, np.pi / 4, -np.pi / 4, np.pi / 2, -np.pi / 2) if top else (0.0, np.pi / 4, -np.pi / 4)
        return [radial + d for d in steps]
    out: list[float] = []
    for yaw in yaws:
        d = wrap_angle(yaw - object_yaw - radial, np.pi)  # nearest turn modulo a half turn
        for delta in (d, d - np.pi, d + np.pi):
            if abs(delta) <= limit + 1e-9 and all(abs(radial + delta - t) > 1e-6 for t in out):
                out.append(radial + delta)
    return out
