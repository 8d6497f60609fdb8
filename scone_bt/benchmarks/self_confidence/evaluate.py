"""``scone-bench sc evaluate``: embedders × estimators × protocols over a folder of self-confidence datasets.

    scone-bench sc evaluate                                   # tools/data/sc, every installed embedder
    scone-bench sc evaluate --data my_logs/ --embedders minilm,onehot --estimators lgbm,eps-knn --json r.json
    scone-bench sc evaluate --protocols novel_products --estimators gp,grounded-lgbm --out docs/results
    scone-bench sc evaluate --ray auto --workers 16           # the grid on a Ray cluster, same numbers

The protocols and the ε-greedy rule are documented in protocols.py. Every distinct action text is embedded once
per embedder (the embedding cache makes a rerun start fast); grounded estimators get each row's embedding followed
by its execution context. The pairs run as independent tasks (local processes or Ray; results are identical).
JSON: ``protocols`` → ``algorithm1`` | ``novel_products`` | ``leave_family_out`` → list of
``{embedder, estimator, auc: {mean, std}, auroc, brier, ece, ece_noise_floor, ...}``; ``--out DIR`` adds Markdown
and PNGs. ``ece_noise_floor`` is the ECE a perfectly calibrated predictor making the same pooled predictions gets
from sampling alone (metrics.ece_noise_floor). Estimators "<name>-cal" are Platt-calibrated on out-of-fold scores
of the training rows (scone_bt.confidence.calibration; four fits per fit); with <name> in the grid too, one task
computes both from the same fits (evaluate_grid_cells) and <name>'s pair_wall_s is 0. The
embedder "oracle-attributes" is no embedder: each product's true catalogue attributes, the ceiling of an
ungrounded κ̂ (reported, never a pair in the targets).

Cells run longest first (a static cost estimate per estimator and embedding size), so the last tasks of the pool
are the cheapest; results are aggregated in task order and do not depend on the schedule.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, cast
from typing import Protocol as TypingProtocol

import numpy as np

from scone_bt.argparsing import path_arg
from scone_bt.benchmarks.self_confidence.dataset import Dataset
from scone_bt.benchmarks.self_confidence.evaldata import EvalDataset, load_eval_datasets
from scone_bt.benchmarks.self_confidence.protocols import (
    CellResult,
    EstimatorFactory,
    EvalOptions,
    PairResult,
    Protocol,
    aggregate_cells,
    evaluate_calibrated_cells,
    evaluate_cell,
    evaluate_protocols,
    row_order,
)
from scone_bt.benchmarks.self_confidence.report import ORACLE
from scone_bt.benchmarks.self_confidence.report_types import (
    EvaluationReport,
    ProtocolEntry,
    ReportOptions,
    Timing,
    clean_report,
)
from scone_bt.checks import OutputKind
from scone_bt.confidence.base import ConfidenceEstimator
from scone_bt.confidence.calibration import CALIBRATION_FOLDS
from scone_bt.errors import ConfigError, SconeError, UnknownNameError

__all__ = [
    "DEFAULT_EMBEDDERS",
    "DEFAULT_ESTIMATORS",
    "Estimator",
    "EstimatorFactory",
    "EvalOptions",
    "GridInputs",
    "ORACLE_EMBEDDER",
    "PairResult",
    "embed_datasets",
    "evaluate_grid_cell",
    "evaluate_grid_cells",
    "evaluate_grid_pair",
    "evaluate_pair",
    "oracle_features",
    "paired_calibrated",
    "prior_baseline",
    "register_evaluate",
    "cell_cost",
    "check_embedder_names",
    "check_report_files",
    "run_evaluate",
    "schedule_longest_first",
    "shuffled_order",
    "split_names",
]

DEFAULT_EMBEDDERS = ("onehot", "glove", "minilm", "mpnet", "mpnet-ft")
"""Embedders of the default grid (those not installed are skipped and reported)."""
_PAPER = ("knn", "lgbm", "rf", "svm", "mlp", "xgb")
DEFAULT_ESTIMATORS = (
    *_PAPER,
    *(f"eps-{n}" for n in _PAPER),
    "gp",
    "grounded-knn",
    "grounded-lgbm",
    "grounded-gp",
    "grounded-lgbm-cal",
    "grounded-gp-cal",
)
"""Estimators of the default grid: the paper's six, each ε-greedy, the GP, three grounded ones and the calibrated
variants of the two grounded ones that the ECE target is about."""


class Estimator(TypingProtocol):
    """What the evaluation needs of κ̂ (scone_bt.confidence estimators satisfy it)."""

    def fit(self, X: np.ndarray, y: np.ndarray) -> Any: ...

    def belief(self, X: np.ndarray) -> np.ndarray: ...

    def decide(self, X: np.ndarray, threshold: float = 0.5) -> np.ndarray: ...


def shuffled_order(n: int, shuffle: int, dataset_index: int, seed: int = 0) -> np.ndarray:
    """The row order of one dataset in one shuffle (protocols.row_order)."""
    return row_order(n, shuffle, dataset_index, seed)


def embed_datasets(
    datasets: Sequence[Dataset | EvalDataset], embed: Callable[[list[str]], np.ndarray]
) -> list[np.ndarray]:
    """(n, d) float matrices, one per dataset; each distinct action text is embedded once."""
    texts = sorted({a for d in datasets for a in d.actions})
    vectors = np.asarray(embed(texts), dtype=np.float64)
    if vectors.shape[0] != len(texts):
        raise ConfigError(f"the embedder returned {vectors.shape[0]} vectors for {len(texts)} texts")
    row = {t: i for i, t in enumerate(texts)}
    return [vectors[[row[a] for a in d.actions]] for d in datasets]


def _as_eval(datasets: Sequence[Dataset | EvalDataset]) -> list[EvalDataset]:
    return [d if isinstance(d, EvalDataset) else EvalDataset.from_dataset(d) for d in datasets]


def evaluate_pair(
    embedder: str,
    estimator: str,
    datasets: Sequence[Dataset | EvalDataset],
    features: Sequence[np.ndarray],
    make: EstimatorFactory,
    options: EvalOptions | None = None,
    protocols: Sequence[Protocol] = (Protocol.ALGORITHM1,),
) -> PairResult:
    """One pair under the given protocols (default: Algorithm 1 only, default EvalOptions)."""
    opts = options or EvalOptions()
    return evaluate_protocols(embedder, estimator, _as_eval(datasets), features, make, protocols, opts)


class _Prior(ConfidenceEstimator):
    """Predicts the training prefix's Laplace-smoothed success rate for every action (what κ̂ must beat)."""

    handles_one_class = True  # the smoothed rate is defined for no data or one class too (0.5 with none)

    def __init__(self) -> None:
        super().__init__("prior")
        self.rate = 0.5

    def _fit_model(self, X: np.ndarray, y: np.ndarray) -> None:
        self.rate = (float(np.sum(y)) + 1.0) / (len(y) + 2.0)

    def _predict_model(self, X: np.ndarray) -> np.ndarray:
        return np.full(len(X), self.rate)


