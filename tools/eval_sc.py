#!/usr/bin/env python
"""Self-confidence benchmark (the paper's Algorithm 1) over any directory of outcome datasets.

    .venv/bin/python tools/eval_sc.py                          # shipped datasets → docs/results/self_confidence.*
    .venv/bin/python tools/eval_sc.py --datasets my_logs/ --out-dir /tmp/sc --embedders minilm onehot
    .venv/bin/python tools/eval_sc.py --ray auto --jobs 16                 # the grid on a Ray cluster, same numbers

A dataset is a CSV/Parquet file with columns action, object, outcome, failure_stage, seed (extra columns are
ignored); an experience store export (`ExperienceStore.export_csv`) works as is. Prints a JSON summary on stdout;
writes <out-dir>/<name>.md (Table I layout), <name>.json (every number) and <name>_curves.png.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

os.environ.setdefault("HF_HUB_OFFLINE", "1")
os.environ.setdefault("TRANSFORMERS_OFFLINE", "1")
os.environ.setdefault("TOKENIZERS_PARALLELISM", "false")
# One BLAS/OpenMP thread per worker: the fits are tiny, and threads of parallel workers only fight over cores.
for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

import numpy as np  # noqa: E402

from scone_bt.benchmarks.self_confidence import (  # noqa: E402
    EvalOptions,
    dataset_summary,
    embed_datasets,
    load_datasets,
    markdown_tables,
    outcome_structure,
    plot_learning_curves,
    prior_baseline,
    write_json,
)
from scone_bt.benchmarks.self_confidence.evaluate import GridInputs, evaluate_grid_pair  # noqa: E402
from scone_bt.distributed import add_engine_arguments, engine_from_args, map_tasks  # noqa: E402
from scone_bt.errors import SconeError  # noqa: E402

DEFAULT_EMBEDDERS = ("onehot", "glove", "minilm", "mpnet")


def _embedders(
    names: list[str], datasets, cache_dir: Path | None
) -> tuple[dict[str, list[np.ndarray]], dict]:
    from scone_bt.embedding import load_embedder

    features, skipped = {}, {}
    vocabulary = sorted({a for d in datasets for a in d.actions})
    for name in names:
        try:
            emb = load_embedder(name, cache_dir, vocabulary=vocabulary if name == "onehot" else None)
            features[name] = embed_datasets(datasets, emb.embed)
        except SconeError as exc:  # a model that is not installed is reported, not fatal
            skipped[name] = str(exc)
            print(f"skipping embedder {name}: {exc}", file=sys.stderr)
    return features, skipped


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    ap = argparse.ArgumentParser(
        description=__doc__.split("\n\n")[0], formatter_class=argparse.RawTextHelpFormatter
    )
    ap.add_argument("--datasets", type=Path, default=ROOT / "tools" / "data" / "sc", help="dataset directory")
    ap.add_argument("--out-dir", type=Path, default=ROOT / "docs" / "results", help="where the results go")
    ap.add_argument("--name", default="self_confidence", help="stem of the output files")
    ap.add_argument(
        "--embedders",
        nargs="+",
        default=list(DEFAULT_EMBEDDERS),
        help="onehot glove minilm mpnet finetuned:<dir> ...",
    )
    ap.add_argument(
        "--estimators", nargs="+", default=None, help="default: every name in scone_bt.confidence.ESTIMATORS"
    )
    ap.add_argument("--shuffles", type=int, default=5)
    ap.add_argument("--n-test", type=int, default=20)
    ap.add_argument(
        "--steps", type=int, nargs="+", default=[10, 20, 30, 40, 50, 60, 70, 80], help="n_train values"
    )
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--jobs", type=int, default=2, help="parallel worker processes (Ray workers with --ray)")
    add_engine_arguments(ap)
    ap.add_argument("--cache-dir", type=Path, default=None, help="embedding cache (default: scone_bt's)")
    ap.add_argument(
        "--kitchen", default="kitchen", help="kitchen file whose catalogue gives object properties"
    )
    ap.add_argument("--no-plot", action="store_true")
    return ap.parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    try:
        return _main(args)
    except SconeError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2


def _main(args: argparse.Namespace) -> int:
    from scone_bt.confidence import ESTIMATORS
    from scone_bt.config import load_kitchen
    from scone_bt.errors import UnknownNameError

    t0 = time.perf_counter()
    options = EvalOptions(n_test=args.n_test, steps=tuple(args.steps), shuffles=args.shuffles, seed=args.seed)
    estimators = list(args.estimators or ESTIMATORS)
    bad = [e for e in estimators if e not in ESTIMATORS]
    if bad:
        raise UnknownNameError("estimator", bad[0], ESTIMATORS)
    datasets = load_datasets(args.datasets, min_rows=options.min_rows)
    features, skipped = _embedders(args.embedders, datasets, args.cache_dir)
    embedders = [e for e in args.embedders if e in features]
    if not embedders:
        raise SconeError(f"no embedder could be loaded ({'; '.join(skipped.values())})")
    t_embed = time.perf_counter() - t0
    pairs = [(emb, est) for emb in embedders for est in estimators]
    engine = engine_from_args(args, args.jobs, progress="embedder × estimator")
    inputs = GridInputs(tuple(datasets), {e: features[e] for e in embedders}, options)
    results = map_tasks(evaluate_grid_pair, pairs, engine=engine, shared=inputs)  # in pair order
    prior = prior_baseline(datasets, options)
    wall = time.perf_counter() - t0

    out = args.out_dir
    stem = args.name
    best = max(results, key=lambda r: np.mean(r.auc))
    payload = {
        "protocol": {
            "algorithm": "SCONE Algorithm 1: per dataset, shuffle rows, test on the last n_test, "
            "fit on the first n_train for each step; accuracy averaged over datasets; normalised AUC",
            "n_test": options.n_test,
            "n_train": list(options.steps),
            "shuffles": options.shuffles,
            "seed": options.seed,
            "pooled_metrics_at_n_train": options.steps[-1],
            "ece_bins": options.ece_bins,
            "threshold": options.threshold,
        },
        "datasets_dir": str(args.datasets),
        "datasets": dataset_summary(datasets),
        "outcome_structure": outcome_structure(datasets, load_kitchen(args.kitchen).catalogue),
        "embedders": embedders,
        "embedders_skipped": skipped,
        "estimators": estimators,
        "results": [r.to_dict() for r in results],
        "prior_baseline": prior.to_dict(),
        "best": {"embedder": best.embedder, "estimator": best.estimator, "auc": float(np.mean(best.auc))},
        "timing_s": {
            "embedding": round(t_embed, 2),
            "total": round(wall, 2),
            "jobs": args.jobs,
            "engine": engine.label,
        },
    }
    write_json(out / f"{stem}.json", payload)
    tables = markdown_tables(results, embedders, estimators)
    (out / f"{stem}_tables.md").write_text(tables)
    if not args.no_plot:
        plot_learning_curves(results, embedders, estimators, out / f"{stem}_curves.png", prior)
    summary = {
        "auc": {f"{r.embedder}/{r.estimator}": round(float(np.mean(r.auc)), 4) for r in results},
        "prior_auc": round(float(np.mean(prior.auc)), 4),
        "best": payload["best"],
        "wall_s": round(wall, 2),
        "outputs": [str(out / f"{stem}{s}") for s in (".json", "_tables.md", "_curves.png")],
    }
    import json

    print(json.dumps(summary, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
