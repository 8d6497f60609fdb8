"""`scone-bench gate --unseen`: leave-products-out really removes the product, and a close neighbour helps."""

from __future__ import annotations

import json
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from scone_bt.benchmarks.gate_unseen import (
    Prior,
    first_occurrences,
    leave_products_out,
    nearest_seen,
    outcome_rates,
    unseen_report,
)
from scone_bt.benchmarks.replay import replay_stream
from scone_bt.benchmarks.replay_streams import Streams
from scone_bt.cli.bench import main
from scone_bt.experience.types import CONTEXT_FIELDS
from scone_bt.gate.budget import BudgetOptions

OPENING_M = 0.08
DIM = 8


def _context(n: int) -> np.ndarray:
    """Every product perceived alike (5 cm wide, 10 cm tall, alone on the middle tier): only ζ tells them apart."""
    values = {
        "shelf_tier": 1.0,
        "clearance_m": 0.5,
        "neighbours": 0.0,
        "detected": 1.0,
        "detected_width_m": 0.05,
        "detected_height_m": 0.10,
    }
    return np.array([[values.get(f, np.nan) for f in CONTEXT_FIELDS]] * n)


def _synthetic(n_streams: int = 3, n: int = 40, twins_lie: bool = False, seed: int = 3) -> Streams:
    """Streams of products never repeated by name; a product is "good" (succeeds, ζ near e0) or "bad" (fails, near
    e1). In the other streams every product has close neighbours of its kind; with ``twins_lie`` the other
    streams' outcomes are the opposite (their neighbours mislead)."""
    rng = np.random.default_rng(seed)
    names, vectors, context, success, products = [], [], [], [], []
    for j in range(n_streams):
        good = rng.random(n) < 0.5
        v = rng.normal(0.0, 0.05, size=(n, DIM))
        v[good, 0] += 1.0
        v[~good, 1] += 1.0
        names.append(f"s{j}")
        vectors.append(v.astype(np.float32))
        context.append(_context(n))
        success.append(good if not (twins_lie and j > 0) else ~good)
        products.append(tuple(f"s{j}-{'good' if g else 'bad'}-{i}" for i, g in enumerate(good)))
    return Streams(names, vectors, context, success, products, [None] * n_streams)


def _report(streams: Streams, replay: Any = None) -> dict[str, Any]:
    # the start these synthetic streams were written for (1 − 3α): a cold robot there asks for what it doubts
    replay = replay or partial(replay_stream, budget=BudgetOptions(start_margin=3.0))
    return unseen_report(streams, replay, "physical", 0.15, seed=0, warmup=5, opening_m=OPENING_M)


def test_leave_products_out_removes_every_execution_of_the_products() -> None:
    prior = Prior(np.arange(10.0).reshape(5, 2), np.array([1, 0, 1, 1, 0], bool), ("a", "b", "a", "c", "a"))
    kept = leave_products_out(prior, {"a"})
    assert kept.products == ("b", "c")
    assert kept.rows.tolist() == [[2.0, 3.0], [6.0, 7.0]]
    assert kept.success.tolist() == [False, True]
    assert first_occurrences(["a", "b", "a", "c", "b"]).tolist() == [True, True, False, True, False]


def test_no_prior_the_report_replays_holds_a_scored_product() -> None:
    """Every stream's products also occur, by name, in the other streams: every prior κ̂ learns before a scored
    decision (fleet and own store alike) must hold none of them, while the fleet-with-products contrast keeps them."""
    base = _synthetic(n=16)
    shared = tuple(f"p{i}" for i in range(16))  # the same 16 products in every stream, in another order
    streams = Streams(
        base.names,
        [base.vectors[0][np.roll(np.arange(16), j)] for j in range(3)],
        base.context,
        [base.success[0][np.roll(np.arange(16), j)] for j in range(3)],
        [tuple(np.roll(np.array(shared), j)) for j in range(3)],
        base.readings,
    )
    by_key = {
        np.asarray(v, np.float32).tobytes(): p
        for s in range(3)
        for v, p in zip(streams.vectors[s], streams.products[s], strict=True)
    }
    seen_priors: list[tuple[set[str], set[str]]] = []

    def spy(vectors, context, success, products, *args, **kwargs):
        prior = args[6]
        if prior is not None:
            learnt = {by_key[np.asarray(r[:DIM], np.float32).tobytes()] for r in prior[0]}
            seen_priors.append((learnt, set(products)))
        return replay_stream(vectors, context, success, products, *args, **kwargs)

    report = _report(streams, spy)
    overlapping = [learnt & decided for learnt, decided in seen_priors if learnt & decided]
    # only the contrast condition (the fleet whole, at the tree's α, one per stream) may hold them
    assert len(overlapping) == 3
    assert report["fleet"]["prior_rows"] == [0, 0, 0]  # every product of the stream was in the others
    assert report["fleet"]["prior_rows_removed"] == [32, 32, 32]


