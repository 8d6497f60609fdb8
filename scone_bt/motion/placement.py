"""Where on the table an object goes: footprint geometry and seeded sampling of the free area (pure numpy).

Footprints are what an object covers seen from above: an oriented rectangle for a box (a carton, a pack) and a
circle for a round product. `clear_spots` is the one test of "does this footprint fit here": it keeps a
candidate whose footprint stays on the table (inset by a margin) and clears every footprint standing there by a
clearance. Both the robot (`sample_placements`, from what its table camera sees or it remembers placing) and the
simulated human (`Kitchen.free_place_spot`, from the simulator's ground truth) use it.

The robot's candidates are a regular grid plus seeded uniform samples over the table; a box is tried at a few
yaws per point (the yaw it arrives at when the arm only turns its base, a quarter turn from that, and the two
yaws aligned with the table's edges). Kept candidates are ordered by the cost

    cost = reach_weight * |r - preferred reach| / table diagonal
         + block_weight * blocking
         + pack_weight * min(room, pack_gap) / pack_gap
         + shadow_weight * (tall obstacles between the robot and the spot)
         + turn_weight * |yaw - arrival yaw| / (pi/2)

where r is the spot's distance from the robot's base, the preferred reach `preferred_reach` (`tall_reach` for an
object at least `tall_height` tall) and room the gap to the nearest footprint or table edge. The arm reaches every
spot from its base outwards, so `blocking` keeps tall objects out of the way of later placements: with
depth = (r - r_min) / (r_max - r_min) over the table's candidates, it is 1 - depth for an object at least
`tall_height` tall (tall objects go to the table's far rim) and 0.3 * depth for a short one (a mild preference for
near spots: short carries, and the arm reaches over short objects). The packing term puts an object next to what
already stands there or against an edge rather than in the middle of the free area, which would split it into
gaps too small for the next product. The shadow term avoids spots the object would have to be lowered into behind
a tall neighbour, one that stands nearer the robot within a hand's width of the line from the base to the spot.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from scone_bt.config import ObjectSpec, SceneSpec
from scone_bt.config.catalogue import Shape
from scone_bt.geometry import wrap_angle

__all__ = [
    "TableRegion",
    "Footprint",
    "Clearance",
    "PlacementOptions",
    "PlacementSpot",
    "PlacementSet",
    "footprint_radius",
    "footprint_gaps",
    "clear_spots",
    "sample_placements",
]


@dataclass(frozen=True)
class TableRegion:
    """The table's top rectangle (axis-aligned in the world frame), metres.

    Attributes:
        center: (x, y) of the top's centre.
        size: (x, y) extents.
        top_z: Height of the top surface.
    """

    center: tuple[float, float]
    size: tuple[float, float]
    top_z: float

    @classmethod
    def from_scene(cls, scene: SceneSpec) -> TableRegion:
        """The table of a kitchen file (scene geometry, known in advance)."""
        (cx, cy, _), (sx, sy, _) = scene.table
        return cls((float(cx), float(cy)), (float(sx), float(sy)), float(scene.table_top_z))


@dataclass(frozen=True)
class Footprint:
    """What an object covers seen from above, metres and radians.

    Attributes:
        name: The object's name (for messages).
        x: Centre, world x.
        y: Centre, world y.
        radius: A circle's radius; for a rectangle the half diagonal (the circle that covers it).
        height: The object's height.
        half_size: A rectangle's half extents along its own x and y axes; None for a circle.
        yaw: The rectangle's orientation about world z.
    """

    name: str
    x: float
    y: float
    radius: float
    height: float
    half_size: tuple[float, float] | None = None
    yaw: float = 0.0

    @classmethod
    def of(cls, spec: ObjectSpec, x: float = 0.0, y: float = 0.0, yaw: float = 0.0) -> Footprint:
        """The footprint of a catalogue product standing upright at (x, y) turned by yaw: boxes are rectangles."""
        sx, sy, sz = spec.size
        if spec.shape == Shape.BOX:
            half = (float(sx) / 2, float(sy) / 2)
            return cls(spec.name, float(x), float(y), float(np.hypot(*half)), float(sz), half, float(yaw))
        return cls(spec.name, float(x), float(y), float(sx) / 2, float(sz))

    @property
    def is_round(self) -> bool:
        return self.half_size is None


@dataclass(frozen=True, eq=False)
class Clearance:
    """Which candidate spots are free, how much room each has, and what rules out the others.

    Attributes:
        free: (N,) True where the footprint fits on the table and clears every obstacle.
        gap: (N,) distance (m) to the nearest obstacle's footprint (a lower bound for two rectangles); inf
            without obstacles.
        edge_gap: (N,) distance (m) from the footprint to the nearest table edge (negative: over it).
        blocker: (N,) index of the obstacle that rules a candidate out (the nearest); -1 where none does.
    """

    free: np.ndarray
    gap: np.ndarray
    edge_gap: np.ndarray
    blocker: np.ndarray


def footprint_radius(spec: ObjectSpec) -> float:
    """Radius of the circle that covers the object seen from above, metres."""
    return Footprint.of(spec).radius


def _extent(
    half: tuple[float, float] | None, radius: float, yaw: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Half extents along world x and y of a footprint turned by `yaw` (its axis-aligned bounding box)."""
    if half is None:
        r = np.full(np.shape(yaw), radius)
        return r, r
    c, s = np.abs(np.cos(yaw)), np.abs(np.sin(yaw))
    return half[0] * c + half[1] * s, half[0] * s + half[1] * c


