"""``scone-scenario``: run scenario files headless and report, for people without pytest habits.

    scone-scenario run scenarios/ [--jobs 2] [--junit report.xml] [--out runs/scenarios] [-k PATTERN] [-t TAG]
    scone-scenario check scenarios/          # validate only
    scone-scenario schema [FILE]             # the JSON Schema of a scenario file

Exit status: 0 when every case passed or failed as expected, 1 when one failed (or passed against its
``expected: fail``), 2 for bad input (one line).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from xml.etree import ElementTree as ET

from scone_bt.errors import SconeError

__all__ = ["main", "junit_xml", "summary_table"]


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="scone-scenario", description="Headless scenario tests (docs/scenarios.md)."
    )
    sub = p.add_subparsers(dest="command", required=True)
    r = sub.add_parser("run", help="run scenario files (or every *.yaml in the folders given)")
    r.add_argument("paths", nargs="+", help="scenario files or folders")
    r.add_argument(
        "--jobs", type=int, default=1, help="cases run at once, each in its own process (default 1)"
    )
    r.add_argument("--junit", type=Path, default=None, help="write a JUnit XML report here")
    r.add_argument(
        "--out",
        type=Path,
        default=None,
        help="folder for a failing case's event log and recording (default: beside the --junit report, else "
        "runs/scenarios)",
    )
    r.add_argument("-k", dest="select", default=None, help="run only cases whose name contains this text")
    r.add_argument(
        "-t", "--tag", action="append", default=[], help="run only cases tagged so (repeat: any of them)"
    )
    r.add_argument("--skip-tag", action="append", default=[], help="leave out cases tagged so")
    r.add_argument("--quiet", action="store_true", help="no progress lines")
    c = sub.add_parser("check", help="validate scenario files without running them")
    c.add_argument("paths", nargs="+")
    s = sub.add_parser("schema", help="print (or write) the JSON Schema of a scenario file")
    s.add_argument("file", nargs="?", type=Path, default=None)
    return p


def summary_table(results: Sequence[object]) -> str:
    """One row per case: verdict, simulated and wall seconds, name, reason."""
    rows = [f"{'verdict':<8} {'sim s':>7} {'wall s':>7}  name"]
    for r in results:
        reason = f"  — {r.reason}" if r.reason else ""  # type: ignore[attr-defined]
        if len(reason) > 140:
            reason = reason[:137] + "..."
        rows.append(f"{r.verdict:<8} {r.sim_s:7.1f} {r.wall_s:7.1f}  {r.name}{reason}")  # type: ignore[attr-defined]
    return "\n".join(rows)


def junit_xml(results: Sequence[object], wall_s: float) -> bytes:
    """A JUnit report: one testcase per case; a failure with the report, an expected failure as skipped."""
    suite = ET.Element(
        "testsuite",
        name="scone-scenarios",
        tests=str(len(results)),
        failures=str(sum(r.verdict in ("failed", "xpass") for r in results)),  # type: ignore[attr-defined]
        errors=str(sum(r.verdict == "error" for r in results)),  # type: ignore[attr-defined]
        skipped=str(sum(r.verdict == "xfail" for r in results)),  # type: ignore[attr-defined]
        time=f"{wall_s:.3f}",
    )
    for r in results:
        case = ET.SubElement(
            suite,
            "testcase",
            classname=Path(r.path).stem,  # type: ignore[attr-defined]
            name=r.name,  # type: ignore[attr-defined]
            time=f"{r.wall_s:.3f}",  # type: ignore[attr-defined]
        )
        ET.SubElement(case, "properties").extend(
            [ET.Element("property", name="sim_s", value=f"{r.sim_s:.1f}")]  # type: ignore[attr-defined]
        )
        if r.verdict in ("failed", "xpass"):  # type: ignore[attr-defined]
            f = ET.SubElement(case, "failure", message=r.reason)  # type: ignore[attr-defined]
            f.text = r.report()  # type: ignore[attr-defined]
        elif r.verdict == "error":  # type: ignore[attr-defined]
            ET.SubElement(case, "error", message=r.reason)  # type: ignore[attr-defined]
        elif r.verdict == "xfail":  # type: ignore[attr-defined]
            ET.SubElement(case, "skipped", type="pytest.xfail", message=r.reason)  # type: ignore[attr-defined]
    return ET.tostring(_wrap(suite), encoding="utf-8", xml_declaration=True)


def _wrap(suite: ET.Element) -> ET.Element:
    root = ET.Element("testsuites")
    root.append(suite)
    return root


def _run(args: argparse.Namespace) -> int:
    from scone_bt.scenario.model import load_scenarios
    from scone_bt.scenario.run import run_cases

    if args.out is None:
        args.out = args.junit.parent if args.junit is not None else Path("runs/scenarios")
    if args.jobs < 1:
        raise SconeError(f"--jobs {args.jobs}: give 1 or more")
    cases = load_scenarios(args.paths)
    if args.select:
        cases = [c for c in cases if args.select in c.name]
        if not cases:
            raise SconeError(f"-k {args.select!r}: no case name contains it")
    if args.tag:
        cases = [c for c in cases if set(c.spec.tags) & set(args.tag)]
    if args.skip_tag:
        cases = [c for c in cases if not set(c.spec.tags) & set(args.skip_tag)]
    if not cases:
        raise SconeError("no case left after --tag/--skip-tag")
    from tqdm import tqdm

    started = time.perf_counter()
    done = [0]
    # a bar on a terminal; in a CI log only the line per case (a bar there is noise)
    bar = tqdm(total=len(cases), file=sys.stderr, unit="case", disable=args.quiet or not sys.stderr.isatty())

    def progress(result: object) -> None:
        done[0] += 1
        r = result
        if not args.quiet:
            line = f"[{done[0]}/{len(cases)}] {r.verdict:<7} {r.name}  ({r.sim_s:.1f} s simulated, {r.wall_s:.1f} s wall)"  # type: ignore[attr-defined]
            if bar.disable:
                print(line, file=sys.stderr, flush=True)
            else:
                bar.write(line, file=sys.stderr)
        bar.set_postfix_str(f"last: {r.name} {r.verdict}", refresh=False)  # type: ignore[attr-defined]
        bar.update(1)

    try:
        results = run_cases(cases, jobs=args.jobs, out_dir=args.out, on_result=progress)
    finally:
        bar.close()
    wall = time.perf_counter() - started
    for r in results:
        if not r.ok:
            print(r.report())
            print()
    print(summary_table(results))
    counts = {
        v: sum(r.verdict == v for r in results) for v in ("passed", "xfail", "failed", "xpass", "error")
    }
    print(
        f"{len(results)} cases: {counts['passed']} passed, {counts['xfail']} failed as expected, "
        f"{counts['failed']} failed, {counts['xpass']} passed unexpectedly, {counts['error']} errors "
        f"in {wall:.1f} s wall"
    )
    if args.junit is not None:
        args.junit.parent.mkdir(parents=True, exist_ok=True)
        args.junit.write_bytes(junit_xml(results, wall))
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

        text = json.dumps(json_schema(), indent=2, ensure_ascii=False) + "\n"
        if args.file is None:
            sys.stdout.write(text)
        else:
            args.file.write_text(text, encoding="utf-8")
        return 0
    except SconeError as exc:
        print(f"scone-scenario: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("scone-scenario: interrupted", file=sys.stderr)
        return 130
