"""Writing the self-confidence evaluation: the JSON (NaN as null), Markdown tables (Table I layout, every protocol,
the ε-greedy robots, the targets) and PNGs (learning curves per protocol, reliability diagrams).

The research story is data, not code: the targets, their thresholds and the titles are report_text/report.yaml,
the prose is report_text/*.md (string.Template); this module computes the numbers and tables and fills them in."""

from __future__ import annotations

import functools
from collections.abc import Iterable, Mapping, Sequence
from importlib import resources
from pathlib import Path
from string import Template
from typing import Any, cast

import numpy as np
import yaml

from scone_bt.benchmarks.self_confidence.evaldata import UNKNOWN_FAMILY, EvalDataset
from scone_bt.benchmarks.self_confidence.metrics import ece_noise_floor
from scone_bt.benchmarks.self_confidence.protocols import (
    EvalOptions,
    algorithm1_split,
    novel_product_rows,
    row_order,
)
from scone_bt.benchmarks.self_confidence.report_types import (
    DatasetSummary,
    EvaluationReport,
    MeanStd,
    ProtocolEntry,
    RobotSummary,
    TargetCheck,
)
from scone_bt.files import write_atomic, write_via
from scone_bt.strict_json import clean_json, dumps

__all__ = [
    "PAPER_TABLE_I",
    "SEMANTIC_EMBEDDERS",
    "dataset_summary",
    "evaluation_markdown",
    "paired_difference",
    "plot_curves",
    "plot_reliability",
    "report_data",
    "target_checks",
    "write_json",
]

SEMANTIC_EMBEDDERS = ("minilm", "mpnet", "mpnet-ft")
"""Sentence embedders (GloVe is the word-vector baseline, one-hot the per-action one)."""
ORACLE = "oracle-attributes"
"""evaluate.ORACLE_EMBEDDER: true product attributes, reported as the ungrounded ceiling, never as a pair."""
_TEXT = "report_text"
"""Folder beside this module: report.yaml (targets, titles) and the Markdown templates (string.Template)."""


@functools.cache
def _text(name: str) -> str:
    """A file of report_text/, read once (importlib.resources: works from a wheel as from the source tree)."""
    return resources.files(__package__).joinpath(_TEXT, name).read_text(encoding="utf-8")


@functools.cache
def report_data() -> dict[str, Any]:
    """report_text/report.yaml: the paper's Table I number, the targets, protocol and metric titles."""
    return yaml.safe_load(_text("report.yaml"))


def _fill(template: str, **values: object) -> str:
    """report_text/<template> with its ${placeholders} filled (a missing one is a KeyError, not a blank)."""
    return Template(_text(template)).substitute(values)


def _lines(lines: Iterable[str]) -> str:
    """Table lines for a template: each ends with a newline (none at all: nothing)."""
    return "".join(f"{line}\n" for line in lines)


PAPER_TABLE_I: dict[str, Any] = report_data()["paper_table_i"]
"""The paper's self-confidence number as this repository quotes it (its best estimator, ε-KNN: 0.81)."""
_PROTOCOL_TITLES: dict[str, str] = report_data()["protocol_titles"]


def _target(key: str, met: bool, measured: str, **numbers: object) -> TargetCheck:
    """One check of report.yaml's target `key`: its label filled with the target's own numbers."""
    spec = report_data()["targets"][key]
    label = spec["label"].format(**{k: v for k, v in spec.items() if k != "label"}, **numbers)
    return TargetCheck(target=label, measured=measured, met=bool(met))


def _threshold(key: str) -> float:
    return float(report_data()["targets"][key]["threshold"])


def write_json(path: Path | None, payload: Mapping[str, Any]) -> dict[str, Any]:
    """Write `payload` as indented JSON (NaN becomes null) if `path` is given; returns the cleaned payload."""
    cleaned = clean_json(payload)
    if path is not None:
        path.parent.mkdir(parents=True, exist_ok=True)
        write_atomic(path, dumps(cleaned, indent=1) + "\n")
    return cleaned


