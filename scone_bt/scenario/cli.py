"""``scone-scenario``: run scenario files headless and report, for people without pytest habits.

A thin layer over `scone_bt.scenario.runner` (which loads, selects, runs and counts the cases): here are its
arguments, its progress lines, the summary and the JUnit report.

    scone-scenario run scenarios/ [--jobs 2] [--junit report.xml] [--out runs/scenarios] [-k PATTERN] [-t TAG]
    scone-scenario run scenarios/ --robot mujoco   # every case on the MuJoCo backend
    scone-scenario check scenarios/          # validate only
    scone-scenario schema [FILE] [--force]   # the JSON Schema of a scenario file

Exit status: 0 when every case passed or failed as expected, 1 when one failed (or passed against its
``expected: fail``), 2 for bad input (one line).
"""

from __future__ import annotations

import argparse
import contextlib
import json
import re
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING
from xml.etree import ElementTree as ET

from scone_bt.argparsing import OneLineArgumentParser, path_arg
from scone_bt.errors import SconeError

if TYPE_CHECKING:
    from scone_bt.scenario.model import Case
    from scone_bt.scenario.run import CaseResult

__all__ = ["main", "junit_xml", "summary_table"]


def _parser() -> argparse.ArgumentParser:
    p = OneLineArgumentParser(
        prog="scone-scenario", description="Headless scenario tests (docs/scenarios.md)."
    )
    sub = p.add_subparsers(dest="command", required=True)
    r = sub.add_parser("run", help="run scenario files (or every *.yaml in the folders given)")
    r.add_argument("paths", nargs="+", help="scenario files or folders")
    r.add_argument(
        "--jobs", type=int, default=1, help="cases run at once, each in its own process (default 1)"
    )
    r.add_argument("--junit", type=path_arg, default=None, help="write a JUnit XML report here")
    r.add_argument(
        "--out",
        type=path_arg,
        default=None,
        help="folder for a failing case's event log and recording (default: beside the --junit report, else "
        "runs/scenarios)",
    )
    r.add_argument(
        "--robot",
        default=None,
        help="robot backend every case runs on: sim (PyBullet) or mujoco (default: each file's world.robot)",
    )
    r.add_argument(
        "--arm",
        default=None,
        help="robot file every case runs with: a name in robots/ or a YAML path (default: each file's world.arm)",
    )
    r.add_argument("-k", dest="select", default=None, help="run only cases whose name contains this text")
    r.add_argument(
        "-t", "--tag", action="append", default=[], help="run only cases tagged so (repeat: any of them)"
    )
    r.add_argument("--skip-tag", action="append", default=[], help="leave out cases tagged so")
    r.add_argument("--quiet", action="store_true", help="no progress lines")
    r.add_argument(
        "--force",
        action="store_true",
        help="replace an existing --junit file that is not a JUnit report, and files in --out that are not a "
        "case's earlier event log or recording",
    )
    c = sub.add_parser("check", help="validate scenario files without running them")
    c.add_argument("paths", nargs="+")
    s = sub.add_parser("schema", help="print (or write) the JSON Schema of a scenario file")
    s.add_argument("file", nargs="?", type=path_arg, default=None)
    s.add_argument(
        "--force", action="store_true", help="replace an existing FILE that is not JSON (never a YAML file)"
    )
    return p


_JUNIT_HEAD = re.compile(r"\A\ufeff?\s*(<\?xml[^>]*\?>\s*)?(<!--.*?-->\s*)*<testsuites?[\s/>]", re.DOTALL)
_SNIFF = 64 * 1024  # a JUnit report is recognised by its root element, within its first bytes


def is_junit_report(path: Path) -> bool:
    """Whether the existing file `path` is empty or a JUnit XML report (root element testsuites or testsuite)."""
    try:
        with path.open("rb") as f:
            head = f.read(_SNIFF)
    except OSError:
        return False
    text = head.decode("utf-8", errors="replace")
    return not head or _JUNIT_HEAD.match(text) is not None


def _scenario_inputs(paths: Sequence[str], cases: Sequence[Case]) -> list[Path]:
    """The run's input files: the scenario files, and the robot, kitchen, recipe... files they name."""
    from scone_bt.scenario.model import profile_path, resolve_input, scenario_files

    files = list(scenario_files(paths))
    for case in cases:
        w, base = case.spec.world, case.base
        for ref in (w.arm, w.kitchen, w.recipe, w.tree, *w.catalogues):
            if Path(resolved := resolve_input(ref, base)).is_file():
                files.append(Path(resolved))
        if case.spec.robot.profile is not None:
            with contextlib.suppress(SconeError):  # an unknown profile is the case's own error when it runs
                files.append(profile_path(case.spec.robot.profile, base))
    return files


