"""``scone-bench``: every benchmark of the project as one subcommand.

Each benchmark lives beside the stage it measures and exposes ``register(subparsers)``, which adds its
subcommand(s) and sets ``func`` (a callable ``(argparse.Namespace) -> int``). Registration must stay cheap:
heavy imports happen inside ``func``.

    scone-bench --help
    scone-bench if --states tools/data/if/test.jsonl
"""

from __future__ import annotations

import argparse
import contextlib
import importlib
import os
import sys
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from scone_bt.argparsing import OneLineArgumentParser
from scone_bt.checks import check_seed
from scone_bt.errors import SconeError

if TYPE_CHECKING:
    from scone_bt.resources import DataKind

__all__ = [
    "main",
    "check_report_path",
    "check_common_ranges",
    "check_backend_option",
    "interrupted_line",
    "BENCHMARK_MODULES",
]

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
    "scone_bt.benchmarks.soak",
    "scone_bt.benchmarks.catalogue",
    "scone_bt.benchmarks.motion",
    "scone_bt.benchmarks.physics",
    "scone_bt.benchmarks.gate",
    "scone_bt.benchmarks.decisions",
    "scone_bt.study.analysis_bench",
    "scone_bt.study.trust_bench",
    "scone_bt.scenario.bench",
)


def _leaf_parsers(parser: argparse.ArgumentParser) -> Iterator[argparse.ArgumentParser]:
    """Every parser that runs a command (subcommands of subcommands included)."""
    subs = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    if not subs:
        yield parser
    for action in subs:
        for child in dict.fromkeys(action.choices.values()):  # aliases map to the same parser
            yield from _leaf_parsers(child)


_FOLDER_INPUT_FILES = 10_000
"""At most this many files of a folder given as an input are counted as inputs (its files, not its sub-folders')."""

_OUTPUT_FOLDERS = ("out",)
"""Options naming a folder the run writes into: the folder itself is protected, not the files it holds (a report
of an earlier run there may be replaced)."""


def _folder_files(folder: Path) -> list[Path]:
    """The files directly inside `folder` (bounded): a folder given as an input reads them."""
    files: list[Path] = []
    try:
        with os.scandir(folder) as entries:
            for entry in entries:
                if len(files) >= _FOLDER_INPUT_FILES:
                    break
                try:
                    if entry.is_file():
                        files.append(Path(entry.path))
                except OSError:
                    continue
    except OSError:
        pass
    return files


def _inputs(args: argparse.Namespace, outputs: Sequence[str]) -> dict[str, list[Path]]:
    """The existing files named by the command's other options: what its report must not be written over.

    A folder given as an input counts with the files directly inside it (e.g. ``scenarios DIR``: its .yaml files),
    an output folder (--out) only as itself.
    """
    from scone_bt.config.inputs import kitchen_inputs, robot_inputs
    from scone_bt.resources import resolve_file

    # Options naming a kitchen or robot (a name or a path): their files and the files those read are inputs.
    descriptions: dict[str, tuple[DataKind, Callable[[Path], list[Path]]]] = {
        "kitchen": ("perception", kitchen_inputs),
        "arm": ("robots", robot_inputs),
    }
    out: dict[str, list[Path]] = {}
    for dest, value in vars(args).items():
        # A subcommand's name is no path (a folder of that name in the working folder is not its input).
        if dest in outputs or callable(value) or dest == "command" or dest.endswith("_command"):
            continue
        for item in value if isinstance(value, (list, tuple)) else [value]:
            if not isinstance(item, (str, Path)) or not str(item):
                continue
            files = out.setdefault(f"--{dest.replace('_', '-')}", [])
            if dest in descriptions:
                kind, expand = descriptions[dest]
                # A name that does not resolve adds nothing: its own loader words the error.
                with contextlib.suppress(SconeError):
                    files.extend(expand(resolve_file(kind, str(item), (".yaml", ".yml"))))
            elif os.path.exists(item):
                files.append(Path(item))
                if os.path.isdir(item) and dest not in _OUTPUT_FOLDERS:
                    files.extend(_folder_files(Path(item)))
    return {flag: files for flag, files in out.items() if files}


def check_common_ranges(args: argparse.Namespace) -> None:
    """Options many benchmarks share, checked before any of them runs: one line naming the flag and its range."""
    seed = getattr(args, "seed", None)
    if isinstance(seed, int) and not isinstance(seed, bool):
        check_seed(seed)
    for dest, low in (
        ("distractors", 0),
        ("jobs", 1),
        ("warmup", 0),
        ("headless_runs", 0),
        ("overhead_tasks", 1),
        ("queries", 1),
        ("executions", 1),
        ("clutter", 0),
        ("table_objects", 0),
    ):
        value = getattr(args, dest, None)
        if isinstance(value, int) and not isinstance(value, bool) and value < low:
            raise SconeError(f"--{dest.replace('_', '-')} {value}: must be an integer >= {low}")
    cache_dir = getattr(args, "cache_dir", None)
    if cache_dir is not None:  # every benchmark's embedding cache: a file or /proc was silently not written
        from scone_bt.checks import check_output_dir

        check_output_dir(Path(cache_dir), "--cache-dir")


