"""``scone-bench sc probe``: how much an action's text can tell κ̂ about the physics that decides its outcome.

    scone-bench sc probe --out docs/results                 # every installed embedder, the shipped datasets
    scone-bench sc probe --embedders minilm,mpnet --estimators rf --json probe.json

In these datasets an outcome is physics: the product is wider than the gripper opens, heavy, glass (a blind
camera), on a crowded tier. An ungrounded κ̂ sees only "Put X on table"; its embedding can help exactly as far as
the text X reveals those attributes. Two measurements say how far that is:

1. **Probes.** Every catalogue product's action text is embedded; K-fold cross-validation over products (seeded)
   fits a logistic probe for *wide* (grasp width above `wide_m`), *heavy* (mass ≥ `heavy_kg`), *glass* and the
   packaging family, and a ridge probe for width and mass. Each product's score comes from the fold that did not
   see it: AUROC, family accuracy, R². A probe learns from (K − 1)/K of the catalogue's labelled products (about
   670 of 841 at K = 5), far more attribute knowledge than κ̂ gets from 80 outcomes.
2. **Ceilings.** Algorithm 1 and the novel-products protocol (protocols.py, the same options and estimators as
   ``sc evaluate``) run with features instead of an embedding: the packaging family one-hot (a text model that
   knew every product's family), the true width, mass and glass flag, and, per embedder, those three as its
   probe predicts them out of fold (what a linear read-out of the text gives of them).

If the text-predicted ceiling sits where the semantic pairs of ``sc evaluate`` sit and far below the true
attributes', the accuracy an ungrounded κ̂ can reach is bounded by the names, not by the estimators.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np

from scone_bt.argparsing import path_arg
from scone_bt.benchmarks.self_confidence.evaldata import EvalDataset, load_eval_datasets
from scone_bt.benchmarks.self_confidence.evaluate import (
    DEFAULT_EMBEDDERS,
    check_embedder_names,
    check_report_files,
    split_names,
)
from scone_bt.benchmarks.self_confidence.protocols import EvalOptions, Protocol, evaluate_protocols
from scone_bt.errors import ConfigError

__all__ = [
    "AttributeProbe",
    "CEILING_ESTIMATORS",
    "ProbeOptions",
    "ProductAttributes",
    "probe_attributes",
    "probe_markdown",
    "product_attributes",
    "register_probe",
    "run_probe",
]

CEILING_ESTIMATORS = ("knn", "lgbm", "rf", "gp")
"""Estimators of the ceilings by default (the paper's KNN and LGBM, the forest and the GP)."""
_PROTOCOLS = (Protocol.ALGORITHM1, Protocol.NOVEL_PRODUCTS)


@dataclass(frozen=True)
class ProbeOptions:
    """Probe settings.

    Attributes:
        folds: K of the cross-validation over catalogue products.
        seed: Seeds the folds (the ceilings' estimators take EvalOptions.seed).
        wide_m: A product is wide above this grasp width, metres: the Panda's 8 cm opening less twice its 4 mm
            opening margin (robots/panda.yaml), the products its fingers cannot close around.
        heavy_kg: A product is heavy at or above this mass, kg: the payload limit of p10_payload_limit.
    """

    folds: int = 5
    seed: int = 0
    wide_m: float = 0.072
    heavy_kg: float = 0.45

    def __post_init__(self) -> None:
        if self.folds < 2:
            raise ConfigError(f"folds (--folds) must be at least 2, got {self.folds}")
        for name in ("wide_m", "heavy_kg"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value > 0):  # NaN too
                flag = "--" + name.replace("_", "-")
                raise ConfigError(f"{name} ({flag}) must be a positive number, got {value}")


@dataclass(frozen=True)
class ProductAttributes:
    """What decides an outcome, for every product of a catalogue (rows in `names` order).

    Attributes:
        names: Product names, sorted.
        width: Grasp width (narrowest horizontal extent), metres.
        mass: Kilograms.
        glass: True for glass products.
        family: Packaging family.
    """

    names: tuple[str, ...]
    width: np.ndarray
    mass: np.ndarray
    glass: np.ndarray
    family: tuple[str, ...]

    def rows(self, products: Sequence[str], source: str) -> np.ndarray:
        """Row index of each product; one missing from the catalogue is a ConfigError naming `source`."""
        row = {n: i for i, n in enumerate(self.names)}
        missing = sorted({p for p in products if p not in row})
        if missing:
            raise ConfigError(
                f"{source}: products not in the catalogue: {', '.join(missing[:5])}"
                + (f" (+{len(missing) - 5} more)" if len(missing) > 5 else "")
                + " (pass their catalogue files with --catalogue)"
            )
        return np.array([row[p] for p in products], dtype=int)


def product_attributes(kitchen: str = "kitchen", catalogues: Sequence[str | Path] = ()) -> ProductAttributes:
    """The attributes of every product in the kitchen's catalogue (plus `catalogues`)."""
    from scone_bt.config import load_kitchen

    specs = {o.name: o for o in load_kitchen(kitchen, catalogues).catalogue.objects}
    names = tuple(sorted(specs))
    return ProductAttributes(
        names=names,
        width=np.array([specs[n].grasp_width for n in names]),
        mass=np.array([specs[n].mass for n in names]),
        glass=np.array([specs[n].material == "glass" for n in names]),  # as evaluate.oracle_features reads it
        family=tuple(specs[n].family or "unknown" for n in names),
    )


@dataclass(frozen=True)
class AttributeProbe:
    """What one embedder's action texts reveal of the products' attributes (out-of-fold scores).

    Attributes:
        embedder: Embedder name.
        products: Catalogue products probed.
        wide_auroc: AUROC of the logistic probe for wide (0.5: the text says nothing).
        heavy_auroc: The same for heavy.
        glass_auroc: The same for glass.
        family_accuracy: Accuracy of the multinomial probe for the packaging family.
        family_majority: Accuracy of always naming the most common family (what the text must beat).
        width_r2: R² of the ridge probe for the grasp width (0: no better than the mean).
        mass_r2: The same for the mass.
    """

    embedder: str
    products: int
    wide_auroc: float
    heavy_auroc: float
    glass_auroc: float
    family_accuracy: float
    family_majority: float
    width_r2: float
    mass_r2: float


def _r2(pred: np.ndarray, true: np.ndarray) -> float:
    ss = float(((true - true.mean()) ** 2).sum())
    return float("nan") if ss == 0 else 1.0 - float(((pred - true) ** 2).sum()) / ss


def probe_attributes(
    embedder: str, vectors: np.ndarray, attrs: ProductAttributes, options: ProbeOptions = ProbeOptions()
) -> tuple[AttributeProbe, np.ndarray]:
    """Cross-validated probes of one embedder over the catalogue.

    Args:
        embedder: Its name (for the record).
        vectors: (len(attrs.names), d) embeddings of each product's action text.
        attrs: The catalogue's attributes.
        options: Folds, seed and the wide / heavy thresholds.

    Returns:
        The probe scores, and (n, 3) out-of-fold predictions per product: width (m), mass (kg), P(glass).
    """
    from sklearn.linear_model import LogisticRegression, RidgeCV
    from sklearn.metrics import roc_auc_score
    from sklearn.model_selection import KFold

    X = np.asarray(vectors, dtype=np.float64)
    n = len(attrs.names)
    if X.shape[0] != n:
        raise ConfigError(f"{embedder}: {X.shape[0]} vectors for {n} products")
    if n < options.folds:
        raise ConfigError(f"the catalogue has {n} products, fewer than the {options.folds} folds")
    labels = {
        "wide": attrs.width > options.wide_m,
        "heavy": attrs.mass >= options.heavy_kg,
        "glass": attrs.glass,
    }
    families = np.array(attrs.family)
    numeric = np.column_stack([attrs.width, attrs.mass])
    oof_p = {k: np.full(n, np.nan) for k in labels}
    oof_family = np.empty(n, dtype=object)
    oof_numeric = np.zeros((n, 2))
    folds = KFold(options.folds, shuffle=True, random_state=options.seed)
    for train, test in folds.split(X):
        for key, y in labels.items():
            if len(set(y[train])) < 2:
                # one class in training: the probe knows nothing; one constant for every such fold, so that
                # fold-to-fold base rates cannot rank the products (that would push the AUROC below 0.5)
                oof_p[key][test] = 0.5
                continue
            clf = LogisticRegression(C=1.0, max_iter=2000).fit(X[train], y[train])
            oof_p[key][test] = clf.predict_proba(X[test])[:, 1]
        if len(set(families[train])) > 1:
            fam = LogisticRegression(C=1.0, max_iter=2000).fit(X[train], families[train])
            oof_family[test] = fam.predict(X[test])
        else:
            oof_family[test] = families[train][0]
        ridge = RidgeCV(alphas=np.logspace(-3, 3, 13), alpha_per_target=True).fit(X[train], numeric[train])
        oof_numeric[test] = ridge.predict(X[test])

    def auc(key: str) -> float:
        y = labels[key]
        return float(roc_auc_score(y, oof_p[key])) if 0 < y.sum() < n else float("nan")

    _, counts = np.unique(families, return_counts=True)
    probe = AttributeProbe(
        embedder=embedder,
        products=n,
        wide_auroc=auc("wide"),
        heavy_auroc=auc("heavy"),
        glass_auroc=auc("glass"),
        family_accuracy=float(np.mean(oof_family == families)),
        family_majority=float(counts.max() / n),
        width_r2=_r2(oof_numeric[:, 0], attrs.width),
        mass_r2=_r2(oof_numeric[:, 1], attrs.mass),
    )
    return probe, np.column_stack([oof_numeric, oof_p["glass"]])


def _standardised(columns: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """`columns` scaled by the mean and std of `reference` (so true and predicted attributes share one scale)."""
    mu, sd = reference.mean(axis=0), reference.std(axis=0)
    return (columns - mu) / np.where(sd > 0, sd, 1.0)


def _ceiling_tables(attrs: ProductAttributes, predicted: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    true = np.column_stack([attrs.width, attrs.mass, attrs.glass.astype(float)])
    families = sorted(set(attrs.family))
    tables = {
        "family one-hot (true)": np.array([[f == g for g in families] for f in attrs.family], dtype=float),
        "width, mass, glass (true)": _standardised(true, true),
    }
    for name, pred in predicted.items():
        tables[f"width, mass, glass from {name} text"] = _standardised(pred, true)
    return tables


def _run_ceilings(
    tables: dict[str, np.ndarray],
    rows: Sequence[np.ndarray],
    datasets: Sequence[EvalDataset],
    estimators: Sequence[str],
    options: EvalOptions,
    log: Callable[[str], None],
) -> dict[str, list[dict[str, Any]]]:
    """Every protocol of every (feature table, estimator); `rows`: per dataset, its rows' catalogue indices."""
    from scone_bt.confidence import make_estimator

    out: dict[str, list[dict[str, Any]]] = {p.value: [] for p in _PROTOCOLS}
    for features, table in tables.items():
        X = [table[r] for r in rows]
        for est in estimators:
            result = evaluate_protocols(
                features,
                est,
                datasets,
                X,
                partial(make_estimator, est),
                _PROTOCOLS,
                options,
            )
            for p in _PROTOCOLS:
                s = result.scores[p].to_dict()
                out[p.value].append(
                    {"features": features, "estimator": est, "auc": s["auc"], "auroc": s["auroc"]}
                )
            a1 = out[_PROTOCOLS[0].value][-1]["auc"]["mean"]
            log(f"ceiling {features} + {est}: Algorithm 1 {a1:.3f}")
    return out


# ----------------------------------------------------------------------------------------------- report
def _cell(v: float | None, digits: int = 3) -> str:
    return "n/a" if v is None or (isinstance(v, float) and np.isnan(v)) else f"{v:.{digits}f}"


def probe_markdown(report: dict[str, Any]) -> str:
    """The probe report as Markdown."""
    o = report["options"]
    base = report["base_rates"]
    lines = [
        "# What the action text tells κ̂ (`scone-bench sc probe`)",
        "",
        f"Catalogue: {report['catalogue_products']} products (`{report['kitchen']}`); datasets `{report['data']}`. "
        f"Probes: {o['folds']}-fold cross-validation over products (seed {o['seed']}); wide = grasp width over "
        f"{o['wide_m'] * 100:.1f} cm ({base['wide']:.0%} of the products), heavy = {o['heavy_kg']} kg or more "
        f"({base['heavy']:.0%}), glass ({base['glass']:.0%}). Method: `scone_bt/benchmarks/self_confidence/probe.py`.",
        "",
        '## Probes: what each embedding of "Put X on table" reveals about X (out of fold)',
        "",
        "| embedder | wide AUROC | heavy AUROC | glass AUROC | family accuracy | width R² | mass R² |",
        "|---|---|---|---|---|---|---|",
    ]
    for p in report["probes"]:
        lines.append(
            f"| {p['embedder']} | {_cell(p['wide_auroc'])} | {_cell(p['heavy_auroc'])} | "
            f"{_cell(p['glass_auroc'])} | {_cell(p['family_accuracy'])} (majority {_cell(p['family_majority'])}) | "
            f"{_cell(p['width_r2'])} | {_cell(p['mass_r2'])} |"
        )
    est = report["estimators"]
    for proto, title in (("algorithm1", "Algorithm 1"), ("novel_products", "Novel products")):
        rows = report["ceilings"].get(proto, [])
        if not rows:
            continue
        by = {(r["features"], r["estimator"]): r for r in rows}
        lines += [
            "",
            f"## Ceilings, {title}: κ̂ on features instead of an embedding (normalised AUC, mean ± std)",
            "",
            "| features | " + " | ".join(est) + " |",
            "|---|" + "---|" * len(est),
        ]
        for features in dict.fromkeys(r["features"] for r in rows):
            cells = []
            for e in est:
                a = by[(features, e)]["auc"]
                cells.append("n/a" if a["mean"] is None else f"{a['mean']:.2f} ± {a['std']:.2f}")
            lines.append(f"| {features} | " + " | ".join(cells) + " |")
    lines += [
        "",
        f"Reading: a probe fits on {(o['folds'] - 1) / o['folds']:.0%} of the catalogue's labelled products, far "
        "more attribute knowledge than the 80 outcomes κ̂ learns from. The text-predicted rows are what a linear read-out of "
        "each text gives of the three attributes that decide most outcomes; compare them with the semantic "
        "pairs of `sc evaluate` and with the true attributes' row.",
        "",
    ]
    return "\n".join(lines)


# ----------------------------------------------------------------------------------------------- command
def run_probe(args: argparse.Namespace) -> int:
    """The ``sc probe`` handler (see the module docstring)."""
    from scone_bt.affordances.types import action_text
    from scone_bt.benchmarks.self_confidence.report import write_json
    from scone_bt.confidence import ESTIMATORS
    from scone_bt.embedding import load_embedder
    from scone_bt.errors import ModelUnavailableError, UnknownNameError
    from scone_bt.files import write_atomic
    from scone_bt.reporting import emit_report
    from scone_bt.strict_json import dumps

    def log(msg: str) -> None:
        print(msg, file=sys.stderr, flush=True)

    t0 = time.perf_counter()
    options = ProbeOptions(folds=args.folds, seed=args.seed, wide_m=args.wide_m, heavy_kg=args.heavy_kg)
    estimators = split_names(args.estimators, CEILING_ESTIMATORS)
    plain = [e for e in ESTIMATORS if not e.startswith("eps-")]
    for e in estimators:
        if e not in plain:
            raise UnknownNameError("ceiling estimator", e, plain)
    eval_options = EvalOptions(seed=args.seed)
    report_files: dict[str, Path] = {}
    if args.out is not None:  # before the probes run: their work is not lost to a bad --out or --name
        report_files = check_report_files(
            Path(args.out),
            args.name,
            {".json": "json", ".md": "text"},
            Path(args.data),
            force=bool(getattr(args, "force", False)),
        )
    attrs = product_attributes(args.kitchen, args.catalogue)
    datasets = load_eval_datasets(args.data, min_rows=eval_options.min_rows, kitchen=args.kitchen)
    # every product known before anything runs; the indices serve every ceiling
    rows = [attrs.rows(d.objects, f"{args.data}/{d.name}") for d in datasets]
    texts = [action_text(n) for n in attrs.names]
    probes: list[AttributeProbe] = []
    predicted: dict[str, np.ndarray] = {}
    skipped: dict[str, str] = {}
    embedders = split_names(args.embedders, DEFAULT_EMBEDDERS)
    check_embedder_names(embedders)
    for name in embedders:
        try:
            emb = load_embedder(name, args.cache_dir, vocabulary=texts if name == "onehot" else None)
            vectors = np.asarray(emb.embed(texts), dtype=np.float64)
        except ModelUnavailableError as exc:  # a model that is not installed is reported, not fatal
            skipped[name] = str(exc)
            log(f"skipping embedder {name}: {exc}")
            continue
        probe, pred = probe_attributes(name, vectors, attrs, options)
        probes.append(probe)
        predicted[name] = pred
        log(f"probed {name}: wide AUROC {probe.wide_auroc:.3f}, heavy {probe.heavy_auroc:.3f}")
    ceilings = _run_ceilings(_ceiling_tables(attrs, predicted), rows, datasets, estimators, eval_options, log)
    report: dict[str, Any] = {
        "benchmark": "sc probe",
        "data": str(args.data),
        "kitchen": str(args.kitchen),
        "catalogue_products": len(attrs.names),
        "options": asdict(options),
        "base_rates": {
            "wide": float(np.mean(attrs.width > options.wide_m)),
            "heavy": float(np.mean(attrs.mass >= options.heavy_kg)),
            "glass": float(np.mean(attrs.glass)),
        },
        "probes": [asdict(p) for p in probes],
        "embedders_skipped": skipped,
        "estimators": estimators,
        "ceilings": ceilings,
        "timing_s": {"total": round(time.perf_counter() - t0, 2)},
    }
    report = write_json(None, report)
    if args.out is not None:
        out = Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        write_atomic(report_files[".json"], dumps(report, indent=1) + "\n")
        write_atomic(report_files[".md"], probe_markdown(report))
    emit_report(report, args.json, indent=1, make_parent=True, force=bool(getattr(args, "force", False)))
    return 0


def register_probe(sc_sub: argparse._SubParsersAction) -> None:
    """Add ``probe`` to ``scone-bench sc``."""
    defaults = ProbeOptions()
    p = sc_sub.add_parser(
        "probe",
        help="what the action texts reveal of width, mass, glass and family, and the κ̂ ceilings that sets",
        description="Cross-validated probes of each embedder's action texts for the attributes that decide "
        "outcomes, and Algorithm 1 / novel-products ceilings of κ̂ on the true and the text-predicted attributes.",
    )
    p.add_argument(
        "--data",
        type=path_arg,
        default=Path("tools/data/sc"),
        help="datasets folder (default: tools/data/sc)",
    )
    p.add_argument(
        "--kitchen", default="kitchen", help="kitchen whose catalogue is probed (default: kitchen)"
    )
    p.add_argument(
        "--catalogue",
        action="append",
        default=[],
        metavar="FILE",
        help="an extra product catalogue YAML (repeatable)",
    )
    p.add_argument(
        "--embedders",
        nargs="+",
        default=None,
        help=f"default: {','.join(DEFAULT_EMBEDDERS)} (those not installed are skipped)",
    )
    p.add_argument(
        "--estimators",
        nargs="+",
        default=None,
        help=f"ceiling estimators (default: {','.join(CEILING_ESTIMATORS)})",
    )
    p.add_argument(
        "--folds", type=int, default=defaults.folds, help=f"probe folds (default: {defaults.folds})"
    )
    p.add_argument(
        "--seed",
        type=int,
        default=defaults.seed,
        help=f"seeds folds and estimators (default: {defaults.seed})",
    )
    p.add_argument(
        "--wide-m", type=float, default=defaults.wide_m, help=f"wide above (default: {defaults.wide_m} m)"
    )
    p.add_argument(
        "--heavy-kg",
        type=float,
        default=defaults.heavy_kg,
        help=f"heavy from (default: {defaults.heavy_kg} kg)",
    )
    p.add_argument("--cache-dir", type=path_arg, default=None, help="embedding cache (default: scone_bt's)")
    p.add_argument("--json", type=path_arg, default=None, help="also write the JSON report to this file")
    p.add_argument("--out", type=path_arg, default=None, help="folder for <name>.json and .md")
    p.add_argument("--name", default="self_confidence_probe", help="stem of the files in --out")
    p.set_defaults(func=run_probe)