def _oracle(keys: Sequence[str], y: np.ndarray) -> float:
    """In-sample accuracy of predicting each key's majority outcome (a ceiling for a model of that key alone)."""
    right = 0
    for k in set(keys):
        m = np.array([x == k for x in keys])
        right += int(max(y[m].sum(), m.sum() - y[m].sum()))
    return round(right / len(y), 4) if len(y) else float("nan")


def dataset_summary(
    datasets: Sequence[EvalDataset], options: EvalOptions | None = None
) -> list[DatasetSummary]:
    """Per dataset: rows, success rate, distinct products and families, novel test rows, context coverage.

    product_oracle / family_oracle: in-sample accuracy of predicting each product's / family's majority outcome.
    """
    opts = options or EvalOptions()
    out: list[DatasetSummary] = []
    for d in datasets:
        entry: DatasetSummary = {
            "name": d.name,
            "rows": len(d),
            "success_rate": round(float(d.success.mean()), 4) if len(d) else None,
            "distinct_products": len(set(d.objects)),
            "families": len(set(d.families) - {UNKNOWN_FAMILY}),
            "context_coverage": round(float(np.mean(~np.isnan(d.context))), 4) if len(d) else 0.0,
            "product_oracle": _oracle(d.objects, d.success),
            "family_oracle": _oracle(d.families, d.success),
        }
        if len(d) >= opts.min_rows:
            prefix, test = algorithm1_split(row_order(len(d), 0, 0), opts)
            entry["novel_test_rows"] = len(novel_product_rows(d.objects, prefix, test))
        out.append(entry)
    return out


# ----------------------------------------------------------------------------------------------- tables
def _by(report: EvaluationReport, protocol: str) -> dict[tuple[str, str], ProtocolEntry]:
    return {(r["embedder"], r["estimator"]): r for r in report["protocols"].get(protocol, [])}


_Metric = MeanStd | float | None
"""A metric's value in an entry: mean ± std over datasets (auc, final_accuracy, greedy_auc) or one pooled number."""


def _metric(entry: ProtocolEntry | RobotSummary, key: str) -> _Metric:
    """`entry[key]` for a metric key of report.yaml (or greedy_auc of a robot)."""
    value: _Metric = cast(Mapping[str, _Metric], entry)[key]
    return value


def _ms(entry: ProtocolEntry | RobotSummary | None, key: str = "auc") -> float:
    if entry is None:
        return float("nan")
    v = _metric(entry, key)
    v = v["mean"] if isinstance(v, dict) else v
    return float("nan") if v is None else float(v)


def _fmt(entry: ProtocolEntry | RobotSummary | None, key: str, bold: bool = False) -> str:
    if entry is None:
        return "–"
    v = _metric(entry, key)
    if isinstance(v, dict):
        if v["mean"] is None:
            return "n/a"
        text = f"{v['mean']:.2f} ± {v['std']:.2f}"
    else:
        text = "n/a" if v is None else f"{v:.3f}"
    return f"**{text}**" if bold else text


def _metric_table(report: EvaluationReport, protocol: str, key: str, higher: bool) -> str:
    """One metric's table (embedders × estimators, the best per column in bold) and the prior under it."""
    by = _by(report, protocol)
    embedders, estimators = report["embedders"], report["estimators"]
    lines = ["| Embedding | " + " | ".join(estimators) + " |", "|---|" + "---|" * len(estimators)]
    best = {}
    for k in estimators:
        scored = [(_ms(by.get((e, k)), key), e) for e in embedders]
        scored = [(v, e) for v, e in scored if not np.isnan(v)]
        if scored:
            best[k] = (max if higher else min)(scored)[1]
    for e in embedders:
        cells = [_fmt(by.get((e, k)), key, best.get(k) == e) for k in estimators]
        lines.append(f"| {e} | " + " | ".join(cells) + " |")
    prior = report.get("prior", {}).get(protocol)
    return _lines(lines) + ("" if prior is None else _fill("prior.md", prior=_fmt(prior, key)))