def prior_baseline(
    datasets: Sequence[Dataset | EvalDataset],
    options: EvalOptions | None = None,
    protocols: Sequence[Protocol] = (Protocol.ALGORITHM1,),
) -> PairResult:
    """Every protocol for a predictor that ignores the action (the smoothed success rate seen so far)."""
    zeros = [np.zeros((len(d), 1)) for d in datasets]
    return evaluate_pair("none", "prior", datasets, zeros, lambda seed: _Prior(), options, protocols)


@dataclass(frozen=True)
class GridInputs:
    """What every pair of the grid reads (shipped once per worker by scone_bt.distributed).

    Attributes:
        datasets: The datasets.
        features: Embedded actions per dataset, per embedder name.
        options: Protocol settings.
        protocols: Protocols to run.
        cell_cache: Folder of finished cells (JSON, keyed by the hash of everything a cell depends on), or
            None to compute every cell.
        with_base: "<name>-cal" estimators whose cells also give <name>'s cells (evaluate_grid_cells).
    """

    datasets: tuple[Dataset | EvalDataset, ...]
    features: dict[str, list[np.ndarray]]
    options: EvalOptions
    protocols: tuple[Protocol, ...] = tuple(Protocol)
    cell_cache: Path | None = None
    with_base: frozenset[str] = frozenset()


