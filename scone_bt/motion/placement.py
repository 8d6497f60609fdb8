"""Where on the table an object goes: seeded sampling of the observed free area (pure numpy, no simulator).

Inputs are the table's rectangle (scene geometry from the kitchen file) and the footprints of what is seen, or
remembered, standing on it. Candidates are a regular grid plus seeded uniform samples over the table inset by
`PlacementOptions.edge_margin`; a candidate is kept if its footprint circle clears every obstacle's footprint
circle by `clearance`. Kept candidates are ordered by the cost

    cost = reach_weight * |r - preferred reach| / table diagonal
         + block_weight * blocking
         + crowd_weight * (1 - min(gap, crowd_gap) / crowd_gap)
         + shadow_weight * (tall obstacles between the robot and the spot)

where r is the spot's distance from the robot's base, the preferred reach `preferred_reach` (`tall_reach` for an
object at least `tall_height` tall) and gap its clearance to the nearest obstacle. The arm
reaches every spot from its base outwards, so `blocking` keeps tall objects out of the way of later placements:
with depth = (r - r_min) / (r_max - r_min) over the table's candidates, it is 1 - depth for an object at least
`tall_height` tall (tall objects go to the table's far rim) and 0.3 * depth for a short one (a mild preference for
near spots: short carries, and the arm reaches over short objects). The shadow term avoids spots the object would
have to be lowered into behind a tall neighbour, one that stands nearer the robot within a hand's width of the
line from the base to the spot.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from scone_bt.config import ObjectSpec, SceneSpec

__all__ = [
    "TableRegion",
    "Footprint",
    "PlacementOptions",
    "PlacementSpot",
    "PlacementSet",
    "footprint_radius",
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
    """What stands on the table, seen from above: a circle (metres) and the object's height."""

    name: str
    x: float
    y: float
    radius: float
    height: float


@dataclass(frozen=True)
class PlacementOptions:
    """Sampling settings (metres unless stated).

    Attributes:
        clearance: Gap kept between the placed object's footprint and any other (room for the fingers).
        edge_margin: Gap kept between the footprint and the table's edge.
        grid_step: Spacing of the regular candidate grid.
        random_samples: Seeded uniform candidates added to the grid.
        tall_height: Objects at least this tall are placed away from the entry edge.
        preferred_reach: Distance from the robot's base the arm places at most comfortably.
        tall_reach: The same for tall objects: farther out, where they do not stand in the way.
        reach_weight, block_weight, crowd_weight, shadow_weight: Cost weights (module docstring).
        crowd_gap: Gap beyond which more room no longer lowers the cost.
        max_spots: Spots returned at most.
        rng_seed: Seeds the random candidates.
    """

    clearance: float = 0.02
    edge_margin: float = 0.01
    grid_step: float = 0.04
    random_samples: int = 48
    tall_height: float = 0.15
    preferred_reach: float = 0.5
    tall_reach: float = 0.68
    reach_weight: float = 1.0
    block_weight: float = 0.6
    crowd_weight: float = 0.3
    shadow_weight: float = 0.5
    crowd_gap: float = 0.08
    max_spots: int = 24
    rng_seed: int = 0


@dataclass(frozen=True)
class PlacementSpot:
    """One candidate: where the object's centre goes (x, y; z is the table top), its cost and its clearance."""

    x: float
    y: float
    z: float
    cost: float
    gap: float

    @property
    def xyz(self) -> tuple[float, float, float]:
        return (self.x, self.y, self.z)


@dataclass(frozen=True)
class PlacementSet:
    """The ordered spots, and which obstacles ruled out the most candidates (for a typed failure's message)."""

    spots: tuple[PlacementSpot, ...]
    blockers: tuple[str, ...]
    candidates: int


def footprint_radius(spec: ObjectSpec) -> float:
    """Radius of the circle that covers the object seen from above, metres."""
    sx, sy, _ = spec.size
    return float(0.5 * np.hypot(sx, sy)) if spec.shape == "box" else float(sx / 2)