def check_named_files(args: argparse.Namespace) -> None:
    """--arm, --arms and --kitchen of any benchmark name a robot or kitchen file, checked before it runs and
    named in the line ("--arm foo: unknown robot; valid: iiwa7, panda")."""
    from scone_bt.resources import resolve_file

    named = [("--arm", getattr(args, "arm", None))]
    if isinstance(getattr(args, "arms", None), str):
        named += [("--arms", a.strip()) for a in args.arms.split(",") if a.strip()]
    for flag, arm in named:
        if isinstance(arm, str):
            resolve_file("robots", arm, (".yaml", ".yml"), flag=flag)
    kitchen = getattr(args, "kitchen", None)
    if isinstance(kitchen, str):
        resolve_file("perception", kitchen, (".yaml", ".yml"), flag="--kitchen")


def check_backend_option(args: argparse.Namespace) -> None:
    """--robot of any benchmark names a backend (a robot file given to it is told to use --arm)."""
    robot = getattr(args, "robot", None)
    if isinstance(robot, str):
        from scone_bt.robot.flags import check_backend

        check_backend(robot)


def check_report_path(args: argparse.Namespace) -> None:
    """--json of any benchmark, before it runs (`reporting.check_report_file`: not one of its inputs, not a device,
    not an existing file that is not a report unless --force, never a YAML file); its folder made if missing."""
    path = getattr(args, "json", None)
    if path is not None and not str(path).strip():  # an empty --json was skipped silently: no report written
        raise SconeError("--json: an empty path; give a file path, or leave the option out")
    if path:
        parent = Path(path).absolute().parent
        if parent.exists() and not parent.is_dir():
            raise SconeError(f"--json {path}: {parent} is not a folder; give another path")
        from scone_bt.reporting import check_report_file

        check_report_file(
            Path(path), inputs=_inputs(args, ("json",)), force=bool(getattr(args, "force", False))
        )
        # Made now (the checks above found where it can be): the report is never lost to a missing folder.
        parent.mkdir(parents=True, exist_ok=True)


def _parser() -> argparse.ArgumentParser:
    p = OneLineArgumentParser(
        prog="scone-bench", description="Every benchmark of SCONE-BT as one subcommand; each prints JSON."
    )
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name in BENCHMARK_MODULES:
        importlib.import_module(name).register(sub)
    for leaf in _leaf_parsers(p):
        has = {o for a in leaf._actions for o in a.option_strings}
        if "--json" in has and "--force" not in has:
            leaf.add_argument(
                "--force",
                action="store_true",
                help="let --json replace an existing file that is not a benchmark report (never a YAML file)",
            )
    return p


def _command(args: argparse.Namespace) -> str:
    """The subcommand as typed: ``sc generate``, ``episode``."""
    return " ".join(str(v) for v in (args.command, getattr(args, "sc_command", None)) if v)


def interrupted_line(args: argparse.Namespace) -> str:
    """What Ctrl-C leaves behind, in one line: no report; what a resumable benchmark keeps."""
    line = f"scone-bench {_command(args)}: interrupted; no report was printed"
    if getattr(args, "json", None):
        line += f" and --json {args.json} was not written"
    if _command(args) == "sc generate":
        # The finished executions are in the profiles' partial files (written atomically after each one).
        line += f"; the executions finished so far are kept in {args.out}, and the same command resumes them"
    return line


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``scone-bench``; errors print one line and exit with status 2, Ctrl-C with 130."""
    args = _parser().parse_args(argv)
    try:
        from scone_bt.extras import require

        require("bench", "scone-bench")
        check_common_ranges(args)
        check_backend_option(args)
        check_named_files(args)
        check_report_path(args)  # before the benchmark runs: minutes of work are not lost to a bad --json
        return int(args.func(args))
    except SconeError as exc:
        print(f"scone-bench: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        # The benchmark unwound (its worker pools terminated): one line, never a traceback.
        print(interrupted_line(args), file=sys.stderr)
        return 130
    except Exception as exc:  # a bug, not a result: one line (SCONE_BT_DEBUG=1 shows the traceback)
        if os.environ.get("SCONE_BT_DEBUG"):
            raise
        from scone_bt.checks import internal_error_line

        print(f"scone-bench {_command(args)}: {internal_error_line(exc)}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