def footprint_gaps(
    points: np.ndarray, yaws: np.ndarray, shape: Footprint, obstacles: Sequence[Footprint]
) -> np.ndarray:
    """(N, M) distance (m) between `shape` placed at each point and yaw and each obstacle; negative if they overlap.

    Circles against circles and circles against rectangles are exact; two rectangles use the separating axes
    (their largest separation along the four edge normals), a lower bound of the distance that is exact when
    they face each other along an edge: a spot is never reported freer than it is.

    Args:
        points: (N, 2) candidate centres, world frame.
        yaws: (N,) candidate orientations (ignored for a round shape).
        shape: The object's footprint (its x, y and yaw are ignored).
        obstacles: What stands there.
    """
    pts = np.asarray(points, dtype=float).reshape(-1, 2)
    yaw = np.broadcast_to(np.asarray(yaws, dtype=float), (len(pts),))
    out = np.empty((len(pts), len(obstacles)))
    # The placed rectangle's own edge normals and its extents along them: the same for every obstacle.
    own_axes: list[tuple[np.ndarray, np.ndarray]] = []
    for j, ob in enumerate(obstacles):
        d = np.array([ob.x, ob.y]) - pts  # from the candidate to the obstacle
        if shape.is_round and ob.is_round:
            out[:, j] = np.linalg.norm(d, axis=1) - shape.radius - ob.radius
        elif shape.is_round or ob.is_round:
            # Circle against rectangle: the circle centre in the rectangle's frame.
            if ob.is_round:
                rect_yaw, half, centre, r = yaw, shape.half_size, -d, ob.radius
            else:
                rect_yaw, half, centre, r = np.full(len(pts), ob.yaw), ob.half_size, d, shape.radius
            assert half is not None
            c, s = np.cos(rect_yaw), np.sin(rect_yaw)
            local = np.column_stack(
                [c * centre[:, 0] + s * centre[:, 1], -s * centre[:, 0] + c * centre[:, 1]]
            )
            q = np.abs(local) - np.asarray(half)
            outside = np.linalg.norm(np.maximum(q, 0.0), axis=1)
            inside = np.minimum(np.max(q, axis=1), 0.0)
            out[:, j] = outside + inside - r
        else:
            assert shape.half_size is not None and ob.half_size is not None
            if not own_axes:
                for a in (yaw, yaw + np.pi / 2):
                    n = np.column_stack([np.cos(a), np.sin(a)])
                    pa = shape.half_size[0] * np.abs(np.cos(a - yaw)) + shape.half_size[1] * np.abs(
                        np.sin(a - yaw)
                    )
                    own_axes.append((n, pa))
            best = np.full(len(pts), -np.inf)
            for k, a in enumerate(
                (yaw, yaw + np.pi / 2, np.full(len(pts), ob.yaw), np.full(len(pts), ob.yaw + np.pi / 2))
            ):
                if k < 2:
                    n, pa = own_axes[k]
                else:
                    n = np.column_stack([np.cos(a), np.sin(a)])
                    pa = shape.half_size[0] * np.abs(np.cos(a - yaw)) + shape.half_size[1] * np.abs(
                        np.sin(a - yaw)
                    )
                dist = np.abs(np.sum(d * n, axis=1))
                pb = ob.half_size[0] * np.abs(np.cos(a - ob.yaw)) + ob.half_size[1] * np.abs(
                    np.sin(a - ob.yaw)
                )
                best = np.maximum(best, dist - pa - pb)
            out[:, j] = best
    return out


