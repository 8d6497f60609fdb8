"""``scone-bench``: every benchmark of the project as one subcommand.

Each benchmark lives beside the stage it measures and exposes ``register(subparsers)``, which adds its
subcommand(s) and sets ``func`` (a callable ``(argparse.Namespace) -> int``). Registration must stay cheap:
heavy imports happen inside ``func``.

    scone-bench --help
    scone-bench if --states tools/data/if/test.jsonl
"""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Sequence
from pathlib import Path

from scone_bt.errors import SconeError
from scone_bt.strict_json import dumps

__all__ = ["main", "emit_report", "BENCHMARK_MODULES"]

# One line per benchmark module; its register() adds the subcommands.
BENCHMARK_MODULES: tuple[str, ...] = (
    "scone_bt.instruction_following.cli",
    "scone_bt.benchmarks.cli",
    "scone_bt.study.loadtest",
    "scone_bt.benchmarks.scale",
    "scone_bt.benchmarks.self_confidence.cli",
    "scone_bt.benchmarks.fleet",
    "scone_bt.benchmarks.perception",
    "scone_bt.benchmarks.episode",
    "scone_bt.benchmarks.catalogue",
    "scone_bt.benchmarks.motion",
    "scone_bt.benchmarks.decisions",
    "scone_bt.study.analysis_bench",
)


def emit_report(
    report: object, json_path: str | Path | None, indent: int = 2, make_parent: bool = False
) -> None:
    """Print a benchmark's JSON report and, with ``--json FILE``, write the same text there (strict JSON)."""
    text = dumps(report, indent=indent)
    print(text)
    if json_path:
        path = Path(json_path)
        if make_parent:
            path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text + "\n")


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="scone-bench", description="Every benchmark of SCONE-BT as one subcommand; each prints JSON."
    )
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name in BENCHMARK_MODULES:
        importlib.import_module(name).register(sub)
    return p


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``scone-bench``; errors print one line and exit with status 2."""
    args = _parser().parse_args(argv)
    try:
        return int(args.func(args))
    except SconeError as exc:
        print(f"scone-bench: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