def check_junit(path: Path, inputs: Sequence[Path], force: bool) -> Path:
    """Refuse a --junit path that would destroy something, before any case runs (one line each).

    Not a folder or device, not one of the run's inputs and not a YAML file (even with --force: a JUnit report is
    XML), not an existing file other than a JUnit report (unless --force), its folder writable.
    """
    from scone_bt.checks import check_not_yaml, check_output_file

    # checks.py has no XML kind: the generic checks there, the JUnit kind here
    check_output_file(path, "--junit", inputs={"scenario": inputs}, force=force)
    check_not_yaml(path, "--junit", "a JUnit report", ".xml", ours=is_junit_report)
    if path.exists() and not force and not is_junit_report(path):
        raise SconeError(
            f"--junit {path}: exists and is not a JUnit XML report; it is not overwritten "
            "(give another path, or --force to replace it)"
        )
    return path


def _is_json_schema(path: Path) -> bool:
    """Whether `path` holds a JSON Schema (a JSON object with "$schema"), as this command writes."""
    try:
        if path.stat().st_size > 16 * 1024 * 1024:
            return False  # no schema of ours is this large; do not read it to find out
        data = json.loads(path.read_bytes())
    except (OSError, ValueError):
        return False
    return isinstance(data, dict) and "$schema" in data


def check_schema_file(path: Path, force: bool) -> Path:
    """Refuse a schema FILE that would destroy something: a folder, device, an existing non-JSON file (unless
    --force), and a YAML file (a scenario, perhaps) that is not a JSON Schema, even with --force."""
    from scone_bt.checks import check_not_yaml, check_output_file

    check_not_yaml(path, "schema", "the schema", ".schema.json", ours=_is_json_schema)
    return check_output_file(path, "schema", kind="json", force=force)


def summary_table(results: Sequence[CaseResult]) -> str:
    """One row per case: verdict, simulated and wall seconds, name, reason."""
    rows = [f"{'verdict':<8} {'sim s':>7} {'wall s':>7}  name"]
    for r in results:
        reason = f"  — {r.reason}" if r.reason else ""
        if len(reason) > 140:
            reason = reason[:137] + "..."
        rows.append(f"{r.verdict:<8} {r.sim_s:7.1f} {r.wall_s:7.1f}  {r.name}{reason}")
    return "\n".join(rows)


def junit_xml(results: Sequence[CaseResult], wall_s: float) -> bytes:
    """A JUnit report: one testcase per case; a failure with the report, an expected failure as skipped."""
    suite = ET.Element(
        "testsuite",
        name="scone-scenarios",
        tests=str(len(results)),
        failures=str(sum(r.verdict in ("failed", "xpass") for r in results)),
        errors=str(sum(r.verdict == "error" for r in results)),
        skipped=str(sum(r.verdict == "xfail" for r in results)),
        time=f"{wall_s:.3f}",
    )
    for r in results:
        case = ET.SubElement(
            suite,
            "testcase",
            classname=Path(r.path).stem,
            name=r.name,
            time=f"{r.wall_s:.3f}",
        )
        ET.SubElement(case, "properties").extend(
            [ET.Element("property", name="sim_s", value=f"{r.sim_s:.1f}")]
        )
        if r.verdict in ("failed", "xpass"):
            f = ET.SubElement(case, "failure", message=r.reason)
            f.text = r.report()
        elif r.verdict == "error":
            ET.SubElement(case, "error", message=r.reason)
        elif r.verdict == "xfail":
            ET.SubElement(case, "skipped", type="pytest.xfail", message=r.reason)
    return ET.tostring(_wrap(suite), encoding="utf-8", xml_declaration=True)


def _wrap(suite: ET.Element) -> ET.Element:
    root = ET.Element("testsuites")
    root.append(suite)
    return root