def _factory(est: str, opts: EvalOptions) -> EstimatorFactory:
    from scone_bt.confidence import make_estimator

    eps = {"epsilon": opts.epsilon, "half_life": opts.half_life} if est.startswith("eps-") else {}
    return lambda seed: make_estimator(est, seed=seed, **eps)


def _inputs_of(est: str, X: np.ndarray, data: EvalDataset) -> np.ndarray:
    return np.hstack([X, data.context]) if est.startswith("grounded-") else X


def evaluate_grid_pair(pair: tuple[str, str], inputs: GridInputs) -> PairResult:
    """One (embedder, estimator) pair of the grid with scone_bt.confidence's estimator."""
    emb, est = pair
    datasets = _as_eval(inputs.datasets)
    features = [_inputs_of(est, X, d) for X, d in zip(inputs.features[emb], datasets, strict=True)]
    return evaluate_protocols(
        emb, est, datasets, features, _factory(est, inputs.options), inputs.protocols, inputs.options
    )


def _cell_key(task: tuple[str, str, int, int], data: EvalDataset, X: np.ndarray, inputs: GridInputs) -> str:
    import hashlib
    import json
    from dataclasses import asdict

    emb, est, shuffle, di = task
    h = hashlib.sha1()
    meta = [
        _code_digest(),
        emb,
        est,
        shuffle,
        di,
        asdict(inputs.options),
        [p.value for p in inputs.protocols],
    ]
    h.update(json.dumps(meta, sort_keys=True, default=str).encode())
    for part in (X, data.success, data.context):
        h.update(np.ascontiguousarray(part).tobytes())
    h.update("\0".join((*data.actions, *data.objects, *data.families)).encode())
    return h.hexdigest()


_CODE_DIGEST: list[str] = []


def _code_digest() -> str:
    """Hash of the code a cell's numbers depend on (estimators, protocols, data reading): edits invalidate cells."""
    if not _CODE_DIGEST:
        import hashlib

        import scone_bt.confidence as conf

        h = hashlib.sha1()
        here = Path(__file__).parent  # this package's folder, without importing its own __init__
        files = [*sorted(Path(conf.__file__).parent.glob("*.py"))]
        files += [here / f for f in ("protocols.py", "evaldata.py", "metrics.py", "dataset.py")]
        for f in files:
            h.update(f.read_bytes())
        _CODE_DIGEST.append(h.hexdigest())
    return _CODE_DIGEST[0]


def _cell_path(
    task: tuple[str, str, int, int], data: EvalDataset, X: np.ndarray, inputs: GridInputs
) -> Path | None:
    """Where the cell cache keeps this task's cell, or None without a cache."""
    if inputs.cell_cache is None:
        return None
    return Path(inputs.cell_cache) / f"{_cell_key(task, data, X, inputs)}.json"


def _cached_cell(path: Path | None) -> CellResult | None:
    import json

    if path is None or not path.is_file():
        return None
    try:
        return CellResult.from_json(json.loads(path.read_text()))
    except (ValueError, KeyError, TypeError):
        return None  # a damaged entry is recomputed


def _store_cell(path: Path | None, cell: CellResult) -> None:
    import json

    if path is None:
        return
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(f".{os.getpid()}.tmp")
    tmp.write_text(json.dumps(cell.to_json()))
    os.replace(tmp, path)


def evaluate_grid_cell(task: tuple[str, str, int, int], inputs: GridInputs) -> CellResult:
    """One (embedder, estimator, shuffle, dataset index) cell of the grid, from the cell cache when it is there."""
    emb, est, shuffle, di = task
    data = _as_eval(inputs.datasets[di : di + 1])[0]
    X = _inputs_of(est, inputs.features[emb][di], data)
    path = _cell_path(task, data, X, inputs)
    cell = _cached_cell(path)
    if cell is None:
        cell = evaluate_cell(
            est, data, X, di, shuffle, _factory(est, inputs.options), inputs.protocols, inputs.options
        )
        _store_cell(path, cell)
    return cell