def test_a_close_neighbour_in_the_prior_helps_and_a_misleading_one_does_not() -> None:
    honest = _report(_synthetic())
    row = honest["fleet"]["targets"]["0.15"]
    assert honest["fleet"]["nearest_similarity"]["p10"] > 0.9  # every unseen product has a close neighbour
    assert row["fleet"]["success_rate"] >= row["cold"]["success_rate"] + 0.1, row
    assert row["fleet"]["keeps_promise"], row
    assert honest["verdict"]["at_default"]["fleet_helps"]

    lying = _report(_synthetic(twins_lie=True))
    row = lying["fleet"]["targets"]["0.15"]
    assert row["fleet"]["success_rate"] < row["cold"]["success_rate"], row
    assert not lying["verdict"]["at_default"]["fleet_helps"]
    # the neighbour's outcome agrees with the decision's in the honest streams, not in the lying ones
    assert honest["fleet"]["similar_outcome_agrees"] > 0.9 > lying["fleet"]["similar_outcome_agrees"]


def test_nearest_seen_measures_zeta_and_size() -> None:
    ctx = _context(2)
    ctx[1, CONTEXT_FIELDS.index("detected_width_m")] = 0.06
    prior = Prior(np.hstack([np.eye(2, DIM), ctx]), np.array([True, False]), ("a", "b"))
    query = np.zeros((1, DIM))
    query[0, :2] = (1.0, 0.2)
    near = nearest_seen(query, _context(1), prior, DIM)
    assert near.similarity[0] == pytest.approx(1.0 / np.hypot(1.0, 0.2))
    assert near.similar_success.tolist() == [1.0]
    assert near.size_mm[0] == 0.0  # prior row 0 is perceived exactly alike
    assert near.size_success.tolist() == [1.0]
    query[0, :2] = (0.1, 1.0)  # now nearest to row 1 in ζ, still to row 0 in size
    near = nearest_seen(query, _context(1), prior, DIM)
    assert (near.similar_success[0], near.size_success[0]) == (0.0, 1.0)
    assert outcome_rates(np.array([1, 0, -1, 1]))["attempt_failure_rate"] == round(1 / 3, 4)


def test_scone_bench_gate_unseen_is_in_the_report_and_repeats(tmp_path: Path) -> None:
    repo = Path(__file__).resolve().parents[2]
    folder = tmp_path / "sc"
    folder.mkdir()
    for name in ("p00_nominal", "p07_rushed_planner"):
        lines = (repo / "tools" / "data" / "sc" / f"{name}.csv").read_text().splitlines()
        (folder / f"{name}.csv").write_text("\n".join(lines[:17]) + "\n")
    argv = [
        "gate",
        "--datasets",
        str(folder),
        "--embedder",
        "onehot",
        "--warmup",
        "3",
        "--no-sweep",
        "--unseen",
    ]
    outs = []
    for k in range(2):
        path = tmp_path / f"r{k}.json"
        assert main([*argv, "--quiet", "--json", str(path)]) == 0
        outs.append(json.loads(path.read_text())["unseen"])
    assert outs[0] == outs[1]
    assert set(outs[0]["fleet"]["targets"]) == {"0.1", "0.15", "0.2"}
    assert {"cold", "own_store", "fleet", "fleet_and_own_store"} <= set(
        outs[0]["own_store"]["targets"]["0.15"]
    )