class _Progress:
    """A line per case as its result comes: under a bar on a terminal; in a CI log only the line (a bar there is
    noise)."""

    def __init__(self, total: int, quiet: bool) -> None:
        from tqdm import tqdm

        self.total, self.quiet, self.done = total, quiet, 0
        self.bar = tqdm(total=total, file=sys.stderr, unit="case", disable=quiet or not sys.stderr.isatty())

    def __call__(self, r: CaseResult) -> None:
        self.done += 1
        if not self.quiet:
            line = f"[{self.done}/{self.total}] {r.verdict:<7} {r.name}  ({r.sim_s:.1f} s simulated, {r.wall_s:.1f} s wall)"
            if self.bar.disable:
                print(line, file=sys.stderr, flush=True)
            else:
                self.bar.write(line, file=sys.stderr)
        self.bar.set_postfix_str(f"last: {r.name} {r.verdict}", refresh=False)
        self.bar.update(1)


def _cases(args: argparse.Namespace) -> list[Case]:
    """The cases to run; the outputs checked before any runs (a bad path found after the run would lose every
    result)."""
    from scone_bt.scenario.runner import Selection, check_jobs, check_outputs, default_out_dir, load_cases

    args.out = default_out_dir(args.out, args.junit)
    check_jobs(args.jobs)
    if args.arm is not None:  # named in the line (the loader's own said only "unknown robot")
        from scone_bt.resources import resolve_file

        resolve_file("robots", args.arm, (".yaml", ".yml"), flag="--arm")
    cases = load_cases(args.paths, args.robot, args.arm)
    if args.junit is not None:
        check_junit(args.junit, _scenario_inputs(args.paths, cases), args.force)
    selected = Selection(args.select, tuple(args.tag), tuple(args.skip_tag)).apply(cases)
    check_outputs(selected, args.out, args.force)
    return selected


def _write_junit(path: Path, results: Sequence[CaseResult], wall_s: float) -> None:
    from scone_bt.files import write_atomic

    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        write_atomic(path, junit_xml(results, wall_s))  # an interrupted write leaves the old report whole
    except OSError as exc:  # checked before the run, so only a full disk or the like is left
        raise SconeError(
            f"--junit {path}: cannot write it ({exc.strerror or exc}); the results are in the summary above"
        ) from None


def _run(args: argparse.Namespace) -> int:
    """`scone-scenario run`: the runner's results as failure reports, a table, a JUnit file; exit 0, 1 or 130."""
    from scone_bt.scenario import runner

    cases = _cases(args)
    started = time.perf_counter()
    progress = _Progress(len(cases), args.quiet)
    try:
        results = runner.run_cases(
            cases, jobs=args.jobs, out_dir=args.out, on_result=progress, force=args.force
        )
    except KeyboardInterrupt:
        progress.bar.close()
        junit = "" if args.junit is None else f"; --junit {args.junit} was not written"
        print(
            f"scone-scenario: interrupted after {progress.done} of {len(cases)} cases (their lines are above){junit}",
            file=sys.stderr,
        )
        return 130
    finally:
        progress.bar.close()
    wall = time.perf_counter() - started
    for r in results:
        if not r.ok:
            print(r.report())
            print()
    print(summary_table(results))
    print(runner.Tally.of(results).line(wall))
    if args.junit is not None:
        _write_junit(args.junit, results, wall)
    lost = runner.lost_names(results)
    if lost:
        shown = ", ".join(lost[:10]) + (f" and {len(lost) - 10} more" if len(lost) > 10 else "")
        print(
            f"scone-scenario: a worker process died (e.g. killed or out of memory); {len(lost)} "
            f"case{'s' if len(lost) > 1 else ''} did not run to the end: {shown}",
            file=sys.stderr,
        )
    return 0 if all(r.ok for r in results) else 1


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``scone-scenario``; bad input prints one line and exits with status 2."""
    args = _parser().parse_args(argv)
    try:
        if args.command == "run":
            return _run(args)
        if args.command == "check":
            from scone_bt.scenario.model import load_scenarios

            cases = load_scenarios(args.paths)
            print(f"{len(cases)} cases valid")
            return 0
        from scone_bt.scenario.model import json_schema

        if args.file is not None:
            check_schema_file(args.file, args.force)
        text = json.dumps(json_schema(), indent=2, ensure_ascii=False) + "\n"
        if args.file is None:
            sys.stdout.write(text)
        else:
            from scone_bt.files import write_atomic

            try:
                write_atomic(args.file, text)
            except OSError as exc:  # checked above, so only a full disk or the like is left
                raise SconeError(f"schema {args.file}: cannot write it ({exc.strerror or exc})") from None
        return 0
    except SconeError as exc:
        print(f"scone-scenario: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("scone-scenario: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    raise SystemExit(main())