def clear_spots(
    table: TableRegion,
    obstacles: Sequence[Footprint],
    shape: Footprint,
    points: np.ndarray,
    yaws: np.ndarray | float = 0.0,
    clearance: float = 0.01,
    edge_margin: float = 0.0,
) -> Clearance:
    """Which of the candidate spots (points, yaws) hold `shape`: on the table and clear of every obstacle.

    The one free-spot test of the kitchen: the robot passes what it observes on the table, the simulated human
    the simulator's ground truth.

    Args:
        table: The table's top.
        obstacles: Footprints standing on it.
        shape: The footprint to place (its own x, y and yaw are ignored).
        points: (N, 2) candidate centres.
        yaws: (N,) or one orientation of the shape, radians.
        clearance: Gap (m) kept from every obstacle.
        edge_margin: Gap (m) kept from the table's edges (0: the footprint may reach the edge).
    """
    pts = np.asarray(points, dtype=float).reshape(-1, 2)
    yaw = np.broadcast_to(np.asarray(yaws, dtype=float), (len(pts),))
    (cx, cy), (sx, sy) = table.center, table.size
    ex, ey = _extent(shape.half_size, shape.radius, yaw)
    edge_gap = np.minimum(sx / 2 - np.abs(pts[:, 0] - cx) - ex, sy / 2 - np.abs(pts[:, 1] - cy) - ey)
    free = edge_gap >= edge_margin - 1e-12
    if obstacles:
        gaps = footprint_gaps(pts, yaw, shape, obstacles)
        gap = gaps.min(axis=1)
        blocker = np.where(gap < clearance, np.argmin(gaps, axis=1), -1)
        free &= gap >= clearance - 1e-12
    else:
        gap = np.full(len(pts), np.inf)
        blocker = np.full(len(pts), -1)
    return Clearance(free, gap, edge_gap, blocker)


@dataclass(frozen=True)
class PlacementOptions:
    """Sampling settings (metres unless stated).

    Attributes:
        clearance: Gap kept between the placed object's footprint and any other (room for the fingers).
        edge_margin: Gap kept between the footprint and the table's edge, for a flat object.
        edge_margin_per_height: Added to ``edge_margin`` per metre of the object's height (dimensionless): a tall
            product set down a few degrees off upright, or brushed later by the arm, tips over the edge where a
            flat one stays (on MuJoCo's 50 seeded episodes a flat 1 cm let 2 of 401 products fall off the table
            and 4 more topple; 1 cm + 0.1 × height let none fall off: docs/results/cross_engine.md).
        grid_step: Spacing of the regular candidate grid.
        random_samples: Seeded uniform candidates added to the grid.
        tall_height: Objects at least this tall are placed away from the entry edge.
        preferred_reach: Distance from the robot's base the arm places at most comfortably.
        tall_reach: The same for tall objects: farther out, where they do not stand in the way.
        reach_weight, block_weight, pack_weight, shadow_weight, turn_weight: Cost weights (module docstring).
        pack_gap: Room beyond which more room no longer raises the cost.
        max_spots: Spots returned at most.
        rng_seed: Seeds the random candidates.
    """

    clearance: float = 0.02
    edge_margin: float = 0.01
    edge_margin_per_height: float = 0.1
    grid_step: float = 0.04
    random_samples: int = 48
    tall_height: float = 0.15
    preferred_reach: float = 0.5
    tall_reach: float = 0.68
    reach_weight: float = 1.0
    block_weight: float = 0.6
    pack_weight: float = 0.3
    shadow_weight: float = 0.5
    turn_weight: float = 0.1
    pack_gap: float = 0.08
    max_spots: int = 24
    rng_seed: int = 0


