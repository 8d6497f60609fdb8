"""Grasp search: which grasp candidates the arm can take, cheapest first, and why the others were rejected.

Candidates (`grasp.grasp_candidates`, cheapest first) are filtered by the hand alone against the scene (no IK),
then by IK of the pre-grasp pose, the arm's collisions there, and a straight collision-free descent and lift
(solved in up to `LINE_MAX_WAYPOINTS` pieces where the joints bow away from the line); where the first IK answer's
arm collides or cannot follow that line, `GraspParams.ik_alternatives` other arm postures (IK from random seeds) are
tried for the same hand pose. The hand is checked, and executed, with its fingers pre-shaped (`preshape`): opened
only as far as the widest candidate needs, so they fit between close neighbours.

The search is resumable: `search_grasps` examines candidates from a cursor until it has found as many as wanted,
so the path search asks for more only when it has used up the ones it had.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from scone_bt.config.grasp import GraspParams
from scone_bt.motion.collision import CollisionWorld, HandModel
from scone_bt.motion.grasp import GraspCandidate, grasp_candidates, lifted
from scone_bt.motion.pick_request import PickScene
from scone_bt.motion.plan_session import (
    LINE_MIN_TOLERANCE,
    LINE_TOLERANCE,
    PlanSession,
    blockers_at,
    collision_pair,
)
from scone_bt.motion.plan_stats import PlanStats

__all__ = ["FeasibleGrasp", "GraspBatch", "GraspSite", "prepare_grasps", "preshape", "search_grasps"]


@dataclass(frozen=True, eq=False)
class GraspSite:
    """The target's candidates and surroundings, prepared once per plan for the grasp search.

    Attributes:
        candidates: Grasp candidates, cheapest first.
        finger_position: Each finger's position (m) the hand is pre-shaped to; None: fully open.
        free_world: The arm among every object, the target included (the approach's world).
        grasp_world: The same with a thinner margin where the hand may touch the target (descent and lift).
        hand_free: The hand alone among every object (at the pre-grasp).
        hand_near: The hand alone with the thinner margin (between pre-grasp and lift).
        lift: Height (m) the object is lifted by: until it clears its neighbours' tops.
        gap: Room (m) between the pre-shaped fingers; None: no opening known.
    """

    candidates: tuple[GraspCandidate, ...]
    finger_position: float | None
    free_world: CollisionWorld
    grasp_world: CollisionWorld
    hand_free: HandModel
    hand_near: HandModel
    lift: float
    gap: float | None


@dataclass(frozen=True, eq=False)
class FeasibleGrasp:
    """A grasp the arm can take: its candidate and the joint paths down to it and up again.

    Attributes:
        cand: The candidate.
        q_pre: (dof,) joints at the pre-grasp pose, radians.
        descend: (k, dof) joint path from q_pre down to the grasp.
        lift: (k, dof) joint path from the grasp up.
    """

    cand: GraspCandidate
    q_pre: np.ndarray
    descend: np.ndarray
    lift: np.ndarray

    @property
    def q_grasp(self) -> np.ndarray:
        """(dof,) joints at the grasp."""
        return self.descend[-1]

    @property
    def q_lift(self) -> np.ndarray:
        """(dof,) joints with the object lifted."""
        return self.lift[-1]


@dataclass(frozen=True, eq=False)
class GraspBatch:
    """What one `search_grasps` call found.

    Attributes:
        grasps: Feasible grasps, cheapest first (at most the number wanted).
        next_index: The cursor to resume from: candidates before it have been examined.
        stats: Why the candidates examined in this call were rejected.
    """

    grasps: tuple[FeasibleGrasp, ...]
    next_index: int
    stats: PlanStats


def preshape(
    candidates: Sequence[GraspCandidate], opening: float | None, closed: float, params: GraspParams
) -> float | None:
    """Finger position (m) that leaves `params.preshape_margin` beside the widest span any candidate needs.

    A hand opened only that far fits between close neighbours (as a robot's pre-grasp posture does); None (fully
    open) without an opening or candidates, or when the widest span needs the full opening anyway.
    """
    if opening is None or not candidates:
        return None
    widest = max(c.span for c in candidates)
    position = closed + widest / 2 + params.preshape_margin
    return None if position >= closed + opening / 2 - 1e-9 else float(position)


def prepare_grasps(session: PlanSession, scene: PickScene) -> GraspSite:
    """The target's grasp candidates, the hand's pre-shape, the collision worlds and the lift height."""
    req = scene.request
    params = req.params
    if req.pinch is not None:  # a slid flat pack: its front edge, nothing else (motion.slide)
        from scone_bt.motion.slide import pinch_candidates

        candidates = pinch_candidates(req.target, req.spec, req.pinch, params.approach)
    else:
        candidates = grasp_candidates(req.target, req.spec, params, req.preferred_yaw, req.opening)
    fingers = preshape(candidates, req.opening, req.finger_closed, params)
    around = [*scene.fixed, scene.target]
    free_world = session.world(around, finger_position=fingers)
    # Near the grasp the fingers come within millimetres of the supporting shelf: a thinner margin there.
    grasp_world = session.world(around, ignore_for_hand=[scene.name], padding=0.004, finger_position=fingers)
    return GraspSite(
        candidates=tuple(candidates),
        finger_position=fingers,
        free_world=free_world,
        grasp_world=grasp_world,
        hand_free=HandModel(session.arm, around, padding=0.01, finger_position=fingers),
        hand_near=HandModel(session.arm, around, padding=0.004, finger_position=fingers),
        lift=_lift_height(scene),
        gap=req.opening if fingers is None else 2 * (fingers - req.finger_closed),
    )


def search_grasps(
    session: PlanSession, scene: PickScene, site: GraspSite, start: int, wanted: int
) -> GraspBatch:
    """Examine candidates from index `start` until `wanted` feasible grasps are found or none are left."""
    found: list[FeasibleGrasp] = []
    stats = PlanStats()
    index = start
    while len(found) < wanted and index < len(site.candidates):
        cand = site.candidates[index]
        index += 1
        grasp, stats = _feasible(session, scene, site, cand, stats.counted())
        if grasp is not None:
            found.append(grasp)
    return GraspBatch(tuple(found), index, stats)


def _feasible(
    session: PlanSession, scene: PickScene, site: GraspSite, cand: GraspCandidate, stats: PlanStats
) -> tuple[FeasibleGrasp | None, PlanStats]:
    """The candidate's joint paths, or None; with `stats` plus why it was rejected."""
    arm, req, params, lift = session.arm, scene.request, scene.request.params, site.lift
    family = cand.family.value
    hits = site.hand_free.colliding(cand.pregrasp)
    if not hits:
        for pose in (_between(cand.pregrasp, cand.grasp, 0.5), cand.grasp, lifted(cand.grasp, lift)):
            hits = site.hand_near.colliding(pose, ignore=(scene.name,))
            if hits:
                break
    if hits:
        return None, stats.blocked(f"{family} grasps: the hand collides with {hits[0]}", hits)
    if not (arm.can_reach(cand.pregrasp[:3, 3]) and arm.can_reach(cand.grasp[:3, 3])):
        return None, stats.blocked(f"{family} grasp beyond the arm's reach", ())
    # The arm's first IK answer may put its forearm into a tall neighbour or start a descent it cannot follow;
    # another arm posture for the same hand pose (a 7-joint arm has a family of them) may not.
    for attempt in range(1 + params.ik_alternatives):
        seed = req.q_start if attempt == 0 else session.rng.uniform(arm.lower, arm.upper)
        q_pre = session.ik(cand.pregrasp, seed, restarts=4)
        if q_pre is None:
            if attempt == 0:
                stats = stats.blocked(f"{family} pre-grasp out of reach", ())
            break  # no posture reaches it from anywhere: another seed finds none either
        stats = stats.reached()
        if not site.free_world.is_valid(q_pre):
            why = f"{family} pre-grasp collides ({collision_pair(site.free_world, q_pre)})"
            stats = stats.blocked(why, blockers_at(site.free_world, q_pre))
            continue
        descend, why, names = session.line(
            q_pre, cand.grasp, site.grasp_world, f"{family} descent", _descent_tolerance(site.gap, cand)
        )
        if descend is None:
            stats = stats.blocked(why, names)
            continue
        up, why, names = session.line(descend[-1], lifted(cand.grasp, lift), site.grasp_world, "lift")
        if up is None and lift > params.lift:  # too high to reach: the plain lift, a harder transit
            up, why, names = session.line(
                descend[-1], lifted(cand.grasp, params.lift), site.grasp_world, "lift"
            )
        if up is None:
            stats = stats.blocked(why, names)
            continue
        return FeasibleGrasp(cand, q_pre, descend, up), stats
    return None, stats


def _lift_height(scene: PickScene) -> float:
    """Lift until the object's bottom clears its neighbours' tops (from there the straight carry towards the
    table is usually free, and OMPL is needed far less often), within the robot file's bounds."""
    req, params = scene.request, scene.request.params
    bottom = req.target.position[2] - req.spec.height
    near_tops = [
        float(o.pose[2, 3] + o.size[2] / 2)
        for o in scene.others
        if np.hypot(*(o.pose[:2, 3] - np.asarray(req.target.position[:2]))) < params.clear_radius
    ]
    return float(np.clip(max(near_tops, default=0.0) + 0.03 - bottom, params.lift, params.max_lift))


def _descent_tolerance(gap: float | None, cand: GraspCandidate) -> float:
    """Sideways drift allowed on the way down: 2/3 of the room beside the object (no finger lands on it).

    A tight fit (a 7.5 cm tub in the 8 cm opening leaves 2.5 mm a side) allows less than the usual line
    tolerance; a finger that drifted onto the rim would tip the object over before the grip closes.
    """
    if gap is None:
        return LINE_TOLERANCE
    return float(np.clip((gap - cand.span) / 3, LINE_MIN_TOLERANCE, LINE_TOLERANCE))


def _between(a: np.ndarray, b: np.ndarray, t: float) -> np.ndarray:
    """The pose a fraction t of the way from a to b (translation only; both share a rotation here)."""
    out = b.copy()
    out[:3, 3] = a[:3, 3] + (b[:3, 3] - a[:3, 3]) * t
    return out