def evaluate_grid_cells(task: tuple[str, str, int, int], inputs: GridInputs) -> tuple[CellResult, ...]:
    """The grid's unit of work: (the task's cell,), or for an estimator in inputs.with_base (its cell, its base's).

    A calibrated estimator's final fits are its base estimator's fits (protocols.evaluate_calibrated_cells), so
    the grid computes both cells in one task instead of fitting the base again in a task of its own.
    """
    emb, est, shuffle, di = task
    if est not in inputs.with_base:
        return (evaluate_grid_cell(task, inputs),)
    base_task = (emb, est.removesuffix("-cal"), shuffle, di)
    data = _as_eval(inputs.datasets[di : di + 1])[0]
    X = _inputs_of(est, inputs.features[emb][di], data)  # a "-cal" name keeps its base's "grounded-" prefix
    paths = [_cell_path(t, data, X, inputs) for t in (task, base_task)]
    cached = [_cached_cell(p) for p in paths]
    if cached[0] is not None and cached[1] is not None:
        return cached[0], cached[1]
    cells = evaluate_calibrated_cells(
        est, data, X, di, shuffle, _factory(est, inputs.options), inputs.protocols, inputs.options
    )
    for path, cell in zip(paths, cells, strict=True):
        _store_cell(path, cell)
    return cells


def paired_calibrated(estimators: Sequence[str]) -> frozenset[str]:
    """The "<name>-cal" estimators of a grid whose <name> is in the grid too (their cells come in one task)."""
    names = set(estimators)
    return frozenset(k for k in names if k.endswith("-cal") and k.removesuffix("-cal") in names)


_RELATIVE_COST = {"mlp": 1.3, "lgbm": 3.0, "rf": 1.1, "xgb": 0.8, "gp": 0.6, "svm": 0.5, "conformal": 0.05}
"""Seconds-ish per cell of each base estimator at 768 dimensions (measured on the 2-core machine; only the
order matters). Unknown names cost 1."""


def cell_cost(task: tuple[str, str, int, int], dims: dict[str, int]) -> float:
    """Estimated relative cost of one grid cell, for scheduling only (never affects a result)."""
    emb, est, _, _ = task
    base = est.removeprefix("grounded-").removeprefix("eps-").removesuffix("-cal")
    cost = _RELATIVE_COST.get(base, 0.01 if base == "knn" else 1.0)
    if est.startswith("eps-"):
        cost *= 1.1  # two online robots plus the folds
    if est.endswith("-cal"):
        cost *= CALIBRATION_FOLDS + 1  # one fit per fold and the final one
    return cost * (0.5 + 0.5 * min(dims.get(emb, 768), 768) / 768)


def schedule_longest_first(tasks: Sequence[tuple[str, str, int, int]], dims: dict[str, int]) -> list[int]:
    """Indices of `tasks`, most expensive first (stable among equals)."""
    return sorted(range(len(tasks)), key=lambda i: -cell_cost(tasks[i], dims))


# ----------------------------------------------------------------------------------------------- command
def split_names(values: Sequence[str] | None, default: Sequence[str]) -> list[str]:
    """Comma- or space-separated names, in order, without repeats."""
    if not values:
        return list(default)
    out = [n.strip() for v in values for n in v.split(",") if n.strip()]
    return list(dict.fromkeys(out))


def check_embedder_names(embedders: Sequence[str], oracle: bool = False) -> None:
    """Raise UnknownNameError for a name that is no embedder (before any model loads); `oracle` admits the oracle."""
    from scone_bt.embedding.registry import EMBEDDER_NAMES

    valid = [*EMBEDDER_NAMES, "mpnet-ft", *([ORACLE_EMBEDDER] if oracle else [])]
    for e in embedders:
        if e not in valid and not e.startswith("finetuned:") and not Path(e).is_dir():
            raise UnknownNameError("embedder", e, [*valid, "finetuned:<dir>", "<model directory>"])


