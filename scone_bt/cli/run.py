"""scone-run: one assistive-cooking episode in simulation.

Examples:
    scone-run --robot sim                                  # default recipe, seed 0, headless
    scone-run --robot sim --recipe example:pancakes --save runs/pancakes.rrd
    scone-run --robot sim --recipe "nw:asian/Banh Mi Sandwich" --viewer
    scone-run --robot sim --experience runs/panda.db       # learning carries over between runs
    scone-run --robot sim --experience postgresql://robot@fleet-db/scone --robot-id panda-2 --learn-from same-model
    scone-run --robot sim --no-self-confidence             # the paper's control condition: always act
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from scone_bt.cli.checks import internal_error_line
from scone_bt.errors import SconeError
from scone_bt.robot.interface import BACKENDS

__all__ = ["main", "build_parser"]


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="scone-run",
        description=(
            "Run the SCONE assistive-cooking robot: it perceives the shelf, ranks 'Put X on table' actions against "
            "the current recipe step, predicts its own success (self-confidence) and either acts or asks the human "
            "for help. Prints one line per decision and a summary."
        ),
        epilog="examples:" + __doc__.split("Examples:", 1)[1],
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    g = p.add_argument_group("input")
    g.add_argument(
        "--robot",
        default="sim",
        help="robot backend; valid: %(choices)s (default: %(default)s)",
        choices=BACKENDS,
    )
    g.add_argument(
        "--arm", default="panda", help="arm model: a file name in robots/ (panda, iiwa, ...) or a YAML path"
    )
    g.add_argument(
        "--recipe",
        default="example:tomato-pasta",
        help="recipe: example:<name> (tomato-pasta, pancakes, hummus), an id from ../shared/data/recipes/recipes.jsonl, "
        "or a JSON/YAML file of the same shape (default: %(default)s)",
    )
    g.add_argument(
        "--kitchen", default="kitchen", help="kitchen file in perception/ or a path (default: %(default)s)"
    )
    g.add_argument(
        "--catalogue",
        action="append",
        default=[],
        metavar="FILE",
        help="one more product file (perception/catalogue/*.yaml shape) merged into the catalogue; repeatable",
    )
    g.add_argument(
        "--tree", default="assistive_cooking", help="tree file in trees/ or a path (default: %(default)s)"
    )
    g.add_argument(
        "--distractors", type=int, default=6, help="objects not in the recipe put on the shelf (default: 6)"
    )

    g = p.add_argument_group("run control")
    g.add_argument(
        "--seed", type=int, default=0, help="seeds everything; a seeded run repeats exactly (default: 0)"
    )
    g.add_argument("--max-ticks", type=int, default=4000, help="limit on 0.1 s control ticks (default: 4000)")
    g.add_argument("--headless", action="store_true", help="no windows (the default; kept for scripts)")
    g.add_argument("--gui", action="store_true", help="open PyBullet's own window (needs a display)")
    g.add_argument("--quiet", action="store_true", help="print only the summary")

    g = p.add_argument_group("rerun output")
    g.add_argument("--save", type=Path, metavar="FILE.rrd", help="record the episode for the rerun viewer")
    g.add_argument("--viewer", action="store_true", help="spawn the rerun live viewer")
    g.add_argument(
        "--connect",
        metavar="ADDR",
        help="stream to a running rerun viewer (e.g. rerun+http://127.0.0.1:9876/proxy)",
    )

    g = p.add_argument_group("self-confidence")
    g.add_argument(
        "--confidence-threshold", type=float, help="act when κ̂ ≥ this, else ask (tree default: 0.5)"
    )
    g.add_argument(
        "--no-self-confidence", action="store_true", help="the paper's control condition: always act"
    )
    g.add_argument(
        "--experience",
        metavar="DB|URL",
        help="outcome store κ̂ is rebuilt from at start: an SQLite file, or postgresql://user@host/db shared by a fleet",
    )
    g.add_argument(
        "--learn-from",
        default="self",
        choices=("self", "same-model", "fleet"),
        help="whose stored outcomes rebuild κ̂: this robot's, every robot's with the same arm and --profile, "
        "or the whole fleet's (default: %(default)s)",
    )
    g.add_argument(
        "--robot-id", default="", help="this robot's id in a shared store (default: the arm's name)"
    )
    g.add_argument(
        "--profile", default="", help="configuration label stored with each outcome (default: none)"
    )
    g.add_argument("--embedder", help="ζ: minilm, mpnet, glove, onehot, finetuned:<dir> or a model directory")
    g.add_argument("--estimator", help="κ̂ estimator, e.g. eps-knn, knn, lgbm, rf, svm, mlp, xgb")
    g.add_argument(
        "--relevance-threshold", type=float, help="ρ: minimum cosine similarity of a relevant action"
    )

    g = p.add_argument_group("simulated human")
    g.add_argument(
        "--takeover-probability",
        type=float,
        default=0.0,
        help="chance the human takes over an action (default: 0)",
    )

    # A real person instead of the simulated human: the tablet UI (scone_bt/study).
    from scone_bt.study.ui import add_ui_arguments

    add_ui_arguments(p)
    return p


def _quiet_backends() -> None:
    from scone_bt.quiet import quiet_backends

    quiet_backends()


def _experience(spec: str | None) -> Path | str | None:
    """A PostgreSQL URL stays a string; anything else is an SQLite file path."""
    from scone_bt.experience import is_postgres_url

    if spec is None or is_postgres_url(spec):
        return spec
    return Path(spec)


def options_from_args(args: argparse.Namespace):  # -> EpisodeOptions
    from scone_bt.behaviours import BehaviourOptions
    from scone_bt.cli import checks
    from scone_bt.episode import EpisodeOptions
    from scone_bt.human import HumanOptions
    from scone_bt.tree import load_tree_spec

    # Every value is checked here, before the kitchen is built or a model is loaded.
    checks.check_seed(args.seed)
    checks.check_positive_int(args.max_ticks, "--max-ticks")
    if args.distractors < 0:
        raise SconeError(f"--distractors {args.distractors}: must be 0 or more")
    checks.check_range(args.takeover_probability, "--takeover-probability", 0.0, 1.0)
    if args.confidence_threshold is not None:
        checks.check_range(args.confidence_threshold, "--confidence-threshold", 0.0, 1.0)
    if args.relevance_threshold is not None:
        checks.check_range(args.relevance_threshold, "--relevance-threshold", -1.0, 1.0)
    if args.save is not None:
        checks.check_output_file(args.save, "--save")
    if isinstance(_experience(args.experience), Path):  # a postgresql:// URL is checked when it is opened
        checks.check_output_file(Path(args.experience), "--experience")
    elif (
        args.experience is not None
    ):  # probe the fleet's server now, not after the kitchen and models are loaded
        from scone_bt.experience import open_store

        open_store(args.experience).close()
    if args.connect is not None:
        from scone_bt.viz.connect import check_viewer_address

        check_viewer_address(args.connect)
    load_tree_spec(args.tree)  # validated now (types and ranges), before the kitchen is built
    # Options not given on the command line come from the tree file's parameters (one source of defaults).
    behaviour = BehaviourOptions(
        embedder=args.embedder,
        estimator=args.estimator,
        confidence_threshold=args.confidence_threshold,
        relevance_threshold=args.relevance_threshold,
        use_self_confidence=not args.no_self_confidence,
        experience_path=_experience(args.experience),
        robot_id=args.robot_id,
        learn_from=args.learn_from,
        profile=args.profile,
        seed=args.seed,
    )
    return EpisodeOptions(
        robot=args.arm,
        kitchen=args.kitchen,
        catalogues=tuple(args.catalogue),
        tree=args.tree,
        recipe=args.recipe,
        seed=args.seed,
        max_ticks=args.max_ticks,
        distractors=args.distractors,
        behaviour=behaviour,
        human=HumanOptions(takeover_probability=args.takeover_probability),
        save=args.save,
        viewer=args.viewer,
        connect=args.connect,
        gui=args.gui,
    )


def main(argv: list[str] | None = None) -> int:
    _quiet_backends()
    args = build_parser().parse_args(argv)
    try:
        from scone_bt.episode import run_episode
        from scone_bt.study.ui import tablet_from_args

        options = options_from_args(args)
        if args.save is not None:
            args.save.parent.mkdir(parents=True, exist_ok=True)
        server = tablet_from_args(args)  # None without --ui
        try:
            if server is not None:
                print(f"tablet: {server.url}")
            summary = run_episode(
                options,
                printer=(lambda _line: None) if args.quiet else print,
                on_event=server.on_event if server is not None else None,
                human_factory=server.human_factory if server is not None else None,
                realtime=server is not None,
            )
        finally:
            if server is not None:
                server.close()
    except SconeError as exc:
        print(f"scone-run: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("scone-run: interrupted; outcomes observed so far are in the experience store", file=sys.stderr)
        return 130
    except (
        Exception
    ) as exc:  # a bug, not an outcome: stop with its message (SCONE_BT_DEBUG=1 shows the traceback)
        if os.environ.get("SCONE_BT_DEBUG"):
            raise
        print(f"scone-run: internal error: {internal_error_line(exc)}", file=sys.stderr)
        return 3
    print(summary.format())
    if args.save is not None:
        print(f"recording: {args.save}  (open with: rerun {args.save})")
    return 0 if summary.completed else 1


if __name__ == "__main__":
    sys.exit(main())