def _best(
    report: EvaluationReport, protocol: str, embedders: Sequence[str], grounded: bool = True
) -> ProtocolEntry | None:
    rows = [r for r in report["protocols"].get(protocol, []) if r["embedder"] in embedders]
    if not grounded:
        rows = [r for r in rows if not r["estimator"].startswith("grounded-")]
    rows = [r for r in rows if not np.isnan(_ms(r))]
    return max(rows, key=_ms) if rows else None


def _floor_note(row: ProtocolEntry) -> str:
    """The noise-floor remark for a row with an ece_noise_floor (older reports have none)."""
    floor = row.get("ece_noise_floor")
    if not floor or floor.get("mean") is None:
        return ""
    return (
        f" (noise floor: a perfectly calibrated predictor with these {row['n_test']} predictions scores "
        f"{floor['mean']:.3f} on average, 95th percentile {floor['p95']:.3f})"
    )


def paired_difference(
    a: ProtocolEntry | None, b: ProtocolEntry | None, resamples: int = 10_000, seed: int = 0
) -> dict[str, float] | None:
    """Pair a − pair b in AUC, dataset by dataset: the mean, a 95 % bootstrap interval over datasets, the wins.

    Both entries must carry ``auc.per_dataset`` (each dataset's AUC, its shuffles averaged) over the same
    datasets (``auc.dataset_index``; every pair of one report has them); None otherwise (older reports). The
    interval resamples datasets with replacement (seeded): it says whether the datasets at hand can tell the two
    pairs apart.
    """

    def values(entry: ProtocolEntry | None) -> dict[int, float]:
        if entry is None or "auc" not in entry:
            return {}
        auc = entry["auc"]
        per = auc.get("per_dataset") or []
        index = auc.get("dataset_index") or list(range(len(per)))
        return {int(i): float("nan") if v is None else float(v) for i, v in zip(index, per, strict=False)}

    va, vb = values(a), values(b)
    if not va or set(va) != set(vb):
        return None
    pairs = np.array([(va[i], vb[i]) for i in sorted(va)])
    pairs = pairs[~np.isnan(pairs[:, 0] - pairs[:, 1])]
    if len(pairs) == 0:
        return None
    d = pairs[:, 0] - pairs[:, 1]
    if len(d) == 1:  # scipy needs two observations; every resample of one is that one
        lo = hi = float(d[0])
    else:
        from scipy import stats  # here, not at import: scone-bench --help registers this module

        # percentile interval: resamples whole datasets (paired), the seeded Generator draws them
        ci = stats.bootstrap(
            (pairs[:, 0], pairs[:, 1]),
            lambda x, y, axis=-1: np.mean(x - y, axis=axis),
            paired=True,
            vectorized=True,
            n_resamples=resamples,
            method="percentile",
            confidence_level=0.95,
            rng=np.random.default_rng(seed),
        ).confidence_interval
        lo, hi = ci.low, ci.high
    return {
        "mean": float(d.mean()),
        "ci_low": float(lo),
        "ci_high": float(hi),
        "wins": int((d > 0).sum()),
        "ties": int((d == 0).sum()),
        "datasets": len(d),
    }


def _paired_note(a: ProtocolEntry | None, b: ProtocolEntry | None, what: str) -> str:
    p = paired_difference(a, b)
    if p is None:
        return ""
    return (
        f"; {what} {p['mean']:+.3f}, 95 % CI [{p['ci_low']:+.3f}, {p['ci_high']:+.3f}] over "
        f"{p['datasets']} datasets, higher on {p['wins']} ({p['ties']} ties)"
    )


