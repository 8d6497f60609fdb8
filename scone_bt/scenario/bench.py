"""``scone-bench scenarios``: run the scenario library and print JSON (passed, expected failures, failed, wall
time, and per scenario its verdict, reason, simulated and wall seconds): a thin layer over
`scone_bt.scenario.runner`."""

from __future__ import annotations

import argparse
import time
from pathlib import Path
from typing import Any

from scone_bt.argparsing import path_arg

__all__ = ["register", "run"]


def run(
    paths: list[str],
    jobs: int,
    out_dir: Path | None,
    robot: str | None = None,
    arm: str | None = None,
    force: bool = False,
) -> dict[str, Any]:
    """The report of one run of the scenarios under ``paths`` (on the robot backend ``robot`` with the robot file
    ``arm``; None: each file's; ``force``: failing cases' outputs replace files of another kind in ``out_dir``)."""
    from scone_bt.scenario.runner import Tally, check_outputs, load_cases, run_cases

    cases = load_cases(paths, robot, arm)
    if out_dir is not None:
        check_outputs(cases, out_dir, force)
    started = time.perf_counter()
    results = run_cases(cases, jobs=jobs, out_dir=out_dir, force=force)
    wall = time.perf_counter() - started
    tally = Tally.of(results)
    return {
        "passed": tally.passed,
        "expected_failures": tally.xfail,
        "failed": tally.not_ok,
        "robot": robot or "per file",
        "arm": arm or "per file",
        "jobs": jobs,
        "wall_s": round(wall, 1),
        "scenarios": [
            {
                "name": r.name,
                "verdict": r.verdict,
                "reason": r.reason,
                "sim_s": round(r.sim_s, 1),
                "wall_s": round(r.wall_s, 1),
            }
            for r in results
        ],
    }


def _main(args: argparse.Namespace) -> int:
    from scone_bt.checks import check_output_dir
    from scone_bt.reporting import emit_report
    from scone_bt.scenario.runner import check_jobs

    # the outputs before any case runs, as scone-scenario run does: a bad path found after the run loses every result
    # (--json is checked by scone-bench for every benchmark, `cli.bench.check_report_path`)
    if args.out is not None:
        check_output_dir(args.out, "--out")
    force = bool(getattr(args, "force", False))  # scone-bench's --force: --json, and the failing cases' files
    report = run(args.paths or ["scenarios"], check_jobs(args.jobs), args.out, args.robot, args.arm, force)
    emit_report(report, args.json, force=force)
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``scenarios`` to ``scone-bench``."""
    p = sub.add_parser(
        "scenarios", help="run the scenario library headless (JSON: verdicts, sim and wall time)"
    )
    p.add_argument("paths", nargs="*", help="scenario files or folders (default: scenarios/)")
    p.add_argument("--jobs", type=int, default=1, help="cases run at once, each in its own process")
    p.add_argument(
        "--robot",
        default=None,
        help="robot backend every case runs on: sim (PyBullet) or mujoco (default: each file's world.robot)",
    )
    p.add_argument(
        "--arm",
        default=None,
        help="robot file every case runs with: a name in robots/ or a YAML path (default: each file's world.arm)",
    )
    p.add_argument(
        "--out", type=path_arg, default=None, help="folder for failing cases' event logs and recordings"
    )
    p.add_argument("--json", default=None, help="also write the report to this file")
    p.set_defaults(func=_main)
