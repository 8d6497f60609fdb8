"""Placement sampling on the observed free area of the table (pure, no simulator)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from scone_bt.config import ObjectSpec
from scone_bt.motion import Footprint, PlacementOptions, TableRegion, sample_placements
from scone_bt.motion.placement import footprint_radius

TABLE = TableRegion((0.47, -0.43), (0.44, 0.40), 0.0)
OLD_SPOTS = [(x, y) for x in (0.37, 0.49, 0.61) for y in (-0.30, -0.42, -0.54)]


def _inside(spot, radius, margin):
    (cx, cy), (sx, sy) = TABLE.center, TABLE.size
    return (
        abs(spot.x - cx) <= sx / 2 - radius - margin + 1e-9
        and abs(spot.y - cy) <= sy / 2 - radius - margin + 1e-9
    )


def test_spots_clear_every_obstacle_and_stay_on_the_table():
    obstacles = [Footprint(f"o{i}", x, y, 0.035, 0.1) for i, (x, y) in enumerate(OLD_SPOTS[:5])]
    opts = PlacementOptions()
    result = sample_placements(TABLE, obstacles, 0.03, 0.1, opts)
    assert len(result.spots) == opts.max_spots
    for s in result.spots:
        assert _inside(s, 0.03, opts.edge_margin + opts.edge_margin_per_height * 0.1) and s.z == TABLE.top_z
        for o in obstacles:
            assert np.hypot(s.x - o.x, s.y - o.y) - o.radius - 0.03 >= opts.clearance - 1e-9
    costs = [s.cost for s in result.spots]
    assert costs == sorted(costs)


def test_a_crowded_table_still_has_room_at_its_rim():
    # Every one of the nine marked spots of the old fixed scheme is taken; a short product (3 cm: a 1.3 cm edge
    # margin) still fits between them and the rim (a 10 cm one, kept 2 cm from the edge, would not).
    obstacles = [Footprint(f"o{i}", x, y, 0.035, 0.12) for i, (x, y) in enumerate(OLD_SPOTS)]
    result = sample_placements(TABLE, obstacles, 0.025, 0.03)
    assert not sample_placements(TABLE, obstacles, 0.025, 0.1).spots
    assert result.spots
    assert all(min(np.hypot(s.x - x, s.y - y) for x, y in OLD_SPOTS) > 0.035 + 0.025 for s in result.spots)


def test_a_full_table_returns_no_spot_and_names_what_fills_it():
    blocker = Footprint("tray", 0.47, -0.43, 0.35, 0.03)
    result = sample_placements(TABLE, [blocker], 0.03, 0.1)
    assert result.spots == () and result.blockers == ("tray",) and result.candidates > 0


def test_tall_objects_go_to_the_far_rim_short_ones_near_the_robot():
    short = sample_placements(TABLE, [], 0.03, 0.05).spots[0]
    tall = sample_placements(TABLE, [], 0.03, 0.22).spots[0]
    assert np.hypot(tall.x, tall.y) > np.hypot(short.x, short.y) + 0.05


def test_spots_behind_a_tall_object_cost_more():
    # A tall bottle between the robot and a spot shadows it; the same bottle short does not.
    spot = (0.56, -0.52)
    d = np.hypot(*spot)
    bottle_xy = (spot[0] * 0.4 / d, spot[1] * 0.4 / d)  # on the line from the base, nearer the robot
    wide = PlacementOptions(random_samples=0, max_spots=1000)
    tall = sample_placements(TABLE, [Footprint("b", *bottle_xy, 0.03, 0.25)], 0.03, 0.1, wide)
    low = sample_placements(TABLE, [Footprint("b", *bottle_xy, 0.03, 0.05)], 0.03, 0.1, wide)

    def at(res):
        return min(res.spots, key=lambda s: np.hypot(s.x - spot[0], s.y - spot[1]))

    assert at(tall).cost > at(low).cost + 0.4


def test_sampling_is_seeded():
    obstacles = [Footprint("a", 0.4, -0.35, 0.04, 0.2)]
    a = sample_placements(TABLE, obstacles, 0.03, 0.1, PlacementOptions(rng_seed=3))
    b = sample_placements(TABLE, obstacles, 0.03, 0.1, PlacementOptions(rng_seed=3))
    c = sample_placements(TABLE, obstacles, 0.03, 0.1, PlacementOptions(rng_seed=4))
    assert a == b and a != c


# ------------------------------------------------------------------------------------- footprint geometry
def _rect(name, x, y, sx, sy, yaw=0.0, height=0.1):
    half = (sx / 2, sy / 2)
    return Footprint(name, x, y, float(np.hypot(*half)), height, half, yaw)


def test_rectangle_gaps_are_exact_face_to_face_and_never_optimistic():
    from scone_bt.motion.placement import footprint_gaps

    carton = _rect("carton", 0.0, 0.0, 0.10, 0.06)
    other = _rect("other", 0.0, 0.0, 0.08, 0.04)
    # Side by side along x: the gap is the distance between the facing edges.
    g = footprint_gaps(np.array([[0.0, 0.0]]), np.array([0.0]), carton, [replace(other, x=0.12)])
    assert g[0, 0] == pytest.approx(0.12 - 0.05 - 0.04)
    # Turned a quarter turn, the carton's short side faces the other one.
    g = footprint_gaps(np.array([[0.0, 0.0]]), np.array([np.pi / 2]), carton, [replace(other, x=0.12)])
    assert g[0, 0] == pytest.approx(0.12 - 0.03 - 0.04)
    # Overlapping rectangles have a negative gap.
    assert footprint_gaps(np.array([[0.0, 0.0]]), np.array([0.0]), carton, [replace(other, x=0.05)])[0, 0] < 0
    # Corner to corner at random yaws, the reported gap never exceeds the true distance between the outlines.
    rng = np.random.default_rng(0)

    def outline(f, yaw, n=80):
        t = np.linspace(-1, 1, n)
        hx, hy = f.half_size
        local = np.vstack(
            [np.column_stack([t * hx, np.full(n, s * hy)]) for s in (-1, 1)]
            + [np.column_stack([np.full(n, s * hx), t * hy]) for s in (-1, 1)]
        )
        c, s = np.cos(yaw), np.sin(yaw)
        return local @ np.array([[c, s], [-s, c]])

    for _ in range(30):
        yaw_a, yaw_b = rng.uniform(-np.pi, np.pi, 2)
        pos = rng.uniform(-0.15, 0.15, 2)
        ob = replace(other, x=float(pos[0]), y=float(pos[1]), yaw=float(yaw_b))
        gap = footprint_gaps(np.zeros((1, 2)), np.array([yaw_a]), carton, [ob])[0, 0]
        a, b = outline(carton, yaw_a), outline(ob, yaw_b) + pos
        true = np.min(np.linalg.norm(a[:, None] - b[None], axis=2))
        if gap > 0:
            assert gap <= true + 1e-3


def test_circle_against_rectangle_is_exact():
    from scone_bt.motion.placement import footprint_gaps

    jar = Footprint("jar", 0.0, 0.0, 0.03, 0.1)
    carton = _rect("carton", 0.10, 0.0, 0.08, 0.04, yaw=np.pi / 2)  # its long side along y
    g = footprint_gaps(np.zeros((1, 2)), np.zeros(1), jar, [carton])
    assert g[0, 0] == pytest.approx(0.10 - 0.02 - 0.03)
    # And the other way round: the carton placed next to a jar.
    g = footprint_gaps(np.array([[0.10, 0.0]]), np.array([np.pi / 2]), carton, [jar])
    assert g[0, 0] == pytest.approx(0.10 - 0.02 - 0.03)


def test_clear_spots_keeps_the_footprint_on_the_table_and_names_the_blocker():
    from scone_bt.motion.placement import clear_spots

    carton = _rect("carton", 0, 0, 0.20, 0.06)
    (cx, cy), (sx, _) = TABLE.center, TABLE.size
    near_edge = np.array([[cx + sx / 2 - 0.05, cy]])
    # Lengthwise towards the edge it hangs over it; turned a quarter turn it fits.
    assert not clear_spots(TABLE, [], carton, near_edge, 0.0).free[0]
    assert clear_spots(TABLE, [], carton, near_edge, np.pi / 2).free[0]
    jar = Footprint("jar", cx, cy, 0.03, 0.1)
    res = clear_spots(TABLE, [jar], carton, np.array([[cx, cy + 0.05], [cx, cy + 0.14]]), 0.0, clearance=0.01)
    assert list(res.free) == [False, True] and list(res.blocker) == [0, -1]


def test_box_footprints_pack_a_table_that_circles_call_full():
    # Eight cartons in two rows along the table's far part, square to its edges, 2.5 cm apart.
    cartons = [
        _rect(f"c{i}", 0.29 + 0.105 * (i % 4), -0.32 - 0.12 * (i // 4), 0.08, 0.095, height=0.2)
        for i in range(8)
    ]
    spec = ObjectSpec("flour", (), "box", (0.11, 0.075, 0.18), 0.5, 0.7, "paper", (1, 1, 1, 1), 0)
    boxes = sample_placements(TABLE, cartons, Footprint.of(spec), spec.height)
    as_circles = [Footprint(c.name, c.x, c.y, c.radius, c.height) for c in cartons]
    circles = sample_placements(TABLE, as_circles, footprint_radius(spec), spec.height)
    assert circles.spots == () and len(boxes.spots) >= 10  # bounding circles call this table full
    from scone_bt.motion.placement import clear_spots

    for s in boxes.spots:
        assert s.yaws  # a box spot says at which yaws it fits
        for yaw in s.yaws:
            res = clear_spots(TABLE, cartons, Footprint.of(spec), np.array([[s.x, s.y]]), yaw, 0.02, 0.01)
            assert res.free[0]


def test_the_random_candidates_are_the_generators_uniform_draws():
    """`sample_placements` scales the generator's standard draws: the same floats as `Generator.uniform` with the
    seed, for any bounds (so spots, and plans, are those `uniform` gave)."""
    for seed in (0, 3, 12345):
        for x0, y0, x1, y1 in (
            (0.1, -0.3, 0.7, 0.4),
            (-1.234567, 0.5, 2.3456, 0.9),
            (0.3, 0.3, 0.30001, 0.5),
        ):
            low, high = np.array([x0, y0]), np.array([x1, y1])
            expected = np.random.default_rng(seed).uniform((x0, y0), (x1, y1), size=(48, 2))
            draws = np.random.default_rng(seed).random(size=(48, 2))
            assert np.array_equal(low + (high - low) * draws, expected)


def test_a_tall_product_is_kept_farther_from_the_edge_than_a_flat_one():
    """A bottle set down a little off upright tips over an edge a pack stays on: 1 cm + 0.1 × height."""
    opts = PlacementOptions(random_samples=0, max_spots=1000)

    def nearest_edge(height: float) -> float:
        spots = sample_placements(TABLE, [], 0.03, height, opts).spots
        (cx, cy), (sx, sy) = TABLE.center, TABLE.size
        return min(min(sx / 2 - abs(s.x - cx), sy / 2 - abs(s.y - cy)) - 0.03 for s in spots)

    flat, tall = nearest_edge(0.04), nearest_edge(0.25)
    assert flat >= 0.01 + 0.1 * 0.04 - 1e-9 and tall >= 0.01 + 0.1 * 0.25 - 1e-9
    assert tall - flat > 0.015  # the grid still reaches as near as each margin allows, within a grid step
