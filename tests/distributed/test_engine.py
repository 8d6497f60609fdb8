"""The task engine: identical results on the local pool and on a real Ray runtime, for any worker count;
dead workers retried without duplicates; program errors surface once, as one line."""

from __future__ import annotations

import argparse

import engine_tasks
import pytest

from scone_bt.benchmarks.self_confidence import EvalOptions, embed_datasets, load_datasets
from scone_bt.benchmarks.self_confidence.evaluate import GridInputs, evaluate_grid_pair
from scone_bt.distributed import (
    EngineKind,
    EngineOptions,
    add_engine_arguments,
    engine_from_args,
    imap_tasks,
    map_tasks,
    task_seed,
)
from scone_bt.errors import DistributedError, SconeError
from scone_bt.resources import repo_root


def test_local_results_do_not_depend_on_the_worker_count():
    runs = [
        map_tasks(engine_tasks.seeded_draws, range(7), engine=EngineOptions(workers=w)) for w in (1, 2, 3)
    ]
    assert runs[0] == runs[1] == runs[2]
    assert [r[0] for r in runs[0]] == list(range(7))
    assert len({r[2] for r in runs[0]}) == 7  # the globals are seeded per task, not once per worker
    assert task_seed(0, 1) != task_seed(0, 2) and task_seed(0, 1) != task_seed(1, 1)


def _grid_inputs() -> GridInputs:
    from scone_bt.embedding import load_embedder

    root = repo_root()
    assert root is not None
    datasets = load_datasets(root / "tools" / "data" / "sc", names=["p00_nominal", "p01_weak_gripper"])
    options = EvalOptions(n_test=10, steps=(10, 20, 30), shuffles=2, seed=3)
    emb = load_embedder("onehot", vocabulary=sorted({a for d in datasets for a in d.actions}))
    return GridInputs(tuple(datasets), {"onehot": embed_datasets(datasets, emb.embed)}, options)


def test_sc_grid_is_identical_with_and_without_ray(ray_runtime):
    inputs = _grid_inputs()
    # one-hot κ̂s mostly predict alike on two small datasets; the GP generalises differently, so results differ
    pairs = [("onehot", est) for est in ("knn", "eps-knn", "gp")]
    results = {}
    for kind, workers in [
        (EngineKind.LOCAL, 1),
        (EngineKind.LOCAL, 2),
        (EngineKind.RAY, 1),
        (EngineKind.RAY, 2),
    ]:
        engine = EngineOptions(kind, workers=workers, address="auto")
        results[kind.value, workers] = map_tasks(evaluate_grid_pair, pairs, engine=engine, shared=inputs)
    reference = results["local", 1]
    assert [(r.embedder, r.estimator) for r in reference] == pairs
    assert all(
        r == reference for r in results.values()
    )  # every curve, AUC, AUROC, Brier, ECE (wall time aside)
    assert len({r.auc for r in reference}) > 1  # the pairs really differ: equality is not vacuous


@pytest.mark.parametrize("kind", [EngineKind.LOCAL, EngineKind.RAY])
def test_a_dead_worker_is_retried_and_no_result_is_duplicated(kind, tmp_path, request):
    if kind is EngineKind.RAY:
        request.getfixturevalue("ray_runtime")
    items = [(n, str(tmp_path)) for n in range(6)]
    engine = EngineOptions(kind, workers=2, address="auto", progress="tasks")
    got = list(imap_tasks(engine_tasks.die_once, items, engine=engine))
    assert (tmp_path / "died").exists()
    assert sorted(i for i, _ in got) == list(range(6))  # each index exactly once
    assert dict(got) == {n: n * n for n in range(6)}
    assert len((tmp_path / "attempts-3").read_text()) == 2  # died once, retried once


@pytest.mark.parametrize("kind", [EngineKind.LOCAL, EngineKind.RAY])
def test_a_program_error_is_raised_once_and_not_retried(kind, tmp_path, request):
    if kind is EngineKind.RAY:
        request.getfixturevalue("ray_runtime")
    items = [(n, str(tmp_path)) for n in range(4)]
    with pytest.raises(SconeError, match="item 2 is bad input"):
        map_tasks(engine_tasks.fail_on_two, items, engine=EngineOptions(kind, workers=2, address="auto"))
    assert (tmp_path / "attempts-2").read_text() == "x"


def test_bad_ray_address_and_options_are_one_line_errors():
    with pytest.raises(DistributedError, match=r"valid: auto, local, ray://<host>:<port>"):
        EngineOptions(EngineKind.RAY, address="head-node:6379")
    with pytest.raises(DistributedError, match="at least 1"):
        EngineOptions(workers=0)
    parser = argparse.ArgumentParser()
    add_engine_arguments(parser)
    assert engine_from_args(parser.parse_args([]), 2).kind is EngineKind.LOCAL
    ray_engine = engine_from_args(parser.parse_args(["--ray"]), 3)
    assert (ray_engine.kind, ray_engine.address, ray_engine.workers) == (EngineKind.RAY, "auto", 3)
    assert (
        engine_from_args(parser.parse_args(["--ray", "ray://head:10001"]), None).address == "ray://head:10001"
    )