def uniform_ece_floor(n: int, bins: int = 10) -> tuple[float, float]:
    """ECE noise floor of a calibrated predictor whose n predictions spread evenly over (0, 1)."""
    return ece_noise_floor((np.arange(n) + 0.5) / max(n, 1), bins)


def target_checks(report: EvaluationReport) -> list[TargetCheck]:
    """The issue's targets, each with the measured numbers and whether it is met.

    The embedding targets compare embedders under the paper's estimators (ungrounded: with the execution
    context a grounded κ̂ barely needs the action's meaning); the grounded and ECE targets take every pair.
    """
    return [*_semantic_checks(report), *_calibration_checks(report), *_time_checks(report)]


def _semantic_checks(report: EvaluationReport) -> list[TargetCheck]:
    """The embedding targets: the best semantic embedder, its gap over one-hot, the order, novel products."""
    checks: list[TargetCheck] = []
    a1 = _by(report, "algorithm1")
    semantic = [e for e in report["embedders"] if e in SEMANTIC_EMBEDDERS]
    best = _best(report, "algorithm1", semantic, grounded=False)
    if best is not None:
        one = a1.get(("onehot", best["estimator"]))
        gap = _ms(best) - _ms(one)
        checks.append(
            _target(
                "best_semantic",
                _ms(best) >= _threshold("best_semantic"),
                f"{best['embedder']} + {best['estimator']} {_ms(best):.3f}",
            )
        )
        checks.append(
            _target(
                "semantic_gap",
                gap >= _threshold("semantic_gap"),
                f"one-hot + {best['estimator']} {_ms(one):.3f}, gap {gap:+.3f}"
                + _paired_note(best, one, "paired gap"),
            )
        )
    for k in report_data()["targets"]["order"]["estimators"]:
        sem_entry = max((a1[(e, k)] for e in semantic if (e, k) in a1), key=_ms, default=None)
        sem = _ms(sem_entry)
        glove, onehot = _ms(a1.get(("glove", k))), _ms(a1.get(("onehot", k)))
        if sem_entry is not None and not any(np.isnan(v) for v in (sem, glove, onehot)):
            checks.append(
                _target(
                    "order",
                    sem > glove > onehot,
                    f"best semantic ({sem_entry['embedder']}) {sem:.3f}, GloVe {glove:.3f}, one-hot {onehot:.3f}"
                    + _paired_note(sem_entry, a1.get(("glove", k)), "semantic − GloVe")
                    + _paired_note(a1.get(("glove", k)), a1.get(("onehot", k)), "GloVe − one-hot"),
                    estimator=k,
                )
            )
    nbest = _best(report, "novel_products", semantic, grounded=False)
    prior = report.get("prior", {}).get("novel_products")
    if nbest is not None:
        one = _by(report, "novel_products").get(("onehot", nbest["estimator"]))
        checks.append(
            _target(
                "novel_products",
                _ms(nbest) >= _threshold("novel_products"),
                f"{nbest['embedder']} + {nbest['estimator']} {_ms(nbest):.3f}; one-hot {_ms(one):.3f}; "
                f"prior {_ms(prior):.3f}",
            )
        )
    return checks


