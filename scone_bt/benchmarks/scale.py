"""``scone-bench scale``: the same self-confidence generation on 1 and 2 Ray workers, and Ray's per-task cost.

    scone-bench scale --json runs/scale.json          # 8 executions of p00_nominal, local Ray runtime
    scone-bench scale --workers 1 2 4 8 --executions 64 --ray auto   # on a cluster (see docs/distributed.md)

Each run executes the same seeded, physical pick-and-place executions (camera, detector, OMPL, PyBullet) as
`scone-bench sc generate`. Before timing, every worker runs one untimed execution so that imports and the arm model
are loaded (a one-off per worker process, not a per-task cost). `identical_results` compares every record of
every run with the same executions run without Ray (in this process). The per-task overhead comes from a batch of
empty tasks; with the measured task time it gives `projection_100_workers` (on paper: see docs/distributed.md).
`machine_ceiling_speedup` is the speed-up plain processes get on pure CPU work on the same machine at the same
time: on a machine shared with other work it bounds what any engine can show.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from typing import TYPE_CHECKING, Any

from scone_bt.argparsing import path_arg
from scone_bt.reporting import emit_report

if TYPE_CHECKING:
    from scone_bt.benchmarks.self_confidence.profiles import Profile

__all__ = ["register", "run_scale", "noop_task", "timed_execution"]


def noop_task(item: int) -> int:
    """An empty task: its round trip is Ray's per-task overhead."""
    return item


def timed_execution(task: Any) -> tuple[Any, float, float]:
    """One ExecutionTask; (record, wall s, CPU s of this worker process during it)."""
    from scone_bt.benchmarks.self_confidence.generate import execute_task

    cpu0, wall0 = time.process_time(), time.perf_counter()
    _name, record, _wall = execute_task(task)
    return record, time.perf_counter() - wall0, time.process_time() - cpu0


def burn_task(item: int) -> float:
    """A fixed amount of pure-Python CPU work (the machine's own ceiling on parallel speed-up); its wall s."""
    t0 = time.perf_counter()
    x = 0
    for i in range(3_000_000):
        x += i ^ item
    return time.perf_counter() - t0


def machine_ceiling(workers: int, tasks: int = 8) -> float:
    """Speed-up of `workers` plain processes over one on CPU-only tasks, measured now: what the load allows."""
    from scone_bt.distributed.pool import abort_pool, spawn_pool

    rates = []
    for w in (1, workers):
        pool = spawn_pool(w)
        try:
            list(pool.map(burn_task, range(w)))  # process start-up outside the timing
            t0 = time.perf_counter()
            list(pool.map(burn_task, range(tasks)))
            rates.append(tasks / (time.perf_counter() - t0))
        except BaseException:
            abort_pool(pool)
            raise
        pool.shutdown(wait=True)
    return rates[1] / rates[0]


def _load() -> list[float]:
    return [round(x, 2) for x in os.getloadavg()]


def _checked_profile(
    executions: int, workers: tuple[int, ...], profile_name: str, robot: str, address: str
) -> Profile:
    """The profile, after every argument is checked (one line each, before Ray starts)."""
    from scone_bt.benchmarks.self_confidence import load_profiles
    from scone_bt.config import load_robot
    from scone_bt.distributed import EngineKind, EngineOptions
    from scone_bt.errors import SconeError
    from scone_bt.resources import repo_root

    if executions < 1 or not workers or min(workers) < 1:
        raise SconeError("--executions and every --workers value must be at least 1")
    root = repo_root()
    profiles_dir = (root / "tools" / "profiles") if root is not None else None
    if profiles_dir is None or not profiles_dir.is_dir():
        raise SconeError("scone-bench scale needs the profiles in tools/profiles of a checkout")
    (profile,) = load_profiles(profiles_dir, [profile_name])
    load_robot(robot)  # an unknown robot is one line here, not a failed task on every worker
    local_cpus = max(os.cpu_count() or 1, 2)
    if address in ("local", "auto") and max(workers) > local_cpus:
        # A local cluster is given as many CPUs as workers: more than the machine has measures only contention.
        raise SconeError(f"--workers {max(workers)}: this machine has {local_cpus} CPUs; give at most that")
    EngineOptions(
        EngineKind.RAY, address=address
    )  # a bad --ray value is a one-line error before anything starts
    return profile


