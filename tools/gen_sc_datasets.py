#!/usr/bin/env python
"""Generate the self-confidence datasets: real simulated pick-and-place executions under proficiency profiles.

    .venv/bin/python tools/gen_sc_datasets.py                       # every profile in tools/profiles, 100 each
    .venv/bin/python tools/gen_sc_datasets.py --only p01_weak_gripper --executions 20 --out /tmp/sc
    .venv/bin/python tools/gen_sc_datasets.py --ray auto --jobs 32             # on a Ray cluster (docs/distributed.md)

One CSV per profile (<out>/<profile>.csv: index, action, object, outcome, failure_stage, seed, detail). Runs in
parallel over --jobs processes (or --jobs Ray workers with --ray; the rows are identical) and resumes where it stopped: finished rows are kept in <out>/.<profile>.partial.csv
until the profile is complete, then renamed to <profile>.csv. Execution i of a profile uses seed
profile.seed * 100000 + i, so any row can be regenerated alone. Prints a JSON summary on stdout and records the
command, seeds and timings in <out>/generation.json.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from scone_bt.benchmarks.self_confidence import (  # noqa: E402
    ExecutionRecord,
    Profile,
    load_profiles,
    read_records,
    write_records,
)
from scone_bt.benchmarks.self_confidence.generate import ExecutionTask, execute_task  # noqa: E402
from scone_bt.distributed import (  # noqa: E402
    add_engine_arguments,
    engine_from_args,
    imap_tasks,
    start_engine,
)
from scone_bt.errors import SconeError  # noqa: E402


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument(
        "--profiles", type=Path, default=ROOT / "tools" / "profiles", help="directory of profile YAMLs"
    )
    ap.add_argument("--only", nargs="+", default=None, help="profile names to run (default: all)")
    ap.add_argument("--out", type=Path, default=ROOT / "tools" / "data" / "sc", help="output directory")
    ap.add_argument("--executions", type=int, default=100, help="executions per profile")
    ap.add_argument("--jobs", type=int, default=2, help="parallel worker processes (Ray workers with --ray)")
    add_engine_arguments(ap)
    ap.add_argument("--kitchen", default="kitchen", help="kitchen file name or path")
    ap.add_argument("--robot", default="panda", help="robot file name or path")
    ap.add_argument("--max-minutes", type=float, default=None, help="stop submitting work after this long")
    return ap.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    try:
        return _main(args)
    except SconeError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2


def _main(args: argparse.Namespace) -> int:
    from tqdm import tqdm

    from scone_bt.config import load_kitchen, load_robot

    load_kitchen(args.kitchen), load_robot(args.robot)  # fail fast on a bad name
    if args.executions < 1:
        raise SconeError("--executions must be at least 1")
    profiles = load_profiles(args.profiles, args.only)
    out: Path = args.out
    out.mkdir(parents=True, exist_ok=True)
    done: dict[str, dict[int, ExecutionRecord]] = {}
    for prof in profiles:
        final, partial = out / f"{prof.name}.csv", out / f".{prof.name}.partial.csv"
        rows = read_records(final) or read_records(partial)
        done[prof.name] = {r.index: r for r in rows if r.index < args.executions}
    todo = [(p, i) for p in profiles for i in range(args.executions) if i not in done[p.name]]
    by_name = {p.name: p for p in profiles}
    walls: dict[str, list[float]] = {p.name: [] for p in profiles}
    t0 = time.perf_counter()
    deadline = None if args.max_minutes is None else t0 + 60.0 * args.max_minutes

    tasks = [ExecutionTask(prof, i, args.kitchen, args.robot) for prof, i in todo]
    engine = engine_from_args(args, args.jobs)
    start_engine(engine)  # an unreachable Ray cluster fails here, before any work
    skipped = sum(len(v) for v in done.values())
    bar = tqdm(total=len(todo), desc="executions", unit="run", file=sys.stderr)
    if skipped:
        bar.write(f"resuming: {skipped} executions already recorded, {len(todo)} to run")
    results = imap_tasks(execute_task, tasks, engine=engine)
    try:
        for _i, (name, record, wall) in results:
            if deadline is not None and time.perf_counter() > deadline:
                bar.write("--max-minutes reached: stopping (finished rows are saved)")
                break
            done[name][record.index] = record
            walls[name].append(wall)
            _save(out, by_name[name], done[name], args.executions)
            bar.set_postfix_str(f"{name} {len(done[name])}/{args.executions}")
            bar.update(1)
    finally:
        results.close()  # stops the pool or cancels the Ray tasks still running
        bar.close()
    elapsed = time.perf_counter() - t0
    summary = {
        "profiles": {
            p.name: {
                "rows": len(done[p.name]),
                "complete": len(done[p.name]) >= args.executions,
                "success_rate": round(
                    sum(r.success for r in done[p.name].values()) / max(1, len(done[p.name])), 3
                ),
                "seeds": [p.execution_seed(0), p.execution_seed(args.executions - 1)],
                "mean_execution_wall_s": round(sum(walls[p.name]) / len(walls[p.name]), 3)
                if walls[p.name]
                else None,
            }
            for p in profiles
        },
        "executions_run": sum(len(w) for w in walls.values()),
        "wall_s": round(elapsed, 1),
        "jobs": args.jobs,
        "engine": engine.label,
    }
    _write_log(out, args, summary)
    print(json.dumps(summary, indent=1))
    return 0 if all(v["complete"] for v in summary["profiles"].values()) else 1


def _save(out: Path, profile: Profile, records: dict[int, ExecutionRecord], total: int) -> None:
    final, partial = out / f"{profile.name}.csv", out / f".{profile.name}.partial.csv"
    if len(records) >= total:
        write_records(final, records.values())
        partial.unlink(missing_ok=True)
    else:
        write_records(partial, records.values())


def _write_log(out: Path, args: argparse.Namespace, summary: dict) -> None:
    """Append this run to generation.json (command, software, timings), keeping earlier runs."""
    log_path = out / "generation.json"
    log = json.loads(log_path.read_text()) if log_path.is_file() else {"runs": []}
    from importlib.metadata import version

    log["runs"].append(
        {
            "command": "tools/gen_sc_datasets.py " + " ".join(sys.argv[1:]),
            "when": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
            "python": platform.python_version(),
            "pybullet": version("pybullet"),
            "cpu_count": os.cpu_count(),
            **summary,
        }
    )
    log_path.write_text(json.dumps(log, indent=1) + "\n")


if __name__ == "__main__":
    sys.exit(main())
