"""Trust transfer through ζ: the paper's splits, recovery of known parameters, transfer by similarity, the fit."""

from __future__ import annotations

import json

import numpy as np
import pytest

from scone_bt.study.trust_bench import PAPER_RESULTS, evaluate_split
from scone_bt.trust.data import load_trust_data
from scone_bt.trust.transfer import (
    Observation,
    TransferModel,
    TrustRows,
    fit_transfer,
    fit_vector,
    load_fitted,
    paper_splits,
    predict_rows,
    rows_of,
)


@pytest.mark.parametrize("domain", ["household", "driving"])
@pytest.mark.parametrize("kind", ["participants", "tasks"])
def test_splits_are_the_papers(domain: str, kind: str) -> None:
    """Every fold's test ratings equal, in order, the targets the paper's saved results hold."""
    data = load_trust_data(domain)
    rows = rows_of(data)
    saved = json.loads(PAPER_RESULTS.read_text())["results"][domain]["gp"][kind]["folds"]
    folds = list(paper_splits(data, kind))
    assert len(folds) == len(saved) == (10 if kind == "participants" else 12)
    for test, fold in zip(folds, saved, strict=True):
        np.testing.assert_allclose(rows.take(test).target, fold["target"], atol=1e-6)


def _synthetic_rows(theta: np.ndarray, sim: np.ndarray, n: int, seed: int) -> TrustRows:
    """The paper's design (two tasks of one category seen, both succeed or both fail; three rated before and after)
    with ratings ~ Beta whose mean is the model's trust."""
    rng = np.random.default_rng(seed)
    task, obs, succ, who = [], [], [], []
    for p in range(n):
        cat = rng.integers(2)
        seen = rng.choice(np.arange(6) + 6 * cat, 2, replace=False)
        rated = rng.choice(12, 3, replace=False)
        s = float(rng.integers(2))
        for after in (False, True):
            for t in rated:
                task.append(t)
                obs.append(seen if after else [-1, -1])
                succ.append(s)
                who.append(p)
    rows = TrustRows(np.array(task), np.array(obs), np.array(succ), np.zeros(len(task)), np.array(who))
    p = predict_rows(theta, sim, rows)
    y = rng.beta(20 * p, 20 * (1 - p))
    return TrustRows(rows.task, rows.observed, rows.success, y, rows.participant)


def test_fit_recovers_known_parameters() -> None:
    rng = np.random.default_rng(3)
    base = rng.normal(size=(2, 16))
    vec = np.repeat(base, 6, axis=0) + 0.8 * rng.normal(size=(12, 16))  # two categories of similar tasks
    vec /= np.linalg.norm(vec, axis=1, keepdims=True)
    sim = vec @ vec.T
    weights = np.array([0.4, -0.3, 0.2, 0.0, -0.1, 0.3, -0.4, 0.1, 0.2, -0.2, 0.0, 0.3])
    truth = np.concatenate([[0.6, np.log(1.5), np.log(2.2), np.log(0.5)], weights])
    fit = fit_vector(sim, _synthetic_rows(truth, sim, 3000, seed=1), l2=0.0)
    np.testing.assert_allclose(fit[:4], truth[:4], atol=0.05)  # bias, log gains, log length scale
    # The anchor weights are identified only up to what the 12 cosines can tell apart: compare the priors.
    np.testing.assert_allclose(sim @ fit[4:] + fit[0], sim @ weights + truth[0], atol=0.1)


def test_failure_transfers_by_similarity() -> None:
    model = TransferModel(load_fitted())
    targets = ["Put the glass bottle on table", "Put the bag of rice on table"]
    before = model.logit(targets, [])
    after = model.logit(targets, [Observation("Put the glass jar on table", success=False)])
    drop = before - after
    assert drop[0] > drop[1] > 0
    gained = model.logit(targets, [Observation("Put the glass jar on table", success=True)]) - before
    assert gained[0] > gained[1] > 0


def test_committed_fit_is_the_household_fit() -> None:
    """scone_bt/trust/fitted.json is what fitting the vendored ratings gives now (not a stale file)."""
    from scone_bt.embedding import load_embedder

    data = load_trust_data("household")
    vectors = load_embedder("minilm").embed([data.tasks[t].text for t in sorted(data.tasks)]).astype(float)
    fresh, saved = fit_transfer(data, vectors), load_fitted()
    assert fresh.anchors == saved.anchors
    for name in ("bias", "success_gain", "failure_loss", "length_scale", "disposition_sd"):
        assert getattr(fresh, name) == pytest.approx(getattr(saved, name), abs=1e-3), name
    np.testing.assert_allclose(fresh.anchor_weights, saved.anchor_weights, atol=1e-3)


def test_household_beats_the_papers_gp_on_both_splits() -> None:
    from scone_bt.embedding import load_embedder

    data = load_trust_data("household")
    vectors = load_embedder("minilm").embed([data.tasks[t].text for t in sorted(data.tasks)]).astype(float)
    saved = json.loads(PAPER_RESULTS.read_text())["results"]["household"]["gp"]
    for kind in ("participants", "tasks"):
        ours = evaluate_split(data, vectors, kind)
        gp = np.mean([f["mae"] for f in saved[kind]["folds"]])
        assert ours["mae"] <= gp, kind


def test_scone_bench_trust_prints_the_issues_keys(tmp_path, capsys) -> None:
    from scone_bt.cli.bench import main

    out = tmp_path / "trust.json"
    assert main(["trust", "--json", str(out)]) == 0
    report = json.loads(out.read_text())
    assert json.loads(capsys.readouterr().out) == report
    for domain in ("household", "driving"):
        d = report[domain]
        for split in ("participants", "tasks"):
            assert 0 < d[split]["mae"] < 0.5 and 0 < d[split]["nll"] < 1
            for name in ("constant", "gp"):
                base = d["baselines"][name][split]
                assert {"mae", "nll", "source"} <= set(base) and base["source"].startswith("code/results/")
    assert report["target_met"] is True
