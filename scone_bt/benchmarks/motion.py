"""``scone-bench motion``: seeded shelf-to-table pick-and-place queries over the catalogue, for each arm (JSON).

Query i (per arm): a fresh kitchen whose shelving holds the target and `--clutter` other products (12 objects in
all by default, as an episode stocks it: the recipe's ingredients and six distractors), on random slots (seed
[seed, i]); `--table-objects` more products have been carried to the table by the simulated human. Targets run
through a seeded permutation of whatever `KitchenConfig.catalogue` holds. Detections are the objects' true
top-face poses, on the shelf and on the table (a perfect table camera): this measures motion, not perception.
Each query is planned and then executed in the physics.

Reported per arm under ``arms.<name>``:
- ``blocked_by_clutter_rate``: queries whose every grasp collides with the clutter (typed reason
  grasps_blocked), among queries whose object fits the gripper (narrowest side <= opening - margin);
- ``physical_success_rate_graspable``: the object stands upright on the table, among queries whose object fits
  the gripper and the payload (the fingers' friction, 2 F mu_finger mu_object, holds twice its weight: PyBullet
  multiplies the two friction coefficients);
- ``plan_success_rate_on_reachable``: whole plans found, among queries where a feasible grasp and placement
  exist (success, or the typed reason no_path);
- ``pick_place_plan_ms_p50/p95`` (wall) and ``pick_place_plan_cpu_ms_p50/p95`` (CPU time of the planning
  thread: wall time on a loaded machine includes waiting for a core), ``ruckig_ms_p50`` per trajectory segment;
- ``failures_by_reason``: typed planning reasons and physical failure stages; the chosen grasp families;
- ``blocked_by_scene_only``: of the blocked graspable queries, those whose blockers are all shelving structure
  (no product among them), and ``targets_off_shelf``: targets that were not standing on a shelf when the query
  began (fell while the shelving settled). Both are counted in the rates above as they are; they say why.

With ``--planner ompl,vamp`` (Panda only: VAMP, built by ``make vamp``, has no model of the other arms) every
joint-space query the pick-and-place hands to OMPL (approach, transit with the object, return home; each a start
and a goal set, in the collision world OMPL checked) is recorded and, once the query has run, solved again by OMPL
and by VAMP one after the other in the benchmark's thread, with the query's seed. Reported under
``arms.<name>.planners``: per OMPL query ``ompl_ms``, ``vamp_ms`` (VAMP's start/goal checks, search and
simplification; building its environment is ``vamp_env_ms``), ``ratio`` (ompl/vamp), ``vamp_mesh_valid`` (the VAMP
path re-checked with the mesh checker at OMPL's motion-validation step), and a summary. Without the flag the report
is what it was.

With ``--probe`` every query hefts its target before carrying it (scone_bt/motion/probe.py, the default settings):
``probe_aborted`` counts the targets set back (neither a success nor a failure). The same seeded queries with and
without it tell whether the probe ever turns a success into a failure.

    scone-bench motion --queries 20                     # development
    scone-bench motion --json runs/motion.json          # 200 queries x both arms (long on 2 cores)
    scone-bench motion --jobs 2 --json runs/motion.json # the same report, queries spread over 2 processes
    scone-bench motion --arms panda --queries 30 --planner ompl,vamp --json docs/results/motion_vamp.json
"""

from __future__ import annotations

import argparse
import contextlib
import os
import platform
import threading
import time
from collections import Counter
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any, cast

from scone_bt.checks import comma_list
from scone_bt.reporting import emit_report

__all__ = ["register", "run", "TARGETS"]

TARGETS = {
    "blocked_by_clutter_rate": ("<=", 0.02),
    "physical_success_rate_graspable": (">=", 0.97),
    "plan_success_rate_on_reachable": (">=", 1.0),
    "pick_place_plan_ms_p50": ("<=", 10.0),
    "pick_place_plan_ms_p95": ("<=", 40.0),
    "ruckig_ms_p50": ("<=", 1.0),
}
"""What each arm's report is checked against (``targets_met``): the motion issue's rates, and issue 29's plan times
(p50 10 ms, p95 40 ms; the motion issue asked for 50 and 150 ms)."""
G = 9.81
PLANNERS = ("ompl", "vamp")
"""What ``--planner`` may list: ompl (always) and vamp (the same OMPL queries solved again by both)."""
PAYLOAD_SAFETY = 2.0
"""A grip holds the payload when the fingers' friction is at least twice its weight (the usual sizing rule for
friction grippers: lifting accelerates the object and a few contact points are not a full pad)."""