def check_report_files(
    out: Path, name: str, files: Mapping[str, OutputKind], data: Path, force: bool = False
) -> dict[str, Path]:
    """The files a report writes in --out, checked before any work: one line naming the file if one cannot be.

    --name is a plain file stem and --out a folder (or one that can be made). No file may be an input of the run:
    every file already in the --data folder counts as one (its datasets, README, generation.json), so a report
    written into the dataset folder adds files there and never replaces one. An existing file of another kind is
    not overwritten unless `force`.

    Args:
        out: The --out folder.
        name: The --name stem.
        files: What follows the stem in each file name → its kind.
        data: The --data folder.
        force: Replace an existing file of another kind (--force).

    Returns:
        The path of each file, by the key of `files`.
    """
    from scone_bt.checks import check_output_dir, check_output_file

    if not name.strip() or name in (".", "..") or any(c in name for c in "/\\\0"):
        raise SconeError(f"--name {name!r}: must be a file name stem without folders (e.g. self_confidence)")
    check_output_dir(out, "--out")
    inputs = {"--data": sorted(p for p in data.iterdir() if p.is_file())} if data.is_dir() else {}
    paths = {}
    for suffix, kind in files.items():
        path = out / f"{name}{suffix}"
        check_output_file(path, "--out/--name", kind=kind, inputs=inputs, force=force)
        paths[suffix] = path
    return paths


def _check_names(
    protocols: list[str], embedders: list[str], estimators: list[str]
) -> tuple[list[Protocol], list[str]]:
    from scone_bt.confidence import CALIBRATED_ESTIMATORS, ESTIMATORS, GROUNDED_ESTIMATORS

    valid_p = [p.value for p in Protocol]
    for p in protocols:
        if p not in valid_p:
            raise UnknownNameError("protocol", p, valid_p)
    check_embedder_names(embedders, oracle=True)
    valid_k = [*ESTIMATORS, *GROUNDED_ESTIMATORS, *CALIBRATED_ESTIMATORS, "xgboost"]
    names = []
    for k in estimators:
        if k not in valid_k and k.replace("xgboost", "xgb") not in valid_k:
            raise UnknownNameError("estimator", k, valid_k)
        names.append(k.replace("xgboost", "xgb"))
    return [Protocol(p) for p in protocols], list(dict.fromkeys(names))


# Not an embedder a robot has: each action's product replaced by its true catalogue attributes (oracle_features).
# An ungrounded κ̂ on these rows shows how far knowing exactly *what* the product is can take a self-confidence
# that ignores *where* it stands: the ceiling of any text embedding. Defined beside the report that treats it so.
ORACLE_EMBEDDER = ORACLE


def oracle_features(datasets: Sequence[EvalDataset], kitchen: str = "kitchen") -> list[np.ndarray]:
    """Per dataset, (n, d) rows of the products' true attributes, standardised over the catalogue.

    Columns: grasp width, height, mass, friction (standardised), then one-hot shape, material and family. A
    product missing from the catalogue is a ConfigError (the oracle would have nothing to say).
    """
    from scone_bt.config import load_kitchen

    specs = {o.name: o for o in load_kitchen(kitchen).catalogue.objects}
    missing = sorted({o for d in datasets for o in d.objects} - set(specs))
    if missing:
        raise ConfigError(
            f"{ORACLE_EMBEDDER}: products not in the {kitchen} catalogue: {', '.join(missing[:5])}"
        )
    names = sorted(specs)
    numeric = np.array(
        [[specs[n].grasp_width, specs[n].height, specs[n].mass, specs[n].friction] for n in names]
    )
    numeric = (numeric - numeric.mean(axis=0)) / np.where(numeric.std(axis=0) > 0, numeric.std(axis=0), 1.0)
    blocks = [numeric]
    for attr in ("shape", "material", "family"):
        values = sorted({getattr(specs[n], attr) for n in names})
        blocks.append(np.array([[getattr(specs[n], attr) == v for v in values] for n in names], dtype=float))
    table = np.hstack(blocks)
    row = {n: i for i, n in enumerate(names)}
    return [table[[row[o] for o in d.objects]] for d in datasets]


def _embed_all(
    names: list[str],
    datasets: list[EvalDataset],
    cache_dir: Path | None,
    log: Callable[[str], None],
    kitchen: str = "kitchen",
) -> tuple[dict[str, list[np.ndarray]], dict[str, str], dict[str, float]]:
    from scone_bt.embedding import load_embedder

    features: dict[str, list[np.ndarray]] = {}
    skipped: dict[str, str] = {}
    seconds: dict[str, float] = {}
    vocabulary = sorted({a for d in datasets for a in d.actions})
    for name in names:
        t0 = time.perf_counter()
        if name == ORACLE_EMBEDDER:
            features[name] = oracle_features(datasets, kitchen)
            seconds[name] = round(time.perf_counter() - t0, 2)
            continue
        try:
            emb = load_embedder(name, cache_dir, vocabulary=vocabulary if name == "onehot" else None)
            features[name] = embed_datasets(datasets, emb.embed)
        except SconeError as exc:  # a model that is not installed is reported, not fatal
            skipped[name] = str(exc)
            log(f"skipping embedder {name}: {exc}")
            continue
        seconds[name] = round(time.perf_counter() - t0, 2)
        log(f"embedded {len(vocabulary)} actions with {name} ({seconds[name]:.1f} s)")
    return features, skipped, seconds


