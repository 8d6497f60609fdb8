"""``scone-bench physics``: the physics shortcuts against the full-rate simulation, on the same seeded executions.

Each query is one seeded pick-and-place of the motion benchmark (`benchmarks.motion`, same index, same scene): run
once with the kitchen's defaults (the robot file's physics step, resting objects frozen, a sleeping scene not
stepped) and
once at the reference rate (`world.kitchen.full_rate_physics`: FULL_RATE_STEP_S, nothing frozen). The report says
how many outcome classes (success, or the failure stage) agree, lists the queries that differ with both messages,
and gives the CPU seconds of each mode (physics and planning together) and their ratio.

    scone-bench physics --queries 60 --arms panda --jobs 2 --json physics.json
"""

from __future__ import annotations

import argparse
import time
from typing import Any

from scone_bt.checks import comma_list
from scone_bt.reporting import emit_report

__all__ = ["compare_query", "outcome_class", "register"]

_DEFAULTS = {"queries": 60, "arms": "panda,iiwa7", "clutter": 11, "table_objects": 2, "seed": 0}


def outcome_class(record: dict[str, Any]) -> str:
    """'success', or the failure stage with the planner's reason when planning failed ('planning: grasps_blocked')."""
    if record["success"]:
        return "success"
    stage = record["stage"] or "unknown"
    return f"{stage}: {record['reason']}" if record.get("reason") else stage


def compare_query(
    kitchen: str, arm: str, seed: int, clutter: int, table_objects: int, i: int
) -> dict[str, Any]:
    """One motion-benchmark query with the shortcuts and at the full rate: both classes, messages and CPU seconds."""
    from scone_bt.benchmarks.motion import _query
    from scone_bt.world.kitchen import full_rate_physics

    out: dict[str, Any] = {"i": i}
    for mode in ("shortcuts", "full_rate"):
        cpu = time.process_time()
        if mode == "full_rate":
            with full_rate_physics():
                record = _query(kitchen, arm, seed, clutter, table_objects, i)
        else:
            record = _query(kitchen, arm, seed, clutter, table_objects, i)
        out["target"] = record["target"]
        out[mode] = {
            "class": outcome_class(record),
            "message": record["message"],
            "sim_s": round(record["sim_s"], 3),
            "cpu_s": round(time.process_time() - cpu, 3),
        }
    out["agree"] = out["shortcuts"]["class"] == out["full_rate"]["class"]
    return out


def _arm_report(args: argparse.Namespace, arm: str) -> dict[str, Any]:
    slots_free = 1 + args.table_objects
    from scone_bt.config import load_kitchen, load_robot

    robot = load_robot(arm)  # an unknown robot is an error before any query runs
    kcfg = load_kitchen(args.kitchen)
    clutter = min(args.clutter, len(kcfg.scene.shelf_slots()) - slots_free)
    jobs = (args.kitchen, arm, args.seed, clutter, args.table_objects)
    if args.jobs > 1:
        import concurrent.futures as cf
        import multiprocessing as mp

        # Each query is seeded by its index: the records do not depend on how many processes ran them.
        with cf.ProcessPoolExecutor(args.jobs, mp_context=mp.get_context("spawn")) as pool:
            records = list(
                pool.map(compare_query, *zip(*[(*jobs, i) for i in range(args.queries)], strict=True))
            )
    else:
        records = [compare_query(*jobs, i) for i in range(args.queries)]
    cpu = {m: sum(r[m]["cpu_s"] for r in records) for m in ("shortcuts", "full_rate")}
    successes = {m: sum(r[m]["class"] == "success" for r in records) for m in ("shortcuts", "full_rate")}
    return {
        "physics_hz": robot.control.physics_hz,
        "queries": len(records),
        "agree": sum(r["agree"] for r in records),
        "agree_rate": round(sum(r["agree"] for r in records) / max(len(records), 1), 4),
        "success_rate": {m: round(n / max(len(records), 1), 4) for m, n in successes.items()},
        "cpu_s": {m: round(v, 1) for m, v in cpu.items()},
        "cpu_ratio_full_over_shortcuts": round(cpu["full_rate"] / cpu["shortcuts"], 3)
        if cpu["shortcuts"]
        else None,
        "differ": [
            {"i": r["i"], "target": r["target"], "shortcuts": r["shortcuts"], "full_rate": r["full_rate"]}
            for r in records
            if not r["agree"]
        ],
        "messages_differ": sum(
            r["agree"] and r["shortcuts"]["message"] != r["full_rate"]["message"] for r in records
        ),
    }


def run(args: argparse.Namespace) -> int:
    from scone_bt.errors import ConfigError
    from scone_bt.robot.flags import require_pybullet
    from scone_bt.world.kitchen import FULL_RATE_STEP_S

    require_pybullet(args.robot, "scone-bench physics")
    if args.queries < 1 or args.jobs < 1 or args.clutter < 0 or args.table_objects < 0:
        raise ConfigError("--queries and --jobs must be >= 1, --clutter and --table-objects >= 0")
    arms = comma_list(args.arms, "--arms", "panda,iiwa7")
    started = time.perf_counter()
    report: dict[str, Any] = {
        "benchmark": "physics",
        "full_rate_step_s": FULL_RATE_STEP_S,
        "queries_per_arm": args.queries,
        "seed": args.seed,
        "clutter": args.clutter,
        "table_objects": args.table_objects,
        "jobs": args.jobs,
        "arms": {arm: _arm_report(args, arm) for arm in arms},
    }
    report["wall_s"] = round(time.perf_counter() - started, 1)
    report["note"] = (
        "each query runs twice, with the physics shortcuts (the kitchen's defaults) and at the full rate "
        "(full_rate_step_s, nothing frozen); 'class' is success or the failure stage"
    )
    emit_report(report, args.json, force=args.force)
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``physics`` to ``scone-bench``."""
    from scone_bt.robot.flags import add_backend_option

    p = sub.add_parser(
        "physics", help="physics shortcuts against the full-rate simulation, same executions (JSON)"
    )
    p.add_argument("--queries", type=int, default=_DEFAULTS["queries"], help="queries per arm (default 60)")
    p.add_argument(
        "--arms", default=_DEFAULTS["arms"], help="comma-separated robot files (default panda,iiwa7)"
    )
    p.add_argument("--clutter", type=int, default=_DEFAULTS["clutter"], help="other products on the shelving")
    p.add_argument(
        "--table-objects", type=int, default=_DEFAULTS["table_objects"], help="products on the table"
    )
    p.add_argument("--kitchen", default="kitchen", help="kitchen file (default perception/kitchen.yaml)")
    add_backend_option(p, arm_flag="--arms")
    p.add_argument("--seed", type=int, default=_DEFAULTS["seed"])
    p.add_argument(
        "--jobs", type=int, default=1, help="processes running the queries (the report is the same)"
    )
    p.add_argument("--json", help="also write the JSON report to this file")
    p.add_argument(
        "--force",
        action="store_true",
        help="let --json replace an existing file that is not a benchmark report (never a YAML file)",
    )
    p.set_defaults(func=run)