def _timed_runs(
    tasks: list[Any], workers: tuple[int, ...], address: str, log: Any
) -> tuple[dict[str, dict[str, Any]], dict[int, list[Any]]]:
    """The executions on each worker count: (worker count → figures, worker count → records)."""
    from scone_bt.distributed import EngineKind, EngineOptions, map_tasks

    executions = len(tasks)
    runs: dict[str, dict[str, Any]] = {}
    records: dict[int, list[Any]] = {}
    for w in workers:
        engine = EngineOptions(EngineKind.RAY, workers=w, address=address, progress=f"{w} worker(s)")
        t0 = time.perf_counter()
        out = map_tasks(timed_execution, tasks, engine=engine)
        elapsed = time.perf_counter() - t0
        records[w] = [r for r, _, _ in out]
        task_wall = sum(t for _, t, _ in out)
        runs[str(w)] = {
            "wall_s": round(elapsed, 3),
            "executions_per_s": round(executions / elapsed, 4),
            "task_wall_s_mean": round(task_wall / executions, 4),
            "task_cpu_s_mean": round(sum(c for _, _, c in out) / executions, 4),
            # wall the workers spent outside the task body (scheduling, transfer, idle at the end)
            "overhead_s_per_task": round(max(0.0, elapsed * w - task_wall) / executions, 4),
            "success_rate": round(sum(r.success for r in records[w]) / executions, 3),
        }
        log(f"{w} worker(s): {runs[str(w)]['executions_per_s']} executions/s")
    return runs, records


def _noop_roundtrip_s(workers: int, address: str, overhead_tasks: int) -> float:
    """Ray's round trip of one empty task, s (after a warm-up batch)."""
    from scone_bt.distributed import EngineKind, EngineOptions, map_tasks

    engine = EngineOptions(EngineKind.RAY, workers=workers, address=address)
    map_tasks(noop_task, range(20), engine=engine)  # warm
    t0 = time.perf_counter()
    map_tasks(noop_task, range(overhead_tasks), engine=engine)
    return (time.perf_counter() - t0) / overhead_tasks


def _projection(task_s: float, noop_s: float) -> dict[str, Any]:
    """The speed-up 100 workers would get, on paper, from the task time and Ray's per-task round trip."""
    per_task = noop_s  # what Ray adds per task; the runs' outside-task time also holds CPU contention and tail idling
    # N workers: each task costs task_s plus its overhead; the driver dispatches one task per noop_s at most
    ideal_100 = 100 * task_s / (task_s + per_task)
    projected = min(ideal_100, task_s / noop_s) if noop_s > 0 else ideal_100
    return {
        "task_s": task_s,
        "overhead_s_per_task": round(per_task, 4),
        "speedup_if_overhead_only": round(ideal_100, 1),
        "driver_dispatch_limit_speedup": round(task_s / noop_s, 1) if noop_s > 0 else None,
        "speedup": round(projected, 1),
    }