@dataclass(frozen=True)
class PlacementSpot:
    """One candidate: where the object's centre goes (x, y; z is the table top), its cost and its room.

    Attributes:
        x: Centre, world x, metres.
        y: Centre, world y, metres.
        z: Table top height, metres.
        cost: Ordering cost (module docstring); lower first.
        gap: Distance (m) to the nearest footprint standing on the table.
        yaws: For a box, the orientations (rad about world z) its footprint fits at here, cheapest first; empty
            for a round object (any orientation fits).
    """

    x: float
    y: float
    z: float
    cost: float
    gap: float
    yaws: tuple[float, ...] = ()

    @property
    def xyz(self) -> tuple[float, float, float]:
        return (self.x, self.y, self.z)


@dataclass(frozen=True)
class PlacementSet:
    """The ordered spots, and which obstacles ruled out the most candidates (for a typed failure's message)."""

    spots: tuple[PlacementSpot, ...]
    blockers: tuple[str, ...]
    candidates: int


@dataclass(frozen=True, eq=False)
class _Candidates:
    """Sampled centres, each with its candidate yaws, and which (centre, yaw) fit (`sample_placements`' step).

    Attributes:
        points: (n, 2) centres, world frame, metres.
        rel: (n, 2) the centres relative to the robot's base, metres.
        yaws: (n, k) candidate yaws per centre, radians (k = 1 for a round object).
        clearance: The free-spot test of every (centre, yaw), centre by centre, yaw within (n * k rows).
    """

    points: np.ndarray
    rel: np.ndarray
    yaws: np.ndarray
    clearance: Clearance

    @property
    def free(self) -> np.ndarray:
        """(n, k) True where the footprint fits at that centre and yaw."""
        return self.clearance.free.reshape(self.yaws.shape)


@dataclass(frozen=True, eq=False)
class _Kept:
    """The centres where some yaw fits, with what ranks them (`sample_placements`' step).

    Attributes:
        points: (m, 2) centres, world frame, metres.
        rel: (m, 2) the centres relative to the robot's base, metres.
        yaws: (m, k) candidate yaws per centre, radians.
        free: (m, k) which of them fit.
        yaw_cost: (m, k) each yaw's cost (turn and packing terms; inf where it does not fit).
        gap: (m,) room (m) to the nearest footprint at the centre's cheapest yaw.
    """

    points: np.ndarray
    rel: np.ndarray
    yaws: np.ndarray
    free: np.ndarray
    yaw_cost: np.ndarray
    gap: np.ndarray


def sample_placements(
    table: TableRegion,
    obstacles: Sequence[Footprint],
    shape: Footprint | float,
    height: float,
    options: PlacementOptions = PlacementOptions(),
    base_xy: tuple[float, float] = (0.0, 0.0),
    arrival_yaw: float = 0.0,
) -> PlacementSet:
    """Free spots for an object of footprint `shape` and `height` on the table, cheapest first.

    Deterministic for given inputs and `options.rng_seed`.

    Args:
        table: The table's top.
        obstacles: Footprints seen (or remembered) on it.
        shape: The object's footprint (its position is ignored), or a radius for a round one.
        height: The object's height, metres.
        options: Sampling settings.
        base_xy: The robot base's position.
        arrival_yaw: For a box, its yaw relative to the direction from the base: the yaw it arrives at a spot
            with when the arm only turns its base is this plus the spot's bearing.
    """
    if not isinstance(shape, Footprint):
        shape = Footprint("object", 0.0, 0.0, float(shape), float(height))
    margin = options.edge_margin + options.edge_margin_per_height * max(0.0, float(height))
    options = replace(options, edge_margin=margin)  # the taller the object, the farther from the edge
    pts = _candidate_points(table, shape, options)
    if pts is None:
        return PlacementSet((), (), 0)
    base = np.asarray(base_xy, dtype=float)
    cands = _fit_candidates(table, obstacles, shape, pts, options, base, arrival_yaw)
    free = np.asarray(cands.free.any(axis=1))  # asarray: numpy types any() as a scalar or an array
    blockers = _blockers(cands, free, obstacles)
    if not free.any():
        return PlacementSet((), blockers, len(pts))
    kept = _keep_fitting(cands, free, options)
    cost = _spot_costs(kept, table, obstacles, shape, height, base, options)
    spots = _ordered_spots(kept, cost, table.top_z, shape.is_round, options.max_spots)
    return PlacementSet(tuple(spots), blockers, len(pts))