def _calibration_checks(report: EvaluationReport) -> list[TargetCheck]:
    """The targets over every pair: calibration (ECE, raw and calibrated) and grounding."""
    checks: list[TargetCheck] = []
    robot_embedders = [e for e in report["embedders"] if e != ORACLE]  # the oracle is a ceiling, not a pair
    overall = _best(report, "algorithm1", robot_embedders)
    if overall is not None:
        checks.append(
            _target(
                "ece",
                _ms(overall, "ece") <= _threshold("ece"),
                f"{overall['embedder']} + {overall['estimator']} ECE {_ms(overall, 'ece'):.3f}"
                + _floor_note(overall),
            )
        )
        rows = [r for r in report["protocols"]["algorithm1"] if r["embedder"] != ORACLE]
        cal = next(
            (
                r
                for r in rows
                if r["estimator"] == f"{overall['estimator']}-cal" and r["embedder"] == overall["embedder"]
            ),
            None,
        )
        if cal is not None:
            checks.append(
                _target(
                    "ece_calibrated",
                    _ms(cal, "ece") <= _threshold("ece_calibrated"),
                    f"{cal['embedder']} + {cal['estimator']} ECE {_ms(cal, 'ece'):.3f}, AUC {_ms(cal):.3f}"
                    + _floor_note(cal),
                )
            )
        grounded = [r for r in rows if r["estimator"].startswith("grounded-")]
        plain = [r for r in rows if not r["estimator"].startswith("grounded-")]
        if grounded and plain:
            g, p = max(grounded, key=_ms), max(plain, key=_ms)
            checks.append(
                _target(
                    "grounded",
                    _ms(g) > _ms(p),
                    f"{g['embedder']} + {g['estimator']} {_ms(g):.3f} vs "
                    f"{p['embedder']} + {p['estimator']} {_ms(p):.3f}",
                )
            )
    return checks


def _time_checks(report: EvaluationReport) -> list[TargetCheck]:
    """The grid's time target (uncached: cells may come from the cache)."""
    checks: list[TargetCheck] = []
    timing = report.get("timing_s", {})
    if "cells_wall_s_sum" in timing:
        # cells may come from the cache: the uncached grid costs the sum of the cells' own times over the workers
        uncached = timing["cells_wall_s_sum"] / max(timing["workers"], 1) + timing["embedding"]
        limit = _threshold("grid_time")
        checks.append(
            _target(
                "grid_time",
                uncached <= limit,
                f"{uncached / 60:.1f} min uncached ({timing['cells']} cells, {timing['workers']} "
                f"workers, embedding {timing['embedding']:.0f} s of it; this run's wall time "
                f"{timing['total'] / 60:.1f} min)",
                minutes=limit / 60,
            )
        )
    return checks