def _pct(values: list[float], q: float) -> float | None:
    import numpy as np

    return round(float(np.percentile(values, q)), 3) if values else None


def _rate(num: int, den: int) -> float | None:
    return round(num / den, 4) if den else None


def _detect(kitchen: Any, name: str) -> Any:
    from scone_bt.perception.types import Detection

    st = kitchen.object_state(name)
    yaw = kitchen.bc.getEulerFromQuaternion(st.orientation)[2]
    x, y, z = st.position
    return Detection(name, 0, (x, y, z + kitchen.specs[name].height / 2), yaw, 1.0, (0, 0, 1, 1))


_WORKER: dict[str, Any] = {}
"""Per-process cache of the loaded kitchen file, robot files and arm models (queries reuse them)."""


def _setup(kitchen: str, arm_name: str) -> dict[str, Any]:
    from scone_bt.config import load_kitchen, load_robot
    from scone_bt.config.grasp import GraspParams
    from scone_bt.motion import ArmModel
    from scone_bt.motion.planner import PlannerOptions

    key = f"{kitchen}|{arm_name}"
    if key not in _WORKER:
        kcfg = _WORKER.get(f"kitchen:{kitchen}") or load_kitchen(kitchen)
        _WORKER[f"kitchen:{kitchen}"] = kcfg
        rcfg = load_robot(arm_name)
        p = rcfg.planner
        _WORKER[key] = {
            "kcfg": kcfg,
            "rcfg": rcfg,
            "arm": ArmModel(rcfg),
            "params": GraspParams.of(rcfg),
            "options": PlannerOptions.of(p),
        }
    return _WORKER[key]


@contextlib.contextmanager
def _recording_ompl_queries() -> Iterator[list[tuple[Any, Any, Any, Any]]]:
    """Every (start, goals, collision world, options) the pick-and-place hands to OMPL while the block runs.

    The planning thread calls `plan_joint_path` through scone_bt.motion.plan_session; the recorder wraps that name
    for the block's duration and passes every call through unchanged. A goal the plan reached by its straight
    segment alone (`direct_path`, asked before a goal set is built) is recorded as a query to that one goal: it
    stands for the query it spared.
    """
    from scone_bt.motion import plan_session

    original, original_direct = plan_session.plan_joint_path, plan_session.direct_path
    calls: list[tuple[Any, Any, Any, Any]] = []
    lock = threading.Lock()

    def record(start: Any, goal: Any, is_valid: Any, options: Any) -> None:
        with lock:
            calls.append((start.copy(), goal.copy(), getattr(is_valid, "__self__", None), options))

    def recording(start: Any, goal: Any, lower: Any, upper: Any, is_valid: Any, options: Any) -> Any:
        record(start, goal, is_valid, options)
        return original(start, goal, lower, upper, is_valid, options)

    def recording_direct(start: Any, goal: Any, lower: Any, upper: Any, is_valid: Any, options: Any) -> Any:
        result = original_direct(start, goal, lower, upper, is_valid, options)
        if result is not None:
            record(start, goal, is_valid, options)
        return result

    # cast: the wrappers take and return what the functions they stand in for do
    plan_session.plan_joint_path = cast(Any, recording)
    plan_session.direct_path = cast(Any, recording_direct)
    try:
        yield calls
    finally:
        plan_session.plan_joint_path = original
        plan_session.direct_path = original_direct


