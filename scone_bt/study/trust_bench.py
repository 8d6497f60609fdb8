"""``scone-bench trust``: the trust-transfer model (trust_transfer.py) on Soh et al.'s human ratings, on the paper's
two splits, beside the paper's own models.

For each domain (household, driving) and split (participants: 10 folds of 3 held-out participants; tasks: 12
folds, one held-out task each), the model is fitted on every rating outside the fold and predicts the fold's
ratings; MAE and NLL (Bernoulli cross-entropy) on the sigmoid(rating - 3.5) scale are averaged over folds, as the
paper's notebook does. The baselines are the paper's saved results (tools/data/trust/paper_results.json, converted
from its code/results/*.pkl); every fold's test targets are checked to equal the saved ones, so the splits are the
paper's. Target: our MAE <= the paper's GP's on both splits in both domains.

    scone-bench trust --json tools/data/trust/bench_trust.json
    scone-bench trust --write        # also refit on all household ratings -> scone_bt/study/trust_fitted.json
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from scone_bt.errors import SconeError

__all__ = ["register", "evaluate_split", "PAPER_RESULTS", "BASELINES"]

PAPER_RESULTS = Path(__file__).resolve().parents[2] / "tools" / "data" / "trust" / "paper_results.json"
BASELINES: tuple[str, ...] = ("constant", "gp", "pmgp", "pogp", "lineargaussian", "rnn")
"""The paper's models in its saved results: constant mean, GP (constant-mean), GP with a prior mean function
(PMGP), GP with pseudo-observations (POGP), linear Gaussian, and its RNN."""


def evaluate_split(
    data, vectors: np.ndarray, kind: str, l2: float = 1.0, saved_targets: list[list[float]] | None = None
) -> dict[str, float]:  # data: TrustDataset
    """Mean over folds of MAE and NLL of the model fitted outside each fold."""
    from scone_bt.study.trust_transfer import CLIP, fit_vector, paper_splits, predict_rows, rows_of

    rows = rows_of(data)
    sim = vectors @ vectors.T
    maes, nlls = [], []
    for f, test in enumerate(paper_splits(data, kind)):
        held = rows.take(test)
        if saved_targets is not None and not np.allclose(held.target, saved_targets[f], atol=1e-5):
            raise SconeError(f"trust bench: {data.domain} {kind} fold {f} is not the paper's split")
        train = rows.take(sorted(set(range(len(rows))) - set(test)))
        p = np.clip(predict_rows(fit_vector(sim, train, l2), sim, held), *CLIP)
        y = held.target
        maes.append(float(np.mean(np.abs(p - y))))
        nlls.append(float(-np.mean(y * np.log(p) + (1 - y) * np.log(1 - p))))
    return {"mae": round(float(np.mean(maes)), 4), "nll": round(float(np.mean(nlls)), 4), "folds": len(maes)}


def _baselines(saved: dict) -> dict:
    out = {}
    for name in BASELINES:
        out[name] = {
            split: {
                "mae": round(float(np.mean([f["mae"] for f in saved[name][split]["folds"]])), 4),
                "nll": round(float(np.mean([f["nll"] for f in saved[name][split]["folds"]])), 4),
                "source": saved[name][split]["file"],
            }
            for split in ("participants", "tasks")
        }
    return out


def _bench(args: argparse.Namespace) -> int:
    from scone_bt.embedding import load_embedder
    from scone_bt.reporting import emit_report
    from scone_bt.study.trust_data import DOMAINS, load_trust_data
    from scone_bt.study.trust_transfer import FITTED_PARAMETERS, fit_transfer

    start = time.perf_counter()
    paper = json.loads(PAPER_RESULTS.read_text())
    embedder = load_embedder(args.embedder)
    report: dict = {
        "embedder": args.embedder,
        "l2": args.l2,
        "metric": "mean over folds; trust = sigmoid(rating - 3.5); predictions clipped to [0.01, 0.99]",
        "paper_results": f"{paper['source']}@{paper['commit'][:7]}: code/results/*.pkl via {PAPER_RESULTS.name}",
    }
    met = True
    for domain in DOMAINS:
        data = load_trust_data(domain)
        vectors = embedder.embed([data.tasks[t].text for t in sorted(data.tasks)]).astype(float)
        saved = paper["results"][domain]
        ours = {
            kind: evaluate_split(
                data, vectors, kind, args.l2, [f["target"] for f in saved["gp"][kind]["folds"]]
            )
            for kind in ("participants", "tasks")
        }
        base = _baselines(saved)
        ok = all(ours[k]["mae"] <= base["gp"][k]["mae"] for k in ours)
        met = met and ok
        report[domain] = {
            "participants_n": data.participants,
            **ours,
            "baselines": base,
            "mae_at_most_gp": ok,
            "fitted_all": json.loads(fit_transfer(data, vectors, args.l2, args.embedder).to_json()),
        }
    report["target"] = "our MAE <= the paper's GP MAE on both splits in both domains"
    report["target_met"] = met
    report["wall_s"] = round(time.perf_counter() - start, 2)
    if args.write:
        FITTED_PARAMETERS.write_text(json.dumps(report["household"]["fitted_all"], indent=1) + "\n")
        report["written"] = str(FITTED_PARAMETERS)
    emit_report(report, args.json)
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``trust`` to ``scone-bench``."""
    b = sub.add_parser(
        "trust", help="trust transfer through ζ fitted to human ratings, on the paper's splits"
    )
    b.add_argument("--embedder", default="minilm", help="ζ (a load_embedder name)")
    b.add_argument("--l2", type=float, default=1.0, help="L2 penalty on the prior's anchor weights")
    b.add_argument(
        "--write", action="store_true", help="write the household fit to scone_bt/study/trust_fitted.json"
    )
    b.add_argument("--json", help="also write the JSON report to this file")
    b.set_defaults(func=_bench)
