"""``scone-bench sc generate``: every execution of every profile, in parallel, resumable, with a JSON summary.

One CSV per profile (<out>/<profile>.csv, columns dataset.COLUMNS). Finished rows of an unfinished profile live in
<out>/.<profile>.partial.csv and are not run again; the file becomes <profile>.csv when all are done. Execution i
of a profile uses seed (profile.seed + --seed) * 100000 + i, so any row can be regenerated alone, on any engine.
Every run is appended to <out>/generation.json (command, software, timings; no machine paths).
"""

from __future__ import annotations

import argparse
import dataclasses
import difflib
import os
import platform
import sys
import time
from collections import Counter
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

from scone_bt.benchmarks.progress import progress_bar
from scone_bt.benchmarks.self_confidence.dataset import ExecutionRecord, read_records, write_records
from scone_bt.benchmarks.self_confidence.generate import ExecutionTask, drawable_products, execute_task
from scone_bt.benchmarks.self_confidence.profiles import Profile, load_profiles
from scone_bt.errors import ConfigError

__all__ = ["run_generate", "parse_products", "parse_profile_names", "check_writable", "summarise"]


def parse_profile_names(values: Sequence[str] | None) -> list[str] | None:
    """Profile names given as several words and/or comma-separated lists; None for all."""
    if not values:
        return None
    return [n.strip() for v in values for n in v.split(",") if n.strip()]


def parse_products(value: str | None, names: Sequence[str]) -> tuple[str, ...] | None:
    """The --products restriction: a file of one name a line (# comments) or comma-separated names.

    Raises:
        ConfigError: A name not in the catalogue (with the closest valid names), or an empty list.
    """
    if value is None:
        return None
    path = Path(value)
    if path.is_file():
        from scone_bt.config.schema import read_text

        items = [line.split("#", 1)[0].strip() for line in read_text(path).splitlines()]
        where = f"--products file {value}"
    else:
        items = [v.strip() for v in value.split(",")]
        where = "--products"
    chosen = tuple(dict.fromkeys(i for i in items if i))
    if not chosen:
        raise ConfigError(f"{where}: no product names")
    known = set(names)
    for name in chosen:
        if name not in known:
            close = difflib.get_close_matches(name, names, n=5, cutoff=0.5)
            hint = f"closest: {', '.join(close)}" if close else "none is close"
            raise ConfigError(
                f"{where}: unknown product {name!r} ({hint}; `scone-bench catalogue` lists all {len(names)})"
            )
    return chosen


def check_writable(out: Path) -> None:
    """Create `out` and prove a file can be written there, before any execution runs."""
    try:
        out.mkdir(parents=True, exist_ok=True)
        probe = out / f".write-test-{os.getpid()}"
        probe.write_text("")
        probe.unlink()
    except OSError as exc:
        raise ConfigError(f"--out {out}: not a writable folder ({exc.strerror or exc})") from None


def _note(bar: Any, text: str) -> None:
    """A line above the bar on stderr (nothing with --no-progress; tqdm.write alone would print to stdout)."""
    if not bar.disable:
        bar.write(text, file=sys.stderr)


def _paths(out: Path, profile: Profile) -> tuple[Path, Path]:
    return out / f"{profile.name}.csv", out / f".{profile.name}.partial.csv"


def _resume(out: Path, profile: Profile, executions: int) -> dict[int, ExecutionRecord]:
    """Rows already recorded for `profile` (complete file first, else the partial one) that are still valid."""
    final, partial = _paths(out, profile)
    rows = read_records(final) or read_records(partial)
    # A row from another seed (a different --seed) is not this run's execution: it is run again.
    return {r.index: r for r in rows if r.index < executions and r.seed == profile.execution_seed(r.index)}


def _save(out: Path, profile: Profile, records: dict[int, ExecutionRecord], total: int) -> None:
    final, partial = _paths(out, profile)
    if len(records) >= total:
        write_records(final, records.values())
        partial.unlink(missing_ok=True)
    else:
        write_records(partial, records.values())