@dataclass(frozen=True)
class _Grid:
    """The checked grid of one ``sc evaluate`` run.

    Attributes:
        protocols: The protocols to evaluate.
        embedders: The embedders asked for (those that cannot load are skipped later).
        estimators: The κ̂ names.
        options: The evaluation's settings.
    """

    protocols: list[Protocol]
    embedders: list[str]
    estimators: list[str]
    options: EvalOptions


def _grid(args: argparse.Namespace) -> _Grid:
    """Check the names, --workers and --kitchen, before any work."""
    from scone_bt.checks import check_output_dir, check_positive_int, check_range
    from scone_bt.config import load_kitchen
    from scone_bt.resources import resolve_file

    protocols, estimators = _check_names(
        split_names(args.protocols, [p.value for p in Protocol]),
        embedders := split_names(args.embedders, DEFAULT_EMBEDDERS),
        split_names(args.estimators, DEFAULT_ESTIMATORS),
    )
    if args.workers < 1:
        raise ConfigError(f"--workers must be at least 1, got {args.workers}")
    # checked now, not when the first cell or the first embedding reaches them (seconds to minutes in)
    check_range(args.epsilon, "--epsilon", 0.0, 1.0)
    check_positive_int(args.refit_every, "--refit-every")
    check_positive_int(args.n_test, "--n-test")
    check_positive_int(args.shuffles, "--shuffles", 1000)
    if args.cache_dir is not None:
        check_output_dir(Path(args.cache_dir), "--cache-dir")
    # read only when a dataset has no family column, so checked now: a bad --kitchen is not found after the work
    load_kitchen(resolve_file("perception", args.kitchen, (".yaml", ".yml"), flag="--kitchen"))
    options = EvalOptions(
        n_test=args.n_test,
        steps=tuple(args.steps),
        lofo_steps=tuple(args.lofo_steps),
        shuffles=args.shuffles,
        seed=args.seed,
        epsilon=args.epsilon,
        refit_every=args.refit_every,
    )
    return _Grid(protocols, embedders, estimators, options)


def _report_files(args: argparse.Namespace, protocols: Sequence[Protocol]) -> dict[str, Path]:
    """--out's report files, checked before the evaluation: minutes of work are not lost to a bad --out."""
    if args.out is None:
        return {}
    plots: dict[str, OutputKind] = {f"_{p.value}_curves.png": "image" for p in protocols}
    return check_report_files(
        Path(args.out),
        args.name,
        {".json": "json", ".md": "text", **plots, "_reliability.png": "image"},
        Path(args.data),
        force=bool(getattr(args, "force", False)),
    )


def _evaluate_cells(
    args: argparse.Namespace,
    grid: _Grid,
    datasets: list[EvalDataset],
    features: dict[str, list[np.ndarray]],
    embedders: list[str],
    engine: Any,
) -> list[CellResult]:
    """Every cell (pair × shuffle × dataset) on the engine, in the grid's order (cached cells reused)."""
    from scone_bt.distributed import map_tasks

    options, estimators = grid.options, grid.estimators
    pairs = [(e, k) for e in embedders for k in estimators]
    # Cells (pair × shuffle × dataset) are the tasks: many small ones balance the workers, and a finished cell
    # is cached, so a rerun, or a run after one more dataset landed, computes only what changed.
    tasks = [(e, k, s, di) for e, k in pairs for s in range(options.shuffles) for di in range(len(datasets))]
    cache = None if args.no_cell_cache else _cell_cache_dir(args.cache_dir)
    paired = paired_calibrated(estimators)
    inputs = GridInputs(
        tuple(datasets), {e: features[e] for e in embedders}, options, tuple(grid.protocols), cache, paired
    )
    # A base estimator's cells come with its calibrated variant's (evaluate_grid_cells): no task of their own.
    bases = {k.removesuffix("-cal") for k in paired}
    work = [t for t in tasks if t[1] not in bases]
    # Longest cells first: the pool's last tasks are then the cheapest, so no worker idles on a long tail.
    # Cells seed their estimators themselves, so the order changes nothing but the wall time.
    order = schedule_longest_first(work, {e: features[e][0].shape[1] for e in embedders})
    run = map_tasks(evaluate_grid_cells, [work[i] for i in order], engine=engine, shared=inputs)
    done: dict[tuple[str, str, int, int], CellResult] = {}
    for i, got in zip(order, run, strict=True):
        e, k, s_, di = work[i]
        done[work[i]] = got[0]
        if len(got) > 1:
            done[(e, k.removesuffix("-cal"), s_, di)] = got[1]
    return [done[t] for t in tasks]