def run_scale(
    executions: int = 8,
    workers: tuple[int, ...] = (1, 2),
    profile_name: str = "p00_nominal",
    robot: str = "panda",
    address: str = "local",
    overhead_tasks: int = 200,
    log: Any = lambda _m: None,
) -> dict[str, Any]:
    """Measure generation throughput per worker count on Ray; returns the JSON report."""
    from scone_bt.benchmarks.self_confidence.generate import ExecutionTask
    from scone_bt.distributed import EngineKind, EngineOptions, map_tasks
    from scone_bt.distributed.ray_engine import cluster_cpus, connect_ray
    from scone_bt.errors import SconeError

    profile = _checked_profile(executions, workers, profile_name, robot, address)
    load_before = _load()
    t_start = time.perf_counter()
    how = connect_ray(address, num_cpus=max(workers) if address in ("local", "auto") else None)
    cpus = cluster_cpus()
    if max(workers) > cpus:
        raise SconeError(f"--workers {max(workers)} exceeds the cluster's {cpus} CPUs")
    log(f"ray: {how} ({cpus} CPUs)")
    tasks = [ExecutionTask(profile, i, robot=robot) for i in range(executions)]
    warm = [ExecutionTask(profile, 100_000 + k, robot=robot) for k in range(max(workers))]
    t_warm = time.perf_counter()
    map_tasks(
        timed_execution, warm, engine=EngineOptions(EngineKind.RAY, workers=max(workers), address=address)
    )
    warmup_s = time.perf_counter() - t_warm  # imports + arm model + one execution, on every worker at once
    runs, records = _timed_runs(tasks, workers, address, log)
    noop_s = _noop_roundtrip_s(min(2, cpus), address, overhead_tasks)
    # What this machine allows right now: plain processes on pure CPU work, 1 vs the most workers (no Ray).
    ceiling = machine_ceiling(max(workers)) if max(workers) > 1 else 1.0
    log(f"machine ceiling (plain processes, CPU-only work): {ceiling:.2f}x")
    # Without Ray: the same executions in this process (the local engine with one worker) are the reference.
    log("the same executions without Ray (reference) ...")
    local = [r for r, _, _ in map_tasks(timed_execution, tasks, engine=EngineOptions(workers=1))]
    identical = all(records[w] == local for w in workers)
    base = runs[str(workers[0])]["executions_per_s"]
    speedups = {str(w): round(runs[str(w)]["executions_per_s"] / base, 3) for w in workers}
    return {
        "benchmark": "scale",
        "profile": profile.name,
        "robot": "sim",  # the backend (its executions build PyBullet kitchens directly)
        "arm": robot,
        "executions": executions,
        "workers": list(workers),
        "ray": {"address": address, "how": how, "cluster_cpus": cpus},
        "executions_per_s": {str(w): runs[str(w)]["executions_per_s"] for w in workers},
        "speedup": speedups[str(workers[-1])] if len(workers) > 1 else 1.0,
        "speedups": speedups,
        "machine_ceiling_speedup": round(ceiling, 3),
        "identical_results": int(identical),
        "runs": runs,
        "overhead": {
            "warmup_s": round(warmup_s, 2),
            "noop_task_roundtrip_ms": round(1000 * noop_s, 3),
            "overhead_ms_per_task_max_workers": round(
                1000 * runs[str(max(workers))]["overhead_s_per_task"], 2
            ),
        },
        "projection_100_workers": _projection(runs[str(workers[0])]["task_wall_s_mean"], noop_s),
        "load_average_before": load_before,
        "load_average_after": _load(),
        "cpu_count": os.cpu_count(),
        "total_wall_s": round(time.perf_counter() - t_start, 1),
        "note": "wall-clock figures depend on the machine's load; see load_average_* (other processes share the CPUs)",
    }


def _handler(args: argparse.Namespace) -> int:
    from scone_bt.quiet import quiet_backends
    from scone_bt.robot.flags import require_pybullet

    require_pybullet(args.robot, "scone-bench scale")  # its executions build PyBullet kitchens directly
    quiet_backends()
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    report = run_scale(
        executions=args.executions,
        workers=tuple(args.workers),
        profile_name=args.profile,
        robot=args.arm,
        address=args.ray,
        overhead_tasks=args.overhead_tasks,
        log=lambda m: print(m, file=sys.stderr),
    )
    emit_report(report, args.json, indent=1, make_parent=True, force=args.force)
    return 0 if report["identical_results"] else 1


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``scale`` to ``scone-bench``."""
    s = sub.add_parser(
        "scale", help="SC generation on 1 and 2 Ray workers: executions/s, speed-up, identical (JSON)"
    )
    s.add_argument("--executions", type=int, default=8, help="executions per run (default: 8)")
    s.add_argument("--workers", type=int, nargs="+", default=[1, 2], help="worker counts (default: 1 2)")
    s.add_argument(
        "--profile", default="p00_nominal", help="profile in tools/profiles (default: p00_nominal)"
    )
    from scone_bt.robot.flags import add_robot_options

    add_robot_options(s)
    s.add_argument(
        "--ray",
        default="local",
        metavar="ADDRESS",
        help="local (start a runtime with max(--workers) CPUs; default), auto, or ray://host:port",
    )
    s.add_argument(
        "--overhead-tasks", type=int, default=200, help="empty tasks timed for the overhead (default: 200)"
    )
    s.add_argument("--json", type=path_arg, help="also write the JSON report to this file")
    s.set_defaults(func=_handler)
