"""``scone-bench``: ``if`` scores every IF policy on a states file; ``if-states`` builds the states files.

scone-bench if --states tools/data/if/test.jsonl            # table + JSON
scone-bench if --states tools/data/if/test.jsonl --ray auto --jobs 4   # rows and baselines as Ray tasks
scone-bench if-states --out tools/data/if                   # regenerate the committed states files
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import replace
from pathlib import Path

from scone_bt.argparsing import path_arg
from scone_bt.errors import SconeError
from scone_bt.resources import repo_root

__all__ = ["register", "default_states_dir"]


def default_states_dir() -> Path | None:
    """tools/data/if in a checkout, else None."""
    root = repo_root()
    return root / "tools" / "data" / "if" if root is not None else None


def _engine(args: argparse.Namespace):  # -> EngineOptions | None
    """None (in-process, one part after another) unless --jobs > 1 or --ray."""
    from scone_bt.distributed import engine_from_args

    return engine_from_args(args, args.jobs) if args.ray or args.jobs > 1 else None


def _check_finetuned_out_and_dev(args: argparse.Namespace) -> None:
    """``--save-finetuned`` (read only while fine-tuning; a folder empty or holding an earlier head) and
    ``--dev`` (a file that exists), each one line naming the flag."""
    if args.save_finetuned is not None:
        from scone_bt.checks import check_output_dir
        from scone_bt.embedding.finetuned import HEAD_FILES

        if args.no_finetune:
            raise SconeError(
                "--save-finetuned: nothing is fine-tuned with --no-finetune; give one or the other"
            )
        check_output_dir(args.save_finetuned, "--save-finetuned")
        # A head saved there before is replaced, as any rerun replaces its own output; anything else is kept.
        others = sorted(p.name for p in args.save_finetuned.iterdir()) if args.save_finetuned.is_dir() else []
        if [name for name in others if name not in HEAD_FILES]:
            raise SconeError(
                f"--save-finetuned {args.save_finetuned}: holds other files than a fine-tuned head "
                f"({', '.join(others[:3])}); its files are never overwritten, give a new folder"
            )
    if args.dev is not None and not Path(args.dev).is_file():
        raise SconeError(
            f"--dev {args.dev}: no such file (a JSONL states file, e.g. tools/data/if/dev.jsonl)"
        )


def _bench(args: argparse.Namespace) -> int:
    from scone_bt.checks import check_positive_int
    from scone_bt.files import write_atomic
    from scone_bt.instruction_following.bench import (
        BenchOptions,
        check_embedders,
        format_table,
        run_benchmark,
    )
    from scone_bt.instruction_following.mcts_baseline import MctsOptions
    from scone_bt.instruction_following.states import load_states

    if args.limit < 0:
        raise SconeError(f"--limit {args.limit}: must be 0 (every state) or a positive number of states")
    check_positive_int(args.simulations, "--simulations")
    embedders = tuple(e for e in args.embedders.split(",") if e)
    # before the states are read or a worker starts
    for flag, names in (("--embedders", embedders), ("--ticc-embedder", (args.ticc_embedder,))):
        if flag == "--ticc-embedder" and args.no_ticc:
            continue
        try:
            check_embedders(names)
        except SconeError as exc:
            raise SconeError(f"{flag} {','.join(names)}: {exc}") from None
    _check_finetuned_out_and_dev(args)  # before the hours of scoring, not after them
    folder = default_states_dir()
    train_path = args.train or (folder / "train.jsonl" if folder else None)
    dev_path = args.dev or (folder / "dev.jsonl" if folder else None)
    if train_path is None:
        raise SconeError("no default train states outside a checkout; pass --train FILE")
    test = load_states(args.states, args.split)
    if args.limit:
        test = test[: args.limit]
    train = load_states(train_path)
    dev = load_states(dev_path) if dev_path is not None and Path(dev_path).is_file() else []
    overlap = {s.recipe_id for s in test if s.recipe_id} & {s.recipe_id for s in train if s.recipe_id}
    if overlap:
        print(
            f"warning: {len(overlap)} recipes occur in both the evaluated and the train states",
            file=sys.stderr,
        )
    options = BenchOptions(
        embedders=embedders,
        finetune=not args.no_finetune,
        finetune_base=args.finetune_base,
        finetune_dir=args.save_finetuned,
        ticc_embedder=args.ticc_embedder,
        mcts=replace(MctsOptions(), simulations=args.simulations),
        pddl=not args.no_pddl,
        ticc=not args.no_ticc,
        engine=_engine(args),
    )
    log = (lambda m: print(m, file=sys.stderr)) if not args.quiet else (lambda _m: None)
    result = run_benchmark(test, train, dev, options, log=log)
    report = {"benchmark": "if", "states_file": str(args.states), **result.to_json()}
    print(
        f"IF benchmark on {args.states} ({len(test)} states; fitted on {len(train)} train, {len(dev)} dev states)"
    )
    print(format_table(result))
    print(json.dumps(report, ensure_ascii=False))
    if args.json:  # written whole: an interrupted write leaves the last report as it was
        from scone_bt.reporting import check_report_file

        path = check_report_file(Path(args.json), force=bool(getattr(args, "force", False)))
        write_atomic(path, json.dumps(report, indent=2, ensure_ascii=False) + "\n")
    return 0


def _build(args: argparse.Namespace) -> int:
    from scone_bt.instruction_following.states import (
        SPLITS,
        StateOptions,
        build_states,
        check_states_files,
        save_states_files,
    )
    from scone_bt.recipes.recipe import read_corpus

    out = Path(args.out)
    names = [*(f"{split}.jsonl" for split in SPLITS), "pdr_mentions.jsonl"]
    inputs = {"--corpus": [Path(args.corpus)]} if args.corpus else {}
    check_states_files(out, names, inputs, force=args.force)  # before the corpus is read and the states built
    recipes = read_corpus(args.corpus)
    opts = StateOptions(distractors=args.distractors, seed=args.seed)
    nw = build_states([r for r in recipes if r.step_ingredients is not None], opts)
    pdr = build_states([r for r in recipes if r.id.startswith("pdr:")], replace(opts, labels="mentions"))
    files = {f"{split}.jsonl": [s for s in nw if s.split == split] for split in SPLITS}
    files["pdr_mentions.jsonl"] = pdr
    # All four files or none: existing ones that differ are replaced only with --force.
    written = save_states_files(out, files, force=args.force)
    counts = {name.removesuffix(".jsonl"): n for name, n in written.items()}
    print(json.dumps({"out": str(out), "states": counts, "seed": args.seed, "distractors": args.distractors}))
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``if`` and ``if-states`` to ``scone-bench``."""
    b = sub.add_parser("if", help="score every instruction-following policy on a states file")
    b.add_argument("--states", required=True, help="JSONL states file (instruction, available, relevant)")
    b.add_argument("--split", choices=["train", "dev", "test"], help="keep only this split of --states")
    b.add_argument("--train", help="train states (default tools/data/if/train.jsonl)")
    b.add_argument("--dev", help="dev states for choosing the stop rule (default tools/data/if/dev.jsonl)")
    b.add_argument(
        "--embedders", default="minilm,mpnet,glove", help="comma-separated (default minilm,mpnet,glove)"
    )
    b.add_argument(
        "--finetune-base", default="auto", help="encoder under the fine-tuned head (auto: mpnet if installed)"
    )
    b.add_argument("--save-finetuned", type=path_arg, help="folder to save the fine-tuned head in")
    b.add_argument("--no-finetune", action="store_true")
    b.add_argument("--no-pddl", action="store_true")
    b.add_argument("--no-ticc", action="store_true")
    b.add_argument("--ticc-embedder", default="minilm", help="embedder behind the TICC intent model")
    b.add_argument("--simulations", type=int, default=300, help="MCTS simulations per decision")
    b.add_argument("--limit", type=int, default=0, help="score only the first N states (quick runs)")
    b.add_argument("--json", help="also write the JSON report to this file")
    b.add_argument("--quiet", action="store_true", help="no progress lines on stderr")
    b.add_argument(
        "--jobs", type=int, default=1, help="embedder rows and baselines in parallel (Ray workers with --ray)"
    )
    from scone_bt.distributed import add_engine_arguments

    add_engine_arguments(b)
    b.set_defaults(func=_bench)
    s = sub.add_parser("if-states", help="build the IF states files from the recipe corpus")
    s.add_argument(
        "--out", type=path_arg, default=str(default_states_dir() or "if-states"), help="output folder"
    )
    s.add_argument(
        "--corpus", type=path_arg, help="recipes.jsonl (default ../shared/data/recipes/recipes.jsonl)"
    )
    s.add_argument("--distractors", type=int, default=5, help="items from other recipes per kitchen")
    s.add_argument("--seed", type=int, default=0)
    s.add_argument(
        "--force",
        action="store_true",
        help="replace states files in --out that hold other states than this build (default: refuse, "
        "write nothing)",
    )
    s.set_defaults(func=_build)
