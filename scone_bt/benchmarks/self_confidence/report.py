"""Writing Algorithm 1's results: a Markdown table in the paper's Table I layout, a JSON of every number, a PNG."""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from scone_bt.benchmarks.self_confidence.dataset import Dataset
from scone_bt.benchmarks.self_confidence.evaluate import PairResult
from scone_bt.config import Catalogue

__all__ = ["dataset_summary", "markdown_tables", "outcome_structure", "plot_learning_curves", "write_json"]

_METRICS = (
    ("auc", "Normalised area under the learning curve (the paper's metric; higher is better)", True),
    ("final_accuracy", "Accuracy at the largest n_train (higher is better)", True),
    ("auroc", "AUROC at the largest n_train, test rows of all datasets pooled (higher is better)", True),
    ("brier", "Brier score at the largest n_train, pooled (lower is better)", False),
    ("ece", "Expected calibration error (10 bins) at the largest n_train, pooled (lower is better)", False),
)


def dataset_summary(datasets: Sequence[Dataset]) -> list[dict[str, Any]]:
    """Per dataset: rows, success rate, distinct actions and failures by stage."""
    out = []
    for d in datasets:
        stages: dict[str, int] = {}
        for ok, stage in zip(d.success, d.failure_stages, strict=True):
            if not ok:
                stages[stage or "unknown"] = stages.get(stage or "unknown", 0) + 1
        out.append(
            {
                "name": d.name,
                "rows": len(d),
                "success_rate": round(d.success_rate, 4),
                "distinct_actions": len(set(d.actions)),
                "failures_by_stage": dict(sorted(stages.items())),
            }
        )
    return out


def outcome_structure(datasets: Sequence[Dataset], catalogue: Catalogue | None = None) -> dict[str, Any]:
    """How much of each dataset's outcomes the object explains, and how they correlate with its properties.

    object_r2 is 1 − (within-object variance of the outcome) / (total variance): 1 when the object alone
    decides the outcome, 0 when it carries no information. The correlations are Pearson coefficients between the
    outcome (1 = success) and the object's mass, grasp width, height and surface friction, over rows whose object
    is in the catalogue. object_oracle_accuracy is the accuracy of predicting each object's majority outcome
    in this dataset (in-sample): a ceiling for any estimator that sees only the action text.
    """
    out: dict[str, Any] = {}
    for d in datasets:
        y = d.success.astype(float)
        entry: dict[str, Any] = {"object_r2": None, "per_object_success": {}}
        total = float(np.var(y)) if len(y) else 0.0
        objects = sorted(set(d.objects))
        within = 0.0
        majority = 0
        for name in objects:
            mask = np.array([o == name for o in d.objects])
            within += float(np.var(y[mask])) * mask.sum()
            majority += int(max(y[mask].sum(), mask.sum() - y[mask].sum()))
            entry["per_object_success"][name] = [int(y[mask].sum()), int(mask.sum())]
        entry["object_oracle_accuracy"] = round(majority / len(y), 4) if len(y) else None
        if total > 0:
            entry["object_r2"] = round(1.0 - within / len(y) / total, 4)
        if catalogue is not None:
            known = {o.name: o for o in catalogue.objects}
            rows = [i for i, o in enumerate(d.objects) if o in known]
            if len(rows) > 2 and np.var(y[rows]) > 0:
                props = {
                    "mass": [known[d.objects[i]].mass for i in rows],
                    "grasp_width": [known[d.objects[i]].grasp_width for i in rows],
                    "height": [known[d.objects[i]].height for i in rows],
                    "friction": [known[d.objects[i]].friction for i in rows],
                }
                entry["correlation"] = {
                    k: round(float(np.corrcoef(v, y[rows])[0, 1]), 4) if np.var(v) > 0 else None
                    for k, v in props.items()
                }
        out[d.name] = entry
    return out


def _cell(values: Sequence[float], best: bool) -> str:
    v = np.asarray(values, dtype=float)
    if np.all(np.isnan(v)):
        return "n/a"
    text = f"{np.nanmean(v):.2f} ± {np.nanstd(v):.2f}"
    return f"**{text}**" if best else text


def markdown_tables(
    results: Sequence[PairResult], embedders: Sequence[str], estimators: Sequence[str]
) -> str:
    """One table per metric: rows are embedders, columns estimators; the best cell of each column in bold."""
    by = {(r.embedder, r.estimator): r for r in results}
    parts = []
    for key, title, higher in _METRICS:
        parts.append(f"**{title}**\n")
        parts.append("| Embedding | " + " | ".join(estimators) + " |")
        parts.append("|---|" + "---|" * len(estimators))
        best: dict[str, str] = {}
        for est in estimators:
            scored = [(np.nanmean(getattr(by[e, est], key)), e) for e in embedders if (e, est) in by]
            scored = [(v, e) for v, e in scored if not np.isnan(v)]
            if scored:
                best[est] = (max if higher else min)(scored)[1]
        for emb in embedders:
            cells = [
                _cell(getattr(by[emb, est], key), best.get(est) == emb) if (emb, est) in by else "–"
                for est in estimators
            ]
            parts.append(f"| {emb} | " + " | ".join(cells) + " |")
        parts.append("")
    return "\n".join(parts)


def plot_learning_curves(
    results: Sequence[PairResult],
    embedders: Sequence[str],
    estimators: Sequence[str],
    path: Path,
    prior: PairResult | None = None,
) -> Path:
    """One panel per estimator, one line (± std band) per embedder; the prior baseline dashed."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    by = {(r.embedder, r.estimator): r for r in results}
    cols = min(4, len(estimators))
    rows = int(np.ceil(len(estimators) / cols))
    fig, axes = plt.subplots(
        rows, cols, figsize=(3.6 * cols, 2.9 * rows), sharex=True, sharey=True, squeeze=False
    )
    colours = plt.get_cmap("tab10")
    for i, est in enumerate(estimators):
        ax = axes[i // cols][i % cols]
        for j, emb in enumerate(embedders):
            r = by.get((emb, est))
            if r is None:
                continue
            m, s = np.array(r.curve_mean), np.array(r.curve_std)
            ax.plot(r.steps, m, marker="o", ms=3, color=colours(j), label=f"{emb} ({np.mean(r.auc):.2f})")
            ax.fill_between(r.steps, m - s, m + s, color=colours(j), alpha=0.15)
        if prior is not None:
            ax.plot(
                prior.steps,
                prior.curve_mean,
                ls="--",
                color="grey",
                label=f"prior ({np.mean(prior.auc):.2f})",
            )
        ax.set_title(est)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=6, loc="lower right")
        if i % cols == 0:
            ax.set_ylabel("test accuracy")
        if i // cols == rows - 1:
            ax.set_xlabel("n_train")
    for k in range(len(estimators), rows * cols):
        axes[k // cols][k % cols].axis("off")
    fig.suptitle(
        "Self-confidence learning curves (mean ± std over shuffles; legend: normalised AUC)", fontsize=9
    )
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def write_json(path: Path, payload: dict[str, Any]) -> Path:
    """Write `payload` as indented JSON (NaN becomes null)."""

    def clean(obj: Any) -> Any:
        if isinstance(obj, float) and np.isnan(obj):
            return None
        if isinstance(obj, dict):
            return {k: clean(v) for k, v in obj.items()}
        if isinstance(obj, list | tuple):
            return [clean(v) for v in obj]
        return obj

    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(clean(payload), indent=1) + "\n")
    return path
