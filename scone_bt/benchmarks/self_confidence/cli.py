"""``scone-bench sc``: the self-confidence benchmark, ``generate`` (datasets) and ``evaluate`` (Table I).

    scone-bench sc generate                                   # 11 profiles x 100 executions into tools/data/sc
    scone-bench sc generate --profiles p01_weak_gripper --executions 20 --out runs/sc
    scone-bench sc generate --catalogue my_products.yaml --products "oat milk,tahini" --out runs/mine
    scone-bench sc generate --ray auto --workers 32           # on a Ray cluster (docs/distributed.md)
    scone-bench sc evaluate ...                               # see scone_bt.benchmarks.self_confidence.evaluate
    scone-bench sc probe --out docs/results                   # what the texts reveal; see .probe

Registration is cheap: the handlers import PyBullet, OMPL and the embedders when they run.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from scone_bt.argparsing import path_arg

__all__ = ["register", "DEFAULT_PROFILES_DIR", "DEFAULT_OUT_DIR"]

DEFAULT_PROFILES_DIR = Path("tools/profiles")
"""Where the shipped proficiency profiles live (relative to the repository root)."""
DEFAULT_OUT_DIR = Path("tools/data/sc")
"""Where the shipped datasets live (relative to the repository root)."""


def _generate(args: argparse.Namespace) -> int:
    from scone_bt.benchmarks.self_confidence.batch import run_generate

    return run_generate(args)


def _register_generate(sc_sub: argparse._SubParsersAction) -> None:
    from scone_bt.distributed import add_engine_arguments
    from scone_bt.robot.flags import add_robot_options

    g = sc_sub.add_parser(
        "generate",
        help="simulated pick-and-place datasets, one CSV per proficiency profile (resumable)",
        description="Run real executions (perception, OMPL, the engine --robot names) per proficiency profile; one CSV each.",
    )
    g.add_argument(
        "--profiles",
        nargs="+",
        default=None,
        metavar="NAME",
        help="profile names (comma or space separated; default: every profile in --profiles-dir)",
    )
    g.add_argument(
        "--profiles-dir",
        type=path_arg,
        default=DEFAULT_PROFILES_DIR,
        help=f"folder of profile YAMLs (default: {DEFAULT_PROFILES_DIR})",
    )
    g.add_argument("--executions", type=int, default=100, help="executions per profile (default: 100)")
    g.add_argument(
        "--out", type=path_arg, default=DEFAULT_OUT_DIR, help=f"output folder (default: {DEFAULT_OUT_DIR})"
    )
    g.add_argument(
        "--catalogue",
        action="append",
        default=[],
        metavar="FILE",
        help="an extra product catalogue YAML (repeatable), as on scone-run",
    )
    g.add_argument(
        "--products",
        default=None,
        metavar="NAMES|FILE",
        help="restrict the draw of targets and distractors: comma-separated names or a file of one name a line",
    )
    g.add_argument(
        "--workers", type=int, default=2, help="parallel worker processes or Ray workers (default: 2)"
    )
    g.add_argument(
        "--seed", type=int, default=None, help="replace every profile's base seed (default: the file's)"
    )
    g.add_argument("--kitchen", default="kitchen", help="kitchen file name or path (default: kitchen)")
    add_robot_options(g)
    g.add_argument(
        "--max-minutes", type=float, default=None, help="stop after this long (finished rows are kept)"
    )
    g.add_argument("--no-progress", action="store_true", help="no progress bar on stderr")
    g.add_argument("--json", type=path_arg, default=None, help="also write the JSON summary to this file")
    add_engine_arguments(g)
    g.set_defaults(func=_generate)


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``sc`` (``generate``, ``evaluate`` when the evaluator provides it, and ``probe``) to ``scone-bench``."""
    import importlib

    sc = sub.add_parser("sc", help="self-confidence datasets (generate) and their evaluation (evaluate)")
    sc_sub = sc.add_subparsers(dest="sc_command", required=True, metavar="SUBCOMMAND")
    _register_generate(sc_sub)
    evaluate = importlib.import_module("scone_bt.benchmarks.self_confidence.evaluate")
    register_evaluate = getattr(evaluate, "register_evaluate", None)
    if register_evaluate is not None:
        register_evaluate(sc_sub)
    from scone_bt.benchmarks.self_confidence.probe import register_probe

    register_probe(sc_sub)