def _candidate_points(table: TableRegion, shape: Footprint, options: PlacementOptions) -> np.ndarray | None:
    """(n, 2) centres: a regular grid, then the seeded uniform samples; None where no footprint could fit."""
    (cx, cy), (sx, sy) = table.center, table.size
    # The grid covers every centre whose footprint could fit at some yaw.
    inset = (min(shape.half_size) if shape.half_size is not None else shape.radius) + options.edge_margin
    x0, x1 = cx - sx / 2 + inset, cx + sx / 2 - inset
    y0, y1 = cy - sy / 2 + inset, cy + sy / 2 - inset
    if x0 > x1 or y0 > y1:
        return None
    gx = np.arange(x0, x1 + 1e-9, options.grid_step)
    gy = np.arange(y0, y1 + 1e-9, options.grid_step)
    # Centre the grid in the usable area so both edges get the same margin.
    gx += (x1 - gx[-1]) / 2
    gy += (y1 - gy[-1]) / 2
    grid = np.stack(np.meshgrid(gx, gy, indexing="ij"), axis=-1).reshape(-1, 2)  # x by x, y by y within
    # Generator.uniform's numbers: low + (high - low) u, u its standard draws (13 against 20 us a call).
    low, high = np.array([x0, y0]), np.array([x1, y1])
    rand = low + (high - low) * np.random.default_rng(options.rng_seed).random(
        size=(options.random_samples, 2)
    )
    return np.vstack([grid, rand]) if len(rand) else grid


def _fit_candidates(
    table: TableRegion,
    obstacles: Sequence[Footprint],
    shape: Footprint,
    pts: np.ndarray,
    options: PlacementOptions,
    base: np.ndarray,
    arrival_yaw: float,
) -> _Candidates:
    """Each centre's candidate yaws, and the free-spot test of every (centre, yaw)."""
    n = len(pts)
    rel = pts - base
    bearing = np.arctan2(rel[:, 1], rel[:, 0])
    # Candidate yaws per point (one for a round object): arrival, a quarter turn from it, the table's axes.
    if shape.is_round:
        yaw_sets = np.zeros((n, 1))
    else:
        arrival = arrival_yaw + bearing
        yaw_sets = np.column_stack([arrival, arrival + np.pi / 2, np.zeros(n), np.full(n, np.pi / 2)])
        yaw_sets = arrival[:, None] + wrap_angle(yaw_sets - arrival[:, None], np.pi)
    k = yaw_sets.shape[1]
    flat = clear_spots(
        table,
        obstacles,
        shape,
        np.repeat(pts, k, axis=0),
        yaw_sets.reshape(-1),
        options.clearance,
        options.edge_margin,
    )
    return _Candidates(pts, rel, yaw_sets, flat)


def _blockers(cands: _Candidates, free: np.ndarray, obstacles: Sequence[Footprint]) -> tuple[str, ...]:
    """What ruled out the centres where nothing fits (at their first yaw), most often first."""
    counts: dict[str, int] = {}
    first_blocker = cands.clearance.blocker.reshape(cands.yaws.shape)[~free, 0]
    for b, times in enumerate(
        np.bincount(first_blocker[first_blocker >= 0], minlength=len(obstacles)).tolist()
    ):
        if times:
            counts[obstacles[b].name] = counts.get(obstacles[b].name, 0) + times
    return tuple(sorted(counts, key=lambda name: (-counts[name], name)))