def _compare(calls: list[tuple[Any, Any, Any, Any]]) -> list[dict[str, Any]]:
    """Each recorded OMPL query solved again by OMPL and by VAMP, back to back, with its seed; one row each."""
    from dataclasses import replace

    import numpy as np

    from scone_bt.motion.collision import CollisionWorld
    from scone_bt.motion.planner import plan_joint_path
    from scone_bt.motion.vamp_planner import VampOptions, plan_vamp

    rows = []
    for k, (start, goal, world, options) in enumerate(calls):
        if not isinstance(world, CollisionWorld):
            continue
        arm = world.arm
        ompl_options = replace(options, backend="ompl")  # OMPL itself, whatever the robot file's backend
        ompl = plan_joint_path(start, goal, arm.lower, arm.upper, world.is_valid, ompl_options)
        vamp = plan_vamp(
            start,
            goal,
            world,
            # the same options the planner's VAMP backend uses (planner._plan_vamp)
            VampOptions(rng_seed=options.rng_seed, simplify=options.simplify, resolution=options.resolution),
        )
        both = ompl.success and vamp.success
        rows.append(
            {
                "k": k,
                "carrying": world.min_up is not None,
                "goals": int(np.atleast_2d(goal).shape[0]),
                "ompl_status": ompl.status.value,
                "ompl_direct": ompl.success and ompl.message.startswith("direct"),
                "ompl_ms": round(ompl.planning_time * 1000, 3),
                "ompl_waypoints": None if ompl.path is None else len(ompl.path),
                "vamp_status": vamp.result.status.value,
                "vamp_ms": round(vamp.result.planning_time * 1000, 3),
                "vamp_env_ms": round(vamp.environment_s * 1000, 3),
                "vamp_reported_ms": round(vamp.vamp_ns / 1e6, 3),
                "vamp_padding": vamp.padding,
                "vamp_waypoints": None if vamp.result.path is None else len(vamp.result.path),
                "ratio": round(ompl.planning_time / vamp.result.planning_time, 2) if both else None,
                "vamp_mesh_valid": vamp.mesh_valid if vamp.success else None,
                "vamp_mesh_why": vamp.mesh.why if vamp.mesh is not None and not vamp.mesh.valid else None,
            }
        )
    return rows


@dataclass(frozen=True, eq=False)
class _Draw:
    """Query i's seeded products: the target, the others, and the generator that then places them on the shelving.

    Attributes:
        target: The product to fetch (a catalogue entry).
        extra: The other products: `clutter` on the shelving, then those the human has carried to the table.
        rng: The query's generator ([seed, i]), past the draw of `extra`.
    """

    target: Any
    extra: list[Any]
    rng: Any


@dataclass(frozen=True, eq=False)
class _Executed:
    """What one query's pick-and-place did in the physics.

    Attributes:
        task: The finished pick-and-place task (its plan, or why none exists).
        outcome: Its outcome.
        sim_s: Simulated seconds from its start to its end.
        on_shelf: The target stood on a shelf when the query began.
        static_names: The kitchen's fixed structure (shelving, table), by name.
        calls: The OMPL queries recorded for the VAMP comparison (empty without it).
    """

    task: Any
    outcome: Any
    sim_s: float
    on_shelf: bool
    static_names: set[str]
    calls: list[tuple[Any, Any, Any, Any]]


def _query(
    kitchen_file: str,
    arm_name: str,
    seed: int,
    clutter: int,
    table_objects: int,
    i: int,
    compare_vamp: bool = False,
    probe: bool = False,
) -> dict[str, Any]:
    """Plan and execute query i of one arm in a fresh kitchen; one record of what happened (seeded by [seed, i]).

    With `compare_vamp`, the record also holds ``planners``: the OMPL queries of the plan solved by both planners.
    With `probe`, every query hefts its target first (motion.probe, the default settings) and may set it back
    (``aborted``: neither a success nor a failure).
    """
    from scone_bt.quiet import quiet_backends

    quiet_backends()
    w = _setup(kitchen_file, arm_name)
    draw = _draw(w["kcfg"], seed, clutter + table_objects, i)
    executed = _execute(w, draw, clutter, i, compare_vamp, probe)
    g, params, target = w["rcfg"].gripper, w["params"], draw.target
    opening = 2.0 * (g.open_position - g.closed_position)
    fits_gripper = target.grasp_width <= opening - params.opening_margin
    fits_payload = 2 * g.max_force * g.finger_friction * target.friction >= PAYLOAD_SAFETY * target.mass * G
    return _record(i, target, bool(fits_gripper), bool(fits_payload), executed, compare_vamp)


def _draw(kcfg: Any, seed: int, others: int, i: int) -> _Draw:
    """Query i's target (a seeded permutation of the catalogue) and `others` other products (seed [seed, i])."""
    import numpy as np

    catalogue = list(kcfg.catalogue.objects)
    order = np.random.default_rng(seed).permutation(len(catalogue))
    rng = np.random.default_rng([seed, i])
    target = catalogue[int(order[i % len(order)])]
    rest = [o for o in catalogue if o.name != target.name]
    picks = rng.choice(len(rest), size=others, replace=False)
    return _Draw(target, [rest[int(j)] for j in picks], rng)


