"""Check that a refactor of the motion code keeps the seeded plans: record in two checkouts, then diff.

``record`` runs motion-benchmark queries (`scone_bt.benchmarks.motion._query`: the same scenes, seeds and physics as
``scone-bench motion``) and keeps, per query, its record without timing and a digest of its plan: the grasp, the
place spot, every OMPL result's status, message and path, every segment's waypoints and trajectory, or why no plan
exists. It also keeps digests of the sampling functions over seeded random inputs (`grasp_candidates`,
`sample_placements`, `plan_joint_path` with OMPL). Nothing timed is kept, so two runs of the same code write the
same file. ``diff`` compares two files and names what differs.

    PYTHONPATH=/tmp/before .venv/bin/python tools/motion_replay.py record runs/before.json
    PYTHONPATH=$PWD .venv/bin/python tools/motion_replay.py record runs/after.json
    .venv/bin/python tools/motion_replay.py diff runs/before.json runs/after.json
"""

from __future__ import annotations

import argparse
import hashlib
import json
import sys
from typing import Any

import numpy as np

TIMING = {"plan_ms", "plan_cpu_ms", "ruckig_ms", "ompl_ms"}
"""Record keys that are wall or CPU times (they differ from run to run)."""


def _h(*arrays: Any) -> str:
    """A short digest of the arrays' float64 bytes (None counts as its own value)."""
    d = hashlib.sha256()
    for a in arrays:
        d.update(b"None" if a is None else np.ascontiguousarray(np.asarray(a, dtype=float)).tobytes())
    return d.hexdigest()[:16]


def _results(plans: Any) -> list[list[Any]]:
    return [[r.status.value, r.message, r.goal_index, _h(r.path)] for r in plans]


def _plan_digest(plan: Any) -> dict[str, Any] | None:
    """What a plan decided (or why none exists), without its timing."""
    from scone_bt.motion import PickPlacePlan

    if plan is None:
        return None
    if not isinstance(plan, PickPlacePlan):
        return {
            "stage": plan.stage.value,
            "reason": plan.reason.value,
            "message": plan.message,
            "blockers": list(plan.blockers),
            "collision_checks": plan.collision_checks,
            "plans": _results(plan.plans),
        }
    g = plan.grasp
    return {
        "grasp": [g.family.value, g.closing_yaw, g.tilt, g.cost, g.span, _h(g.point, g.rotation)],
        "place_spot": plan.place_spot,
        "plans": _results(plan.plans),
        "segments": [
            [
                s.phase.value,
                _h(s.waypoints),
                _h(
                    s.trajectory.times,
                    s.trajectory.positions,
                    s.trajectory.velocities,
                    s.trajectory.accelerations,
                ),
            ]
            for s in plan.segments
        ],
        "collision_checks": plan.collision_checks,
        "grasps_tried": plan.grasps_tried,
        "goal_set_sizes": list(plan.goal_set_sizes),
        "finger_position": plan.finger_position,
    }


def _queries(arms: list[tuple[str, int]], seed: int, clutter: int, table_objects: int) -> dict[str, Any]:
    """Per arm, each query's record (timing left out) with its plan's digest."""
    import scone_bt.motion as motion
    from scone_bt.benchmarks import motion as bench

    tasks: list[Any] = []

    class Recording(motion.MotionSystem):
        """The motion system, keeping each pick-and-place task it starts."""

        def pick_and_place(self, *args: Any, **kwargs: Any) -> Any:
            tasks.append(super().pick_and_place(*args, **kwargs))
            return tasks[-1]

    original = motion.MotionSystem
    motion.MotionSystem = Recording  # _query imports it from scone_bt.motion when it runs
    out: dict[str, Any] = {}
    try:
        for arm, n in arms:
            rows = []
            for i in range(n):
                tasks.clear()
                rec = bench._query("kitchen", arm, seed, clutter, table_objects, i)
                rec = {k: v for k, v in rec.items() if k not in TIMING}
                rec["plan_digest"] = _plan_digest(tasks[0].plan) if tasks else "no task"
                rows.append(rec)
                what = "ok" if rec["success"] else f"{rec['stage'] or ''} {rec['reason'] or ''}".strip()
                print(f"[{arm} {i}] {rec['target']}: {what}", file=sys.stderr, flush=True)
            out[arm] = rows
    finally:
        motion.MotionSystem = original
    return out