def _keep_fitting(cands: _Candidates, free: np.ndarray, options: PlacementOptions) -> _Kept:
    """The centres where some yaw fits, with each yaw's cost (turning away from the arrival yaw costs a little)."""
    flat, yaw_sets, free_k = cands.clearance, cands.yaws, cands.free
    turn = np.abs(wrap_angle(yaw_sets - yaw_sets[:, :1], np.pi)) / (np.pi / 2)
    room = np.minimum(flat.gap, np.maximum(flat.edge_gap, 0.0)).reshape(yaw_sets.shape)
    yaw_cost = (
        options.turn_weight * turn
        + options.pack_weight * np.minimum(room, options.pack_gap) / options.pack_gap
    )
    yaw_cost = np.where(free_k, yaw_cost, np.inf)
    best_yaw = np.argmin(yaw_cost, axis=1)
    keep = np.flatnonzero(free)
    gap = flat.gap.reshape(yaw_sets.shape)[keep, best_yaw[keep]]
    return _Kept(cands.points[keep], cands.rel[keep], yaw_sets[keep], free_k[keep], yaw_cost[keep], gap)


def _spot_costs(
    kept: _Kept,
    table: TableRegion,
    obstacles: Sequence[Footprint],
    shape: Footprint,
    height: float,
    base: np.ndarray,
    options: PlacementOptions,
) -> np.ndarray:
    """(m,) each kept centre's cost: reach, blocking, its cheapest yaw and the shadow of tall obstacles."""
    rel = kept.rel
    diag = float(np.hypot(*table.size))
    reach = np.linalg.norm(rel, axis=1)
    tall = height >= options.tall_height
    preferred = options.tall_reach if tall else options.preferred_reach
    cost = options.reach_weight * np.abs(reach - preferred) / diag
    span = max(float(reach.max() - reach.min()), 1e-9)
    depth = (reach - reach.min()) / span  # 0 at the spot nearest the robot, 1 at the farthest
    cost += options.block_weight * ((1.0 - depth) if tall else 0.3 * depth)
    cost += kept.yaw_cost.min(axis=1)
    ray = rel / np.maximum(reach, 1e-9)[:, None]
    for o in obstacles:
        if o.height < options.tall_height:
            continue
        orel = np.array([o.x, o.y]) - base
        along = ray @ orel
        across = np.abs(ray[:, 0] * orel[1] - ray[:, 1] * orel[0])
        shadowed = (along > 0) & (along < reach) & (across < o.radius + shape.radius + 0.05)
        cost += options.shadow_weight * shadowed
    return cost


def _ordered_spots(
    kept: _Kept, cost: np.ndarray, top_z: float, is_round: bool, max_spots: int
) -> list[PlacementSpot]:
    """The cheapest `max_spots` spots (ties by x, then y), each with its fitting yaws cheapest first."""
    pts = kept.points
    order = np.lexsort((pts[:, 1], pts[:, 0], np.round(cost, 9)))[:max_spots]
    # Per spot, its fitting yaws cheapest first (each once, to the nanoradian), all spots' rankings at once.
    fitting: list[list[tuple[float, bool]]] = [[]] * len(order)
    if not is_round:
        ranks = np.argsort(kept.yaw_cost[order], axis=1, kind="stable")
        yaw_rows = np.take_along_axis(kept.yaws[order], ranks, axis=1).tolist()
        fit_rows = np.take_along_axis(kept.free[order], ranks, axis=1).tolist()
        fitting = [list(zip(y, f, strict=True)) for y, f in zip(yaw_rows, fit_rows, strict=True)]
    rows = zip(pts[order].tolist(), cost[order].tolist(), kept.gap[order].tolist(), fitting, strict=True)
    return [
        PlacementSpot(x, y, top_z, c, g, tuple(dict.fromkeys(round(v, 9) + 0.0 for v, ok in fit if ok)))
        for (x, y), c, g, fit in rows
    ]