def _execute(
    w: dict[str, Any], draw: _Draw, clutter: int, i: int, compare_vamp: bool, probe: bool = False
) -> _Executed:
    """Stock a fresh kitchen with the draw, then plan and execute the pick-and-place (seeded by i)."""
    from scone_bt.motion import MotionSystem
    from scone_bt.motion.execution import ExecutionSettings
    from scone_bt.motion.timing import limits_of
    from scone_bt.world import Kitchen

    kcfg, rcfg, target, extra = w["kcfg"], w["rcfg"], draw.target, draw.extra
    with Kitchen(kcfg, rcfg) as kitchen:
        kitchen.spawn([target, *extra], draw.rng)
        on_table = [s.name for s in extra[clutter:] if kitchen.human_place_on_table(s.name)]
        kitchen.advance(0.3)
        on_shelf = kitchen.is_on_shelf(target.name)
        static_names = {b.name for b in kitchen.static_boxes}
        system = MotionSystem(
            kitchen, w["arm"], w["options"], limits_of(rcfg), w["params"], ExecutionSettings(), rcfg
        )
        shelf = [(_detect(kitchen, s.name), s) for s in extra if s.name not in on_table]
        table = [(_detect(kitchen, n), kitchen.specs[n]) for n in on_table]
        recorder: contextlib.AbstractContextManager[list[tuple[Any, Any, Any, Any]]] = (
            _recording_ompl_queries() if compare_vamp else contextlib.nullcontext([])
        )
        with recorder as calls:
            task = system.pick_and_place(
                _detect(kitchen, target.name), target, shelf, rng_seed=i, table_obstacles=table
            )
            if probe:
                from scone_bt.motion.probe import ProbeSettings

                task.probe = ProbeSettings()
            start = kitchen.sim_time
            task.start()
            while not task.done():
                if task.is_planning():
                    task.wait_planned()  # simulated time must not depend on the planning thread's speed
                kitchen.advance(0.1)
            outcome = task.outcome()
        sim_s = kitchen.sim_time - start
        system.close()
    return _Executed(task, outcome, sim_s, bool(on_shelf), static_names, calls)


def _record(
    i: int, target: Any, fits_gripper: bool, fits_payload: bool, executed: _Executed, compare_vamp: bool
) -> dict[str, Any]:
    """One query's record: the target, whether it fits, the outcome, and the plan's figures or why none exists."""
    from scone_bt.motion import PickPlacePlan

    plan, outcome = executed.task.plan, executed.outcome
    assert outcome is not None
    rec: dict[str, Any] = {
        "i": i,
        "target": target.name,
        "fits_gripper": fits_gripper,
        "fits_payload": fits_payload,
        "success": bool(outcome.success),
        "aborted": bool(getattr(outcome, "aborted", False)),
        "stage": outcome.stage.value if outcome.stage else None,
        "message": outcome.message,
        "sim_s": executed.sim_s,
        "planned": isinstance(plan, PickPlacePlan),
        "reason": None,
        "on_shelf": executed.on_shelf,
        "scene_only": False,
    }
    if compare_vamp:
        rec["planners"] = _compare(executed.calls)
    if isinstance(plan, PickPlacePlan):
        rec.update(
            family=plan.grasp.family.value,
            plan_ms=plan.planning_wall_s * 1000,
            plan_cpu_ms=plan.planning_cpu_s * 1000,
            ruckig_ms=[t * 1000 for t in plan.ruckig_times],
            ompl_ms=[r.planning_time * 1000 for r in plan.plans],
        )
    elif plan is not None:
        rec["reason"] = plan.reason.value
        # Blocked by the shelving's own structure alone (no product among what blocked the most grasps).
        rec["scene_only"] = bool(plan.blockers) and set(plan.blockers) <= executed.static_names
    return rec


