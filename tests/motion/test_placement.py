"""Placement sampling on the observed free area of the table (pure, no simulator)."""

from __future__ import annotations

import numpy as np

from scone_bt.motion import Footprint, PlacementOptions, TableRegion, sample_placements

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
        assert _inside(s, 0.03, opts.edge_margin) and s.z == TABLE.top_z
        for o in obstacles:
            assert np.hypot(s.x - o.x, s.y - o.y) - o.radius - 0.03 >= opts.clearance - 1e-9
    costs = [s.cost for s in result.spots]
    assert costs == sorted(costs)


def test_a_crowded_table_still_has_room_at_its_rim():
    # Every one of the nine marked spots of the old fixed scheme is taken.
    obstacles = [Footprint(f"o{i}", x, y, 0.035, 0.12) for i, (x, y) in enumerate(OLD_SPOTS)]
    result = sample_placements(TABLE, obstacles, 0.025, 0.1)
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