def _write_report_files(report: EvaluationReport, args: argparse.Namespace, files: dict[str, Path]) -> None:
    """The JSON, the Markdown and the figures into --out."""
    from scone_bt.benchmarks.self_confidence.report import evaluation_markdown, plot_curves, plot_reliability
    from scone_bt.files import write_atomic
    from scone_bt.strict_json import dumps

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    write_atomic(files[".json"], dumps(report, indent=1) + "\n")
    write_atomic(files[".md"], evaluation_markdown(report, args.name))
    plot_curves(report, out, args.name)
    plot_reliability(report, files["_reliability.png"])


def run_evaluate(args: argparse.Namespace) -> int:
    """The ``sc evaluate`` handler (see the module docstring)."""
    from scone_bt.benchmarks.self_confidence.report import dataset_summary
    from scone_bt.distributed import engine_from_args
    from scone_bt.reporting import emit_report

    def log(msg: str) -> None:
        print(msg, file=sys.stderr, flush=True)

    # One BLAS/OpenMP thread per worker: the fits are tiny, and threads of parallel workers only fight over cores.
    for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(var, "1")
    os.environ.setdefault("TOKENIZERS_PARALLELISM", "false")
    t0 = time.perf_counter()
    grid = _grid(args)
    options, protocols, estimators = grid.options, grid.protocols, grid.estimators
    report_files = _report_files(args, protocols)
    datasets = load_eval_datasets(args.data, min_rows=options.min_rows, kitchen=args.kitchen)
    features, skipped, embed_s = _embed_all(grid.embedders, datasets, args.cache_dir, log, args.kitchen)
    embedders = [e for e in grid.embedders if e in features]
    if not embedders:
        raise SconeError(f"no embedder could be loaded ({'; '.join(skipped.values())})")
    if any(k.startswith("grounded-") for k in estimators) and all(
        np.isnan(d.context).all() for d in datasets
    ):
        log(f"note: {args.data} has no context columns; grounded estimators see only missing-value flags")
    t_embed = time.perf_counter() - t0
    engine = engine_from_args(args, args.workers, progress="cells (pair × dataset)")
    cells = _evaluate_cells(args, grid, datasets, features, embedders, engine)
    pairs = [(e, k) for e in embedders for k in estimators]
    per_pair = len(cells) // max(len(pairs), 1)
    results = [
        aggregate_cells(e, k, cells[i * per_pair : (i + 1) * per_pair], protocols, options)
        for i, (e, k) in enumerate(pairs)
    ]
    prior = prior_baseline(datasets, options, tuple(protocols))
    wall = time.perf_counter() - t0
    report = EvaluationReport(
        benchmark="sc evaluate",
        data=str(args.data),
        options=ReportOptions(
            n_test=options.n_test,
            n_train=list(options.steps),
            lofo_n_train=list(options.lofo_steps),
            shuffles=options.shuffles,
            seed=options.seed,
            threshold=options.threshold,
            ece_bins=options.ece_bins,
            epsilon0=options.epsilon,
            half_life=options.half_life,
            refit_every=options.refit_every,
        ),
        datasets=dataset_summary(datasets, options),
        embedders=embedders,
        embedders_skipped=skipped,
        estimators=estimators,
        protocols={p.value: [cast(ProtocolEntry, r.entry(p)) for r in results] for p in protocols},
        prior={p.value: cast(ProtocolEntry, prior.entry(p)) for p in protocols},
        timing_s=Timing(
            embedding=round(t_embed, 2),
            embedding_per_embedder=embed_s,
            total=round(wall, 2),
            workers=args.workers,
            engine=engine.label,
            cells=len(cells),
            cells_wall_s_sum=round(sum(c.wall_s for c in cells), 1),
        ),
    )
    report = clean_report(report)  # NaN → null, the same text as the file
    if args.out is not None:
        _write_report_files(report, args, report_files)
    emit_report(report, args.json, indent=1, make_parent=True, force=bool(getattr(args, "force", False)))
    return 0