def _bench_arm(args: argparse.Namespace, kcfg: Any, arm_name: str) -> dict[str, Any]:
    from scone_bt.config import load_robot
    from scone_bt.motion.vamp_planner import VAMP_ROBOTS, vamp_available

    load_robot(arm_name)  # an unknown robot is an error before any query runs
    planners = getattr(args, "planners", ("ompl",))
    compare_vamp = "vamp" in planners and arm_name in VAMP_ROBOTS
    if compare_vamp and not vamp_available():
        from scone_bt.motion.vamp_planner import VampUnavailableError

        raise VampUnavailableError("--planner vamp: VAMP is not installed; build it with `make vamp`")
    slots = len(kcfg.scene.shelf_slots())
    catalogue = kcfg.catalogue.objects
    clutter = min(args.clutter, slots - 1 - args.table_objects, len(catalogue) - 1 - args.table_objects)
    cpu0 = time.process_time()
    children0 = os.times().children_user + os.times().children_system
    jobs = (args.kitchen, arm_name, args.seed, clutter, args.table_objects)
    if args.jobs > 1:
        import concurrent.futures as cf
        import multiprocessing as mp

        # Queries are independent and seeded by their index: the records (and the report) do not depend on how
        # many processes ran them.
        with cf.ProcessPoolExecutor(args.jobs, mp_context=mp.get_context("spawn")) as pool:
            futures = [pool.submit(_query, *jobs, i, compare_vamp, args.probe) for i in range(args.queries)]
            records = []
            for f in futures:
                records.append(f.result())
                _print_record(args, arm_name, records[-1])
    else:
        records = []
        for i in range(args.queries):
            records.append(_query(*jobs, i, compare_vamp, args.probe))
            _print_record(args, arm_name, records[-1])
    # The workers' CPU time is counted once they have exited (the pool is closed by now).
    children = os.times().children_user + os.times().children_system - children0
    report = _report(records, time.process_time() - cpu0 + children)
    if "vamp" in planners:
        report["planners"] = (
            _planner_report(records)
            if compare_vamp
            else {
                "note": f"VAMP has no model of {arm_name}: not compared (VAMP arms: {', '.join(VAMP_ROBOTS)})"
            }
        )
    return report


def _planner_report(records: list[dict[str, Any]]) -> dict[str, Any]:
    """OMPL against VAMP over every recorded OMPL query: the rows and their summary."""
    import numpy as np

    rows = [{"i": rec["i"], **row} for rec in records for row in rec.get("planners", [])]
    solved_ompl = [r for r in rows if r["ompl_status"] == "success"]
    solved_vamp = [r for r in rows if r["vamp_status"] == "success"]
    both = [r for r in rows if r["ratio"] is not None]
    searched = [r for r in both if not r["ompl_direct"]]

    def summary(part: list[dict[str, Any]]) -> dict[str, Any]:
        ratios = [r["ratio"] for r in part]
        return {
            "queries": len(part),
            "ompl_ms_p50": _pct([r["ompl_ms"] for r in part], 50),
            "ompl_ms_p95": _pct([r["ompl_ms"] for r in part], 95),
            "vamp_ms_p50": _pct([r["vamp_ms"] for r in part], 50),
            "vamp_ms_p95": _pct([r["vamp_ms"] for r in part], 95),
            "vamp_env_ms_p50": _pct([r["vamp_env_ms"] for r in part], 50),
            "ratio_median": round(float(np.median(ratios)), 2) if ratios else None,
            # VAMP's environment is built from the collision world for each query (OMPL's world already exists)
            "ratio_with_env_median": (
                round(float(np.median([r["ompl_ms"] / (r["vamp_ms"] + r["vamp_env_ms"]) for r in part])), 2)
                if part
                else None
            ),
            "vamp_mesh_valid_share": _rate(sum(bool(r["vamp_mesh_valid"]) for r in part), len(part)),
        }

    return {
        "what": "each OMPL query of the pick-and-place solved again by OMPL and VAMP back to back (same thread, "
        "same seed); ms are wall; ratio = ompl_ms / vamp_ms (vamp_ms without building VAMP's environment, "
        "ratio_with_env with it); vamp_mesh_valid: the VAMP path passes the mesh check",
        "queries": len(rows),
        "ompl_success_rate": _rate(len(solved_ompl), len(rows)),
        "vamp_success_rate": _rate(len(solved_vamp), len(rows)),
        "vamp_success_rate_where_ompl_solved": _rate(
            sum(r["vamp_status"] == "success" for r in solved_ompl), len(solved_ompl)
        ),
        "vamp_mesh_valid_share": _rate(
            sum(bool(r["vamp_mesh_valid"]) for r in solved_vamp), len(solved_vamp)
        ),
        "vamp_status": dict(Counter(r["vamp_status"] for r in rows)),
        "vamp_fell_back_to_world_padding": sum(r["vamp_padding"] == 0.0 for r in solved_vamp),
        "both_solved": summary(both),
        "both_solved_ompl_searched": summary(searched),
        "both_solved_free": summary([r for r in both if not r["carrying"]]),
        "both_solved_carrying": summary([r for r in both if r["carrying"]]),
        "rows": rows,
    }