def _functions(n: int) -> dict[str, Any]:
    """Digests of the sampling functions over `n` seeded random inputs each (planner: n // 5)."""
    from dataclasses import replace

    from scone_bt.config import load_kitchen, load_robot
    from scone_bt.config.grasp import GraspParams
    from scone_bt.motion.grasp import grasp_candidates
    from scone_bt.motion.placement import Footprint, PlacementOptions, TableRegion, sample_placements
    from scone_bt.motion.planner import PlannerOptions, plan_joint_path
    from scone_bt.perception.types import Detection

    rng = np.random.default_rng(1234)
    kitchen = load_kitchen("kitchen")
    objs = list(kitchen.catalogue.objects)
    grasps = []
    for arm in ("panda", "iiwa7"):
        base = GraspParams.of(load_robot(arm))
        variants = [base, replace(base, side_grasps=False), replace(base, shallow_depth=0.0)]
        for k in range(n):
            spec = objs[int(rng.integers(len(objs)))]
            pos = (float(rng.uniform(-0.8, 0.8)), float(rng.uniform(-0.8, 0.8)), float(rng.uniform(0.0, 1.2)))
            det = Detection(spec.name, 0, pos, float(rng.uniform(-np.pi, np.pi)), 1.0, (0, 0, 1, 1))
            opening = [None, 0.08, 0.05, 0.02][k % 4]
            cands = grasp_candidates(det, spec, variants[k % 3], float(rng.uniform(-np.pi, np.pi)), opening)
            grasps.append(
                [
                    [c.family.value, c.closing_yaw, c.tilt, c.cost, c.span, _h(c.grasp, c.pregrasp)]
                    for c in cands
                ]
            )
    table = TableRegion.from_scene(kitchen.scene)
    (cx, cy), (sx, sy) = table.center, table.size
    spots = []
    for k in range(n):
        obstacles = [
            Footprint.of(
                objs[int(rng.integers(len(objs)))],
                cx + rng.uniform(-sx / 2, sx / 2),
                cy + rng.uniform(-sy / 2, sy / 2),
                float(rng.uniform(-np.pi, np.pi)),
            )
            for _ in range(int(rng.integers(0, 9)))
        ]
        spec = objs[int(rng.integers(len(objs)))]
        options = PlacementOptions(rng_seed=int(rng.integers(1000)), max_spots=[24, 5, 200][k % 3])
        found = sample_placements(
            table, obstacles, Footprint.of(spec), spec.size[2], options, (0.0, 0.0), float(rng.uniform(-3, 3))
        )
        spots.append(
            [list(found.blockers), found.candidates, [[s.x, s.y, s.cost, list(s.yaws)] for s in found.spots]]
        )
    paths = []
    for k in range(max(1, n // 5)):
        centres, radii = rng.uniform(-2.5, 2.5, size=(10, 3)), rng.uniform(0.5, 1.3, size=10)

        def valid(q: np.ndarray, c: np.ndarray = centres, r: np.ndarray = radii) -> bool:
            return bool(np.all(np.linalg.norm(c - q, axis=1) > r))

        start, goals = rng.uniform(-3, 3, size=3), rng.uniform(-3, 3, size=(1 + k % 3, 3))
        options = PlannerOptions(
            time_limit_s=[0.5, 0.0005, 1.0, 0.004][k % 4],
            simplify=bool(k % 2),
            rng_seed=k,
            try_direct=k % 4 == 0,
        )
        r = plan_joint_path(start, goals, -np.pi * np.ones(3), np.pi * np.ones(3), valid, options)
        paths.append([r.status.value, r.message, r.goal_index, _h(r.path)])
    return {"grasp_candidates": grasps, "sample_placements": spots, "plan_joint_path": paths}


def _diff(a: dict[str, Any], b: dict[str, Any]) -> tuple[list[str], int]:
    """One line per query or function input whose digest differs (the first ten per part), a summary line per
    part, and how many differ in all."""
    lines, total = [], 0
    for part in ("queries", "functions"):
        for key in sorted(set(a[part]) | set(b[part])):
            rows_a, rows_b = a[part].get(key, []), b[part].get(key, [])
            differ = [
                i for i in range(max(len(rows_a), len(rows_b))) if rows_a[i : i + 1] != rows_b[i : i + 1]
            ]
            lines.extend(f"  {part} {key} #{i} differs" for i in differ[:10])
            lines.append(f"{part} {key}: {len(rows_a)} vs {len(rows_b)} rows, {len(differ)} differ")
            total += len(differ)
    return lines, total


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    rec = sub.add_parser("record", help="record the queries' outcomes and the functions' digests")
    rec.add_argument("out", help="JSON file to write")
    rec.add_argument("--arms", default="panda:20,iiwa7:20", help="arm:queries, comma-separated")
    rec.add_argument("--seed", type=int, default=0)
    rec.add_argument("--clutter", type=int, default=11)
    rec.add_argument("--table-objects", type=int, default=2)
    rec.add_argument("--inputs", type=int, default=300, help="random inputs per sampling function")
    diff = sub.add_parser("diff", help="compare two recordings")
    diff.add_argument("a")
    diff.add_argument("b")
    args = parser.parse_args(argv)
    if args.command == "diff":
        with open(args.a, encoding="utf-8") as fa, open(args.b, encoding="utf-8") as fb:
            lines, total = _diff(json.load(fa), json.load(fb))
        print("\n".join(lines))
        print("identical" if total == 0 else f"{total} differ")
        return 1 if total else 0
    arms = [(name, int(n)) for name, n in (a.split(":") for a in args.arms.split(",") if a)]
    report = {
        "queries": _queries(arms, args.seed, args.clutter, args.table_objects),
        "functions": _functions(args.inputs),
    }
    with open(args.out, "w", encoding="utf-8") as f:
        json.dump(report, f, indent=1, sort_keys=True, default=str)
    return 0


if __name__ == "__main__":
    sys.exit(main())