def sample_placements(
    table: TableRegion,
    obstacles: Sequence[Footprint],
    radius: float,
    height: float,
    options: PlacementOptions = PlacementOptions(),
    base_xy: tuple[float, float] = (0.0, 0.0),
) -> PlacementSet:
    """Free spots for an object of footprint `radius` and `height` on the table, cheapest first.

    Deterministic for given inputs and `options.rng_seed`.
    """
    (cx, cy), (sx, sy) = table.center, table.size
    inset = radius + options.edge_margin
    x0, x1 = cx - sx / 2 + inset, cx + sx / 2 - inset
    y0, y1 = cy - sy / 2 + inset, cy + sy / 2 - inset
    if x0 > x1 or y0 > y1:
        return PlacementSet((), (), 0)
    gx = np.arange(x0, x1 + 1e-9, options.grid_step)
    gy = np.arange(y0, y1 + 1e-9, options.grid_step)
    # Centre the grid in the usable area so both edges get the same margin.
    gx += (x1 - gx[-1]) / 2
    gy += (y1 - gy[-1]) / 2
    grid = np.array([(x, y) for x in gx for y in gy])
    rng = np.random.default_rng(options.rng_seed)
    rand = rng.uniform((x0, y0), (x1, y1), size=(options.random_samples, 2))
    pts = np.vstack([grid, rand]) if len(rand) else grid
    n = len(pts)

    if obstacles:
        centres = np.array([(o.x, o.y) for o in obstacles])
        radii = np.array([o.radius for o in obstacles])
        gaps = np.linalg.norm(pts[:, None, :] - centres[None, :, :], axis=2) - radii[None, :] - radius
        free = np.all(gaps >= options.clearance, axis=1)
        nearest_gap = gaps.min(axis=1)
        blocked_by = np.argmin(gaps - options.clearance, axis=1)
        counts: dict[str, int] = {}
        for i in np.flatnonzero(~free):
            name = obstacles[int(blocked_by[i])].name
            counts[name] = counts.get(name, 0) + 1
        blockers = tuple(sorted(counts, key=lambda k: (-counts[k], k)))
    else:
        free = np.ones(n, dtype=bool)
        nearest_gap = np.full(n, options.crowd_gap)
        blockers = ()
    pts, nearest_gap = pts[free], nearest_gap[free]
    if not len(pts):
        return PlacementSet((), blockers, n)

    diag = float(np.hypot(sx, sy))
    rel = pts - np.asarray(base_xy, dtype=float)
    reach = np.linalg.norm(rel, axis=1)
    tall = height >= options.tall_height
    preferred = options.tall_reach if tall else options.preferred_reach
    cost = options.reach_weight * np.abs(reach - preferred) / diag
    span = max(float(reach.max() - reach.min()), 1e-9)
    depth = (reach - reach.min()) / span  # 0 at the spot nearest the robot, 1 at the farthest
    cost += options.block_weight * ((1.0 - depth) if tall else 0.3 * depth)
    cost += options.crowd_weight * (1.0 - np.minimum(nearest_gap, options.crowd_gap) / options.crowd_gap)
    ray = rel / np.maximum(reach, 1e-9)[:, None]
    for o in obstacles:
        if o.height < options.tall_height:
            continue
        orel = np.array([o.x, o.y]) - np.asarray(base_xy, dtype=float)
        along = ray @ orel
        across = np.abs(ray[:, 0] * orel[1] - ray[:, 1] * orel[0])
        shadowed = (along > 0) & (along < reach) & (across < o.radius + radius + 0.05)
        cost += options.shadow_weight * shadowed
    order = np.lexsort((pts[:, 1], pts[:, 0], np.round(cost, 9)))[: options.max_spots]
    spots = tuple(
        PlacementSpot(float(pts[i, 0]), float(pts[i, 1]), table.top_z, float(cost[i]), float(nearest_gap[i]))
        for i in order
    )
    return PlacementSet(spots, blockers, n)