def _print_record(args: argparse.Namespace, arm_name: str, rec: dict[str, Any]) -> None:
    if args.verbose:
        what = "ok" if rec["success"] else rec["message"][:120]
        print(f"[{arm_name} {rec['i']}] {rec['target']}: {what}", flush=True)


def _probe_counts(records: list[dict[str, Any]]) -> dict[str, int]:
    """Targets the heft test set back (--probe), all and those that fit the gripper and the payload."""
    aborted = [r for r in records if r.get("aborted", False)]
    return {
        "probe_aborted": len(aborted),
        "probe_aborted_graspable": sum(r["fits_gripper"] and r["fits_payload"] for r in aborted),
    }


def _report(records: list[dict[str, Any]], cpu_total: float) -> dict[str, Any]:
    counts: Counter[str] = Counter()
    reasons: Counter[str] = Counter()
    families: Counter[str] = Counter()
    failed_objects: Counter[str] = Counter()
    plan_ms: list[float] = []
    plan_cpu_ms: list[float] = []
    ruckig_ms: list[float] = []
    ompl_ms: list[float] = []
    sim_s: list[float] = []
    examples: dict[str, list[str]] = {}
    off_shelf: list[str] = []
    for rec in records:
        fits_gripper, fits_payload = rec["fits_gripper"], rec["fits_payload"]
        sim_s.append(rec["sim_s"])
        if not rec.get("on_shelf", True):
            off_shelf.append(rec["target"])
        counts["queries"] += 1
        counts["fits_gripper"] += fits_gripper
        counts["fits_gripper_and_payload"] += fits_gripper and fits_payload
        if rec["planned"]:
            counts["planned"] += 1
            counts["reachable"] += 1
            families[rec["family"]] += 1
            plan_ms.append(rec["plan_ms"])
            plan_cpu_ms.append(rec["plan_cpu_ms"])
            ruckig_ms.extend(rec["ruckig_ms"])
            ompl_ms.extend(rec["ompl_ms"])
        elif rec["reason"] is not None:
            key = f"planning: {rec['reason']}"
            reasons[key] += 1
            counts["reachable"] += rec["reason"] == "no_path"
            blocked = fits_gripper and rec["reason"] == "grasps_blocked"
            counts["blocked_graspable"] += blocked
            counts["blocked_by_scene_only"] += blocked and rec.get("scene_only", False)
        if rec["success"]:
            counts["success"] += 1
            counts["success_graspable"] += fits_gripper and fits_payload
        elif rec.get("aborted", False):  # set back where it stood (--probe): neither a success nor a failure
            reasons["probe: set back"] += 1
        else:
            failed_objects[rec["target"]] += 1
            key = f"physical: {rec['stage'] or 'place'}" if rec["planned"] else f"planning: {rec['reason']}"
            if rec["planned"]:
                reasons[key] += 1
            if fits_gripper and fits_payload:
                examples.setdefault(key, []).append(f"{rec['target']}: {rec['message'][:160]}")
    report: dict[str, Any] = {
        "queries": counts["queries"],
        "fits_gripper": counts["fits_gripper"],
        "fits_gripper_and_payload": counts["fits_gripper_and_payload"],
        "blocked_by_clutter_rate": _rate(counts["blocked_graspable"], counts["fits_gripper"]),
        "blocked_by_scene_only": counts["blocked_by_scene_only"],
        "targets_off_shelf": off_shelf,
        "physical_success_rate_graspable": _rate(
            counts["success_graspable"], counts["fits_gripper_and_payload"]
        ),
        "physical_success_rate_all": _rate(counts["success"], counts["queries"]),
        **_probe_counts(records),
        "plan_success_rate_on_reachable": _rate(counts["planned"], counts["reachable"]),
        "pick_place_plan_ms_p50": _pct(plan_ms, 50),
        "pick_place_plan_ms_p95": _pct(plan_ms, 95),
        "pick_place_plan_cpu_ms_p50": _pct(plan_cpu_ms, 50),
        "pick_place_plan_cpu_ms_p95": _pct(plan_cpu_ms, 95),
        "ompl_query_ms_p50": _pct(ompl_ms, 50),
        "ruckig_ms_p50": _pct(ruckig_ms, 50),
        "ruckig_ms_max": round(max(ruckig_ms), 3) if ruckig_ms else None,
        "failures_by_reason": dict(sorted(reasons.items())),
        "failures_of_graspable": {k: v[:6] for k, v in sorted(examples.items())},
        "grasp_families": dict(sorted(families.items())),
        "failed_objects": dict(failed_objects.most_common(12)),
        "sim_s_per_query_p50": _pct(sim_s, 50),
        "cpu_s_total": round(cpu_total, 1),
    }
    report["targets_met"] = {
        key: (None if report[key] is None else (report[key] <= bound if op == "<=" else report[key] >= bound))
        for key, (op, bound) in TARGETS.items()
    }
    return report