def _robot_table(report: EvaluationReport) -> list[str]:
    a1 = _by(report, "algorithm1")
    rows = [r for r in report["protocols"].get("algorithm1", []) if r.get("robot")]
    if not rows:
        return []
    lines = [
        "| pair | belief AUC: X (all labels) | ε-X robot | greedy robot | labels ε / greedy | "
        "successes ε / greedy | help requests ε / greedy | regret ε / greedy |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        rb = r["robot"]
        base = a1.get((r["embedder"], r["estimator"].removeprefix("eps-")))
        e, g = rb["epsilon"], rb["greedy"]
        lines.append(
            f"| {r['embedder']} + {r['estimator']} | {_fmt(base, 'auc')} | {_fmt(r, 'auc')} | "
            f"{_fmt(rb, 'greedy_auc')} | {e['attempts']} / {g['attempts']} | {e['successes']} / {g['successes']} | "
            f"{e['help_requests']} / {g['help_requests']} | {e['regret']} / {g['regret']} |"
        )
    return lines


def evaluation_markdown(report: EvaluationReport, name: str = "self_confidence") -> str:
    """The whole evaluation as Markdown; the PNGs of plot_curves/plot_reliability are linked as <name>_*.png.

    The prose is report_text/*.md (string.Template), the targets and titles report_text/report.yaml: this
    function computes the tables and numbers and fills them in.
    """
    opts, timing = report["options"], report["timing_s"]
    targets = [
        f"| {c['target']} | {c['measured']} | {'yes' if c['met'] else '**no**'} |"
        for c in target_checks(report)
    ]
    ceiling = _best(report, "algorithm1", [ORACLE], grounded=False) if ORACLE in report["embedders"] else None
    table_i = ""
    if "algorithm1" in report["protocols"]:
        by = _by(report, "algorithm1")
        table_i = _fill(
            "table_i.md",
            rows=_lines(
                f"| {e} | {_fmt(by.get((e, 'lgbm')), 'auc')} | {_fmt(by.get((e, 'eps-knn')), 'auc')} |"
                for e in report["embedders"]
            ),
            best_estimator=PAPER_TABLE_I["best_estimator"],
            best_auc=f"{PAPER_TABLE_I['best_auc']:.2f}",
        )
    robot = _robot_table(report)
    return _fill(
        "page.md",
        data=report["data"],
        n_datasets=len(report["datasets"]),
        embedders=", ".join(report["embedders"]),
        skipped=f" (skipped: {', '.join(report['embedders_skipped'])})"
        if report["embedders_skipped"]
        else "",
        n_train=opts["n_train"],
        lofo_n_train=opts["lofo_n_train"],
        n_test=opts["n_test"],
        shuffles=opts["shuffles"],
        seed=opts["seed"],
        epsilon0=opts["epsilon0"],
        half_life=opts["half_life"],
        refit_every=opts["refit_every"],
        wall=f"{timing['total']:.0f}",
        workers=timing["workers"],
        targets=_lines(targets),
        ceiling=""
        if ceiling is None
        else _fill("ceiling.md", oracle=ORACLE, auc=f"{_ms(ceiling):.3f}", estimator=ceiling["estimator"]),
        table_i=table_i,
        protocols="".join(_protocol_section(report, protocol, name) for protocol in report["protocols"]),
        robot=_fill("robot.md", rows=_lines(robot)) if robot else "",
        datasets=_lines(
            f"| {d['name']} | {d['rows']} | {d['success_rate']} | {d['distinct_products']} | {d['families']} | "
            f"{d.get('novel_test_rows', '–')} | {d['context_coverage']:.2f} |"
            for d in report["datasets"]
        ),
        name=name,
    )


def _protocol_section(report: EvaluationReport, protocol: str, name: str) -> str:
    """One protocol: its AUC table, then one table per metric of report.yaml (ECE with its noise floor)."""
    rows = report["protocols"][protocol]
    metrics = ""
    for metric in report_data()["metrics"]:
        floor = ""
        if metric["key"] == "ece" and rows:
            mean, p95 = uniform_ece_floor(rows[0]["n_test"], report["options"]["ece_bins"])
            floor = _fill("ece_floor.md", n_test=rows[0]["n_test"], mean=f"{mean:.3f}", p95=f"{p95:.3f}")
        table = _metric_table(report, protocol, metric["key"], metric["higher"])
        metrics += _fill("metric.md", title=metric["title"], table=table, floor=floor)
    return _fill(
        "protocol.md",
        title=_PROTOCOL_TITLES.get(protocol, protocol),
        auc_table=_metric_table(report, protocol, "auc", True),
        pooled=_fill("pooled.md", n_test=rows[0]["n_test"]) if rows else "",
        metrics=metrics,
        name=name,
        protocol=protocol,
    )


# ----------------------------------------------------------------------------------------------- figures
def _pyplot():  # noqa: ANN202 - matplotlib's module
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _save_png(plt: Any, fig: Any, path: Path) -> None:
    """Save `fig` as a PNG at `path` through a temporary file beside it (an interrupted or failed write leaves the
    old figure whole, never half a PNG), and close it."""
    path.parent.mkdir(parents=True, exist_ok=True)
    try:
        write_via(path, lambda tmp: fig.savefig(tmp, dpi=100, format="png"))
    finally:
        plt.close(fig)


def plot_curves(report: EvaluationReport, out_dir: Path, name: str = "self_confidence") -> list[Path]:
    """One PNG per protocol (<out_dir>/<name>_<protocol>_curves.png): a panel per estimator, a line per embedder."""
    plt = _pyplot()
    paths = []
    estimators, embedders = report["estimators"], report["embedders"]
    colours = plt.get_cmap("tab10")
    for protocol in report["protocols"]:
        by = _by(report, protocol)
        cols = min(5, len(estimators))
        rows = int(np.ceil(len(estimators) / cols))
        fig, axes = plt.subplots(rows, cols, figsize=(3.2 * cols, 2.6 * rows), sharey=True, squeeze=False)
        prior = report.get("prior", {}).get(protocol)
        for i, k in enumerate(estimators):
            ax = axes[i // cols][i % cols]
            for j, e in enumerate(embedders):
                r = by.get((e, k))
                if r is None or r["accuracy_curve"]["mean"][0] is None:
                    continue
                c = r["accuracy_curve"]
                m = np.array(c["mean"], dtype=float)
                s = np.array(c["std"], dtype=float)
                ax.plot(c["n_train"], m, marker="o", ms=2.5, color=colours(j), label=f"{e} ({_ms(r):.2f})")
                ax.fill_between(c["n_train"], m - s, m + s, color=colours(j), alpha=0.12)
            if prior is not None and prior["accuracy_curve"]["mean"][0] is not None:
                c = prior["accuracy_curve"]
                ax.plot(c["n_train"], c["mean"], ls="--", color="grey", label=f"prior ({_ms(prior):.2f})")
            ax.set_title(k, fontsize=9)
            ax.grid(alpha=0.3)
            ax.legend(fontsize=5.5, loc="lower right")
            if i % cols == 0:
                ax.set_ylabel("test accuracy")
            if i // cols == rows - 1:
                ax.set_xlabel("n_train")
        for j in range(len(estimators), rows * cols):
            axes[j // cols][j % cols].axis("off")
        fig.suptitle(f"{_PROTOCOL_TITLES.get(protocol, protocol)}: accuracy ± std over datasets", fontsize=9)
        fig.tight_layout()
        path = Path(out_dir) / f"{name}_{protocol}_curves.png"
        _save_png(plt, fig, path)
        paths.append(path)
    return paths


def plot_reliability(report: EvaluationReport, path: Path) -> Path:
    """Reliability diagrams at the largest n_train: per protocol the best pair, one-hot with its estimator, prior."""
    plt = _pyplot()
    protocols = list(report["protocols"])
    fig, axes = plt.subplots(1, len(protocols), figsize=(3.6 * len(protocols), 3.4), squeeze=False)
    for ax, protocol in zip(axes[0], protocols, strict=True):
        best = _best(report, protocol, report["embedders"])
        shown: list[tuple[str, ProtocolEntry]] = []
        if best is not None:
            shown.append((f"{best['embedder']} + {best['estimator']}", best))
            one = _by(report, protocol).get(("onehot", best["estimator"]))
            if one is not None and one is not best:
                shown.append((f"onehot + {best['estimator']}", one))
        if report.get("prior", {}).get(protocol):
            shown.append(("prior", report["prior"][protocol]))
        ax.plot([0, 1], [0, 1], color="black", lw=0.8, ls=":")
        for j, (label, r) in enumerate(shown):
            bins = [b for b in r["reliability"] if b["count"]]
            x = [b["mean_predicted"] for b in bins]
            yv = [b["observed_rate"] for b in bins]
            sizes = [8 + 2 * b["count"] for b in bins]
            ece = r["ece"]
            ax.plot(
                x,
                yv,
                marker="o",
                ms=3,
                lw=1,
                color=f"C{j}",
                label=f"{label} (ECE {ece:.3f})" if ece is not None else label,
            )
            ax.scatter(x, yv, s=sizes, color=f"C{j}", alpha=0.3)
        ax.set_xlim(0, 1)
        ax.set_ylim(0, 1)
        ax.set_xlabel("predicted success probability")
        ax.set_ylabel("observed success rate")
        ax.set_title(protocol, fontsize=9)
        ax.legend(fontsize=6, loc="upper left")
        ax.grid(alpha=0.3)
    fig.tight_layout()
    _save_png(plt, fig, path)
    return path