def summarise(
    profile: Profile, records: dict[int, ExecutionRecord], executions: int, walls: Sequence[float]
) -> dict[str, Any]:
    """Per-profile summary: rows, success rate, failure stages, seeds, mean wall time per execution."""
    recs = list(records.values())
    stages = Counter(r.failure_stage for r in recs if not r.success)
    return {
        "rows": len(recs),
        "complete": len(recs) >= executions,
        "success_rate": round(sum(r.success for r in recs) / len(recs), 3) if recs else None,
        "failure_stages": dict(sorted(stages.items())),
        "distinct_objects": len({r.object for r in recs}),
        "seeds": [profile.execution_seed(0), profile.execution_seed(executions - 1)],
        "mean_execution_wall_s": round(sum(walls) / len(walls), 3) if walls else None,
    }


def _cpu_s() -> float:
    """CPU seconds (user + system) of this process and of its child processes that have ended."""
    import resource

    own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


def _portable(argv: Sequence[str]) -> str:
    """The command line without machine paths (an absolute path keeps only its last two parts)."""
    parts = []
    for a in argv:
        parts.append(f".../{Path(a).parent.name}/{Path(a).name}" if os.path.isabs(a) else a)
    return " ".join(["scone-bench", *parts])


def _code_version() -> str | None:
    """The checkout's commit, with "-dirty" when files differ from it (None outside a git checkout)."""
    import subprocess

    try:
        out = subprocess.run(
            ["git", "describe", "--always", "--dirty", "--abbrev=12"],
            capture_output=True,
            text=True,
            timeout=10,
            cwd=Path(__file__).resolve().parent,
        )
    except (OSError, subprocess.SubprocessError):
        return None
    return out.stdout.strip() or None if out.returncode == 0 else None


def _write_log(out: Path, argv: Sequence[str], summary: dict[str, Any]) -> None:
    """Append this run to generation.json, keeping earlier runs."""
    import json
    from importlib.metadata import version

    log_path = out / "generation.json"
    try:
        log = json.loads(log_path.read_text()) if log_path.is_file() else {"runs": []}
    except json.JSONDecodeError:
        raise ConfigError(f"{log_path}: not valid JSON; delete or fix it") from None
    log.setdefault("runs", []).append(
        {
            "command": _portable(argv),
            "when": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
            "python": platform.python_version(),
            "pybullet": version("pybullet"),
            "cpu_count": os.cpu_count(),
            "code": _code_version(),
            **summary,
        }
    )
    log_path.write_text(json.dumps(log, indent=1) + "\n")