def run(args: argparse.Namespace) -> int:
    """Run the queries for every arm; print the JSON report (and write it to --json)."""
    from scone_bt.config import load_kitchen
    from scone_bt.errors import ConfigError
    from scone_bt.quiet import quiet_backends
    from scone_bt.robot.flags import require_pybullet

    require_pybullet(args.robot, "scone-bench motion")
    if args.queries < 1 or args.clutter < 0 or args.table_objects < 0 or args.jobs < 1:
        raise ConfigError("--queries and --jobs must be >= 1, --clutter and --table-objects >= 0")
    args.planners = tuple(dict.fromkeys(p.strip() for p in args.planner.split(",") if p.strip()))
    if "ompl" not in args.planners or not set(args.planners) <= set(PLANNERS):
        raise ConfigError(f"--planner: ompl, or ompl,vamp (got {args.planner!r})")
    quiet_backends()
    kcfg = load_kitchen(args.kitchen)
    arms = comma_list(args.arms, "--arms", "panda,iiwa7")
    t0 = time.perf_counter()
    report: dict[str, Any] = {
        "benchmark": "motion",
        "queries_per_arm": args.queries,
        "clutter": args.clutter,
        "table_objects": args.table_objects,
        "catalogue_size": len(kcfg.catalogue),
        "seed": args.seed,
        **({"probe": True} if args.probe else {}),
        "targets": {k: f"{op} {v}" for k, (op, v) in TARGETS.items()},
        "arms": {arm: _bench_arm(args, kcfg, arm) for arm in arms},
        "wall_s": None,
        "machine": {
            "python": platform.python_version(),
            "processor": platform.machine(),
            "cpus": os.cpu_count(),
        },
        "load_average_1min": round(os.getloadavg()[0], 2),
        "jobs": args.jobs,
        **({"planners": list(args.planners)} if "vamp" in args.planners else {}),
        # the planning thread shares its process with the physics loop: wall times grow with the machine's load
        "note": "plan times: wall and the planning thread's own CPU; load_average_1min is taken at the end",
    }
    report["wall_s"] = round(time.perf_counter() - t0, 1)
    emit_report(report, args.json, force=args.force)
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``motion`` to ``scone-bench``."""
    from scone_bt.robot.flags import add_backend_option

    b = sub.add_parser("motion", help="pick-and-place planning and physics over the catalogue, both arms")
    b.add_argument("--queries", type=int, default=200, help="queries per arm (default 200)")
    b.add_argument("--arms", default="panda,iiwa7", help="comma-separated robot files (default panda,iiwa7)")
    add_backend_option(b, arm_flag="--arms")
    b.add_argument("--clutter", type=int, default=11, help="other products on the shelving (default 11)")
    b.add_argument("--table-objects", type=int, default=2, help="products already on the table (default 2)")
    b.add_argument("--kitchen", default="kitchen", help="kitchen file (default perception/kitchen.yaml)")
    b.add_argument("--seed", type=int, default=0)
    b.add_argument("--json", help="also write the JSON report to this file")
    b.add_argument("--verbose", action="store_true", help="one line per query")
    b.add_argument(
        "--probe",
        action="store_true",
        help="heft every target first (the heft test, default settings): a product that slips is set back "
        "(probe_aborted), not carried",
    )
    b.add_argument(
        "--jobs",
        type=int,
        default=1,
        help="processes running the queries (default 1; the report is the same)",
    )
    b.add_argument(
        "--planner",
        default="ompl",
        help="ompl (default), or ompl,vamp: also solve every OMPL query again with both planners and compare "
        "(VAMP: make vamp; Panda only)",
    )
    b.set_defaults(func=run)