def _cell_cache_dir(cache_dir: Path | None) -> Path:
    from scone_bt.embedding.cache import default_cache_dir

    return Path(cache_dir if cache_dir is not None else default_cache_dir()) / "sc_cells"


def _steps(text: str) -> list[int]:
    try:
        return [int(v) for v in text.replace(",", " ").split()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a list of integers: {text!r}") from None


def register_evaluate(sc_sub: argparse._SubParsersAction) -> None:
    """Add ``evaluate`` to ``scone-bench sc``."""
    from scone_bt.distributed import add_engine_arguments

    e = sc_sub.add_parser(
        "evaluate",
        help="embedders × estimators × protocols on a datasets folder (JSON; --out adds Markdown and PNGs)",
        description=(
            "Algorithm 1, novel products and leave-one-family-out for each embedder × estimator pair: "
            "normalised AUC of the accuracy curve, AUROC, Brier, ECE and reliability at the largest n_train."
        ),
    )
    e.add_argument(
        "--data", type=path_arg, default=Path("tools/data/sc"), help="datasets folder (default: %(default)s)"
    )
    e.add_argument(
        "--protocols",
        nargs="+",
        default=None,
        help="comma or space separated: algorithm1, novel_products, leave_family_out (default: all)",
    )
    e.add_argument(
        "--embedders",
        nargs="+",
        default=None,
        help=f"default: {','.join(DEFAULT_EMBEDDERS)} (those not installed are skipped); also finetuned:<dir>",
    )
    e.add_argument(
        "--estimators",
        nargs="+",
        default=None,
        help="knn lgbm rf svm mlp xgb(oost) gp conformal, eps-<name>, grounded-<name> (default: "
        f"{','.join(DEFAULT_ESTIMATORS)})",
    )
    e.add_argument("--json", type=path_arg, default=None, help="also write the JSON report to this file")
    e.add_argument("--out", type=path_arg, default=None, help="folder for <name>.json, .md and PNGs")
    e.add_argument(
        "--name", default="self_confidence", help="stem of the files in --out (default: %(default)s)"
    )
    e.add_argument("--seed", type=int, default=0, help="seeds shuffles, estimators and ε draws (default: 0)")
    e.add_argument("--workers", type=int, default=2, help="parallel processes or Ray workers (default: 2)")
    e.add_argument("--shuffles", type=int, default=1, help="row orders; 1 = the datasets' own (default)")
    e.add_argument("--n-test", type=int, default=20, help="test rows at the end (default: 20)")
    e.add_argument(
        "--steps", type=_steps, default=list(EvalOptions().steps), help="n_train values, e.g. 10,20,30"
    )
    e.add_argument(
        "--lofo-steps", type=_steps, default=list(EvalOptions().lofo_steps), help="leave-family-out n_train"
    )
    e.add_argument("--epsilon", type=float, default=EvalOptions().epsilon, help="ε₀ of the ε-greedy robot")
    e.add_argument(
        "--refit-every", type=int, default=EvalOptions().refit_every, help="online refit interval (rows)"
    )
    e.add_argument("--kitchen", default="kitchen", help="catalogue for families when a file has none")
    e.add_argument(
        "--cache-dir", type=path_arg, default=None, help="embedding and cell cache (default: scone_bt's)"
    )
    e.add_argument(
        "--no-cell-cache",
        action="store_true",
        help="recompute every cell (default: reuse <cache-dir>/sc_cells)",
    )
    add_engine_arguments(e)
    e.set_defaults(func=run_evaluate)
