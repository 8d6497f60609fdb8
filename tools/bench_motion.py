"""Benchmark of the motion stage: seeded shelf-to-table pick-and-place queries over the catalogue. Prints JSON.

    .venv/bin/python tools/bench_motion.py                 # 100 queries with the Panda (a few minutes)
    .venv/bin/python tools/bench_motion.py --queries 10    # for development
    .venv/bin/python tools/bench_motion.py --robot iiwa7

Query i: a fresh kitchen with the catalogue's object i (mod 25) and 4 other random objects on random shelf slots
(seed i); the target goes to the first free table spot. Detections are the objects' true top-face poses: this
measures motion, not perception. Reported:
- planning: success rate of whole pick-and-place plans whose grasp and place poses are reachable and collision-free
  (goals where IK finds no pose, or every pose collides with the clutter, are counted apart), and of the OMPL queries
  themselves; time per OMPL query (p50/p95) and per whole plan (IK + 3 OMPL queries + timing);
- collision checks per second (random configurations in the kitchen scene, and during planning);
- ruckig solver time per trajectory segment, in the worker while physics runs, and alone on the main thread;
- physical success rate with the failure breakdown by stage; simulated, wall and CPU time per pick-and-place
  (planning included; wall time depends on what else runs on the machine, see load_average_1min).
Targets (2-core machine): planning success >= 98% on reachable goals, planning p50 <= 100 ms, ruckig <= 1 ms.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import time
from collections import Counter

import numpy as np

from scone_bt.config import load_kitchen, load_robot
from scone_bt.motion import (
    ArmModel,
    CollisionWorld,
    ExecutionSettings,
    FailureStage,
    GraspParams,
    MotionSystem,
    PickPlacePlan,
    PlannerOptions,
    limits_of,
    time_path,
)
from scone_bt.perception.types import Detection
from scone_bt.world import Kitchen


def _pct(values: list[float], q: float) -> float | None:
    return round(float(np.percentile(values, q)), 3) if values else None


def _detect(kitchen: Kitchen, name: str) -> Detection:
    st = kitchen.object_state(name)
    yaw = kitchen.bc.getEulerFromQuaternion(st.orientation)[2]
    x, y, z = st.position
    return Detection(name, 0, (x, y, z + kitchen.specs[name].height / 2), yaw, 1.0, (0, 0, 1, 1))


def _checks_per_second(arm: ArmModel, system: MotionSystem, n: int) -> float:
    world = CollisionWorld(arm, system.static)
    rng = np.random.default_rng(0)
    qs = [rng.uniform(arm.lower, arm.upper) for _ in range(n)]
    t = time.perf_counter()
    for q in qs:
        world.is_valid(q)
    return n / (time.perf_counter() - t)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--queries", type=int, default=100)
    ap.add_argument("--robot", default="panda")
    ap.add_argument("--distractors", type=int, default=4)
    args = ap.parse_args()

    kcfg = load_kitchen()
    rcfg = load_robot(args.robot)
    catalogue = kcfg.catalogue.objects
    t0 = time.perf_counter()
    arm = ArmModel(rcfg)
    model_load_s = time.perf_counter() - t0
    p = rcfg.planner
    options = PlannerOptions(
        name=p.name, time_limit_s=p.time_limit_s, simplify=p.simplify, rng_seed=p.rng_seed
    )

    plan_ok = plan_reachable = plan_valid = 0
    blocked: Counter[str] = Counter()
    by_object: Counter[str] = Counter()
    ompl_times, ompl_ok, ompl_total = [], 0, 0
    plan_walls, ruckig_ms, checks, check_time = [], [], 0, 0.0
    stages: Counter[str] = Counter()
    plan_failures: Counter[str] = Counter()
    sim_s, wall_s, cpu_s = [], [], []
    offline_ruckig_ms: list[float] = []
    limits = limits_of(rcfg)
    successes = 0
    for i in range(args.queries):
        rng = np.random.default_rng(i)
        target = catalogue[i % len(catalogue)]
        others = [o for o in catalogue if o.name != target.name]
        picks = rng.choice(len(others), size=args.distractors, replace=False)
        specs = [target, *(others[int(j)] for j in picks)]
        with Kitchen(kcfg, rcfg) as kitchen:
            kitchen.spawn(specs, rng)
            system = MotionSystem(kitchen, arm, options, limits_of(rcfg), GraspParams(), ExecutionSettings())
            obstacles = [(_detect(kitchen, s.name), s) for s in specs[1:]]
            task = system.pick_and_place(_detect(kitchen, target.name), target, obstacles, rng_seed=i)
            start_sim, start_wall, start_cpu = kitchen.sim_time, time.perf_counter(), time.process_time()
            task.start()
            while not task.done():
                kitchen.advance(0.1)
            outcome = task.outcome()
            wall_s.append(time.perf_counter() - start_wall)
            cpu_s.append(time.process_time() - start_cpu)
            sim_s.append(kitchen.sim_time - start_sim)
            system.close()
        plan = task.plan
        if plan is not None:
            for r in plan.plans:
                ompl_total += 1
                ompl_ok += r.success
                ompl_times.append(r.planning_time * 1000)
            if isinstance(plan, PickPlacePlan):
                plan_ok += 1
                plan_reachable += 1
                plan_valid += 1
                plan_walls.append(plan.planning_wall_s * 1000)
                ruckig_ms.extend(t * 1000 for t in plan.ruckig_times)
                for seg in plan.segments:  # again on the main thread, with no physics thread competing
                    _, rep = time_path(seg.waypoints, limits.scaled(1.0), rcfg.control.rate_hz)
                    offline_ruckig_ms.append(rep.calculation_s * 1000)
                checks += plan.collision_checks
                check_time += plan.collision_time
            elif plan.stage is not FailureStage.IK:
                plan_reachable += 1
                # Grasp or place poses that all collide (clutter) are invalid goals; anything else is the planner's.
                if "no feasible grasp" in plan.message or "no way to place" in plan.message:
                    blocked[plan.message.split(":")[0]] += 1
                else:
                    plan_valid += 1
                    plan_failures[plan.message] += 1
        successes += outcome.success
        stages["success" if outcome.success else outcome.stage.value] += 1
        if not outcome.success:
            by_object[f"{outcome.stage.value}: {target.name}"] += 1

    n = args.queries
    report = {
        "benchmark": "motion",
        "robot": rcfg.name,
        "planner": options.name,
        "queries": n,
        "machine": {"python": platform.python_version(), "processor": platform.machine()},
        "model_load_s": round(model_load_s, 3),
        "planning": {
            "kinematically_reachable": plan_reachable,
            "blocked_by_clutter": dict(blocked),
            "reachable_collision_free_goals": plan_valid,
            "plan_success_rate_on_reachable": round(plan_ok / plan_valid, 4) if plan_valid else None,
            "plan_failures_on_reachable": dict(plan_failures),
            "ompl_queries": ompl_total,
            "ompl_success_rate": round(ompl_ok / ompl_total, 4) if ompl_total else None,
            "ompl_query_ms_p50": _pct(ompl_times, 50),
            "ompl_query_ms_p95": _pct(ompl_times, 95),
            "pick_place_plan_ms_p50": _pct(plan_walls, 50),
            "pick_place_plan_ms_p95": _pct(plan_walls, 95),
        },
        "collision_checks_per_s": {
            "random_configurations": round(_checks_per_second(arm, system, 5000)),
            "during_planning": round(checks / check_time) if check_time else None,
        },
        "ruckig_ms_per_trajectory": {
            "p50": _pct(ruckig_ms, 50),
            "p95": _pct(ruckig_ms, 95),
            "max": round(max(ruckig_ms), 3) if ruckig_ms else None,
            "segments": len(ruckig_ms),
            "alone_p50": _pct(offline_ruckig_ms, 50),
            "alone_p95": _pct(offline_ruckig_ms, 95),
        },
        "physical": {
            "success_rate": round(successes / n, 4),
            "outcomes": dict(sorted(stages.items())),
            "failures_by_object": dict(sorted(by_object.items())),
            "sim_s_p50": _pct(sim_s, 50),
            "sim_s_p95": _pct(sim_s, 95),
            "wall_s_p50": _pct(wall_s, 50),
            "wall_s_p95": _pct(wall_s, 95),
            "cpu_s_p50": _pct(cpu_s, 50),
            "cpu_s_p95": _pct(cpu_s, 95),
        },
        "load_average_1min": round(os.getloadavg()[0], 2),
    }
    print(json.dumps(report, indent=2))


if __name__ == "__main__":
    main()