def run_generate(args: argparse.Namespace) -> int:
    """Run the executions `args` asks for; print (and with --json write) the summary. 0 when every profile is
    complete, 1 when stopped early (--max-minutes)."""
    from scone_bt.config import load_kitchen, load_robot
    from scone_bt.distributed import engine_from_args, imap_tasks, start_engine
    from scone_bt.reporting import emit_report

    if args.executions < 1:
        raise ConfigError(f"--executions {args.executions}: must be at least 1")
    if args.workers < 1:
        raise ConfigError(f"--workers {args.workers}: must be at least 1")
    if args.max_minutes is not None and args.max_minutes <= 0:
        raise ConfigError(f"--max-minutes {args.max_minutes}: must be positive")
    for c in args.catalogue:
        if not Path(c).is_file():
            raise ConfigError(f"--catalogue {c}: no such file")
    kitchen_cfg = load_kitchen(args.kitchen, args.catalogue)
    load_robot(args.robot)  # a bad robot name fails here, before any work
    profiles_dir = Path(args.profiles_dir)
    if not profiles_dir.is_dir():
        raise ConfigError(f"--profiles-dir {profiles_dir}: no such folder")
    profiles = load_profiles(profiles_dir, parse_profile_names(args.profiles))
    offset = int(args.seed or 0)
    if offset:
        profiles = [dataclasses.replace(p, seed=p.seed + offset) for p in profiles]
        bad = [p for p in profiles if not 0 <= p.seed <= 42_949]
        if bad:
            raise ConfigError(
                f"--seed {offset}: profile {bad[0].name} would get seed {bad[0].seed}, not in 0-42949"
            )
    products = parse_products(args.products, kitchen_cfg.catalogue.names())
    pool = drawable_products(kitchen_cfg, products)
    most = max(p.objects_on_shelf for p in profiles)
    if len(pool) < most:
        raise ConfigError(
            f"--products: {len(pool)} product(s) fit the shelving, profile needs {most} per execution "
            f"(objects_on_shelf); name more products"
        )
    out = Path(args.out)
    check_writable(out)

    done = {p.name: _resume(out, p, args.executions) for p in profiles}
    by_name = {p.name: p for p in profiles}
    catalogues = tuple(str(c) for c in args.catalogue)
    tasks = [
        ExecutionTask(p, i, args.kitchen, args.robot, catalogues, products)
        for p in profiles
        for i in range(args.executions)
        if i not in done[p.name]
    ]
    engine = engine_from_args(args, args.workers)
    start_engine(engine)  # an unreachable Ray cluster fails here, before any work
    walls: dict[str, list[float]] = {p.name: [] for p in profiles}
    load_before = os.getloadavg()[0] if hasattr(os, "getloadavg") else None
    cpu0 = _cpu_s()
    t0 = time.perf_counter()
    deadline = None if args.max_minutes is None else t0 + 60.0 * args.max_minutes
    bar = progress_bar(len(tasks), "executions", quiet=args.no_progress, unit="run")
    skipped = sum(len(v) for v in done.values())
    if skipped:
        _note(bar, f"resuming: {skipped} executions already recorded, {len(tasks)} to run")
    stopped = False
    results: Iterator[tuple[int, tuple[str, ExecutionRecord, float]]] = imap_tasks(
        execute_task, tasks, engine=engine
    )
    try:
        for _i, (name, record, wall) in results:
            done[name][record.index] = record
            walls[name].append(wall)
            _save(out, by_name[name], done[name], args.executions)
            bar.set_postfix_str(f"{name} {len(done[name])}/{args.executions}")
            bar.update(1)
            if deadline is not None and time.perf_counter() > deadline:
                _note(bar, "--max-minutes reached: stopping (finished rows are saved)")
                stopped = True
                break
    finally:
        results.close()  # type: ignore[attr-defined]  # stops the pool or cancels the Ray tasks still running
        bar.close()
    elapsed = time.perf_counter() - t0
    cpu = _cpu_s() - cpu0  # this process and its finished worker processes (a Ray cluster's are not counted)
    run = sum(len(w) for w in walls.values())
    summary: dict[str, Any] = {
        "profiles": {p.name: summarise(p, done[p.name], args.executions, walls[p.name]) for p in profiles},
        "executions_run": run,
        "executions_resumed": skipped,
        "wall_s": round(elapsed, 1),
        "executions_per_s": round(run / elapsed, 3) if run and elapsed > 0 else None,
        "cpu_s_per_execution": round(cpu / run, 3) if run and engine.kind.value == "local" else None,
        "workers": args.workers,
        "engine": engine.label,
        "products_drawn_from": len(pool),
        "user_catalogues": [Path(c).name for c in catalogues],
        "load_average_1min": {
            "start": round(load_before, 2) if load_before is not None else None,
            "end": round(os.getloadavg()[0], 2) if hasattr(os, "getloadavg") else None,
        },
        "stopped_early": stopped,
    }
    _write_log(
        out, sys.argv[1:] if sys.argv and "scone-bench" in sys.argv[0] else ["sc", "generate"], summary
    )
    emit_report(summary, args.json)
    return 0 if all(v["complete"] for v in summary["profiles"].values()) else 1
