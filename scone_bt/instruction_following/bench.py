"""Runs every IF policy on a states file and lays the scores out like the IF column of the paper's Table I.

Fitting uses only the train split (the fine-tuned head, every ρ, the TICC intent model); the dev split picks
between an absolute and a relative IF-tuned threshold; the scores are on the evaluated states.
"""

from __future__ import annotations

import re
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from scone_bt.embedding.base import Embedder
from scone_bt.errors import ModelUnavailableError, SconeError, UnknownNameError
from scone_bt.instruction_following.mcts_baseline import MctsOptions, TiccMctsPolicy
from scone_bt.instruction_following.metric import Episode, IfScore, evaluate
from scone_bt.instruction_following.pddl_baseline import PddlPolicy
from scone_bt.instruction_following.policies import (
    SimilarityPolicy,
    fit_threshold,
    relative_scores,
    state_scores,
    threshold_picks_score,
)
from scone_bt.instruction_following.product_policy import (
    RecipeAwarePolicy,
    fit_selection_options,
    fit_similarity_policy,
)
from scone_bt.instruction_following.states import IfState

__all__ = [
    "BenchOptions",
    "EmbedderRow",
    "BenchResult",
    "run_benchmark",
    "format_table",
    "state_category",
    "fit_intent_model",
]

_NEGATION = re.compile(
    r"\b(?:not|don't|do not|without|no|never|avoid|except|instead of|reserv\w*|set aside)\b", re.I
)


@dataclass(frozen=True)
class BenchOptions:
    """What the benchmark runs.

    Attributes:
        embedders: Embedder names to score (one-hot is excluded by design); unavailable ones are skipped.
        finetune: Train the fine-tuned embedder on the train split.
        finetune_base: Frozen encoder for it; "auto" takes MPNet when installed, else MiniLM.
        finetune_dir: Where to save the fine-tuned head (None: not saved).
        ticc_embedder: Embedder behind the TICC baseline's intent model.
        mcts: TICC search settings.
        pddl: Run the PDDL (LAMA) baseline.
        ticc: Run the TICC-style baseline.
        cache_dir: Embedding cache folder (None: the default).
        engine: scone_bt.distributed.EngineOptions running the embedder rows and the PDDL and TICC baselines as
            parallel tasks (local pool or Ray); None: one after another in this process. Same scores either way.
    """

    embedders: tuple[str, ...] = ("minilm", "mpnet", "glove")
    finetune: bool = True
    finetune_base: str = "auto"
    finetune_dir: Path | None = None
    ticc_embedder: str = "minilm"
    mcts: MctsOptions = field(default_factory=MctsOptions)
    pddl: bool = True
    ticc: bool = True
    cache_dir: Path | None = None
    engine: Any = None


@dataclass(frozen=True)
class EmbedderRow:
    """One embedder's scores with each stopping rule.

    Attributes:
        name: Embedder label.
        rho: ρ from ``RelevanceFilter.fit`` on train (balanced accuracy on action labels), cosine similarity.
        rho_if: ρ tuned on train for IF accuracy; relative to the best action's similarity when ``rho_if_relative``.
        rho_if_relative: Whether dev preferred the relative threshold.
        with_rho: Scores stopping at ``rho``.
        with_rho_if: Scores stopping at ``rho_if``.
        oracle_stop: Scores stopping after len(relevant) picks (ranking quality alone).
        product: The policy the robot runs (recipe-aware selection with its own stop rule), fitted on train.
        product_rho: Its semantic fallback's ρ, cosine similarity.
        product_margin: Its ambiguity margin, cosine similarity.
        product_named: Share of evaluated states where the step names at least one candidate item.
        recipe_similarity: Ablation: the recipe's items chosen by similarity alone (no name reading).
    """

    name: str
    rho: float
    rho_if: float
    rho_if_relative: bool
    with_rho: IfScore
    with_rho_if: IfScore
    oracle_stop: IfScore
    product: IfScore
    product_rho: float
    product_margin: float
    product_named: float
    recipe_similarity: IfScore | None = None


@dataclass(frozen=True)
class BenchResult:
    """Everything the benchmark measured.

    Attributes:
        rows: Embedding policies.
        baselines: PDDL, TICC-style and pick-everything scores.
        skipped: Embedder → why it was not run.
        counts: Number of train, dev and evaluated states.
        seconds: Wall time per part.
        finetuned: Training facts of the fine-tuned embedder (empty if not trained).
    """

    rows: tuple[EmbedderRow, ...]
    baselines: tuple[IfScore, ...]
    skipped: dict[str, str]
    counts: dict[str, int]
    seconds: dict[str, float]
    finetuned: dict[str, object]

    def best_row(self) -> EmbedderRow | None:
        """The embedding row with the highest IF accuracy (either ρ)."""
        if not self.rows:
            return None
        return max(self.rows, key=lambda r: max(r.with_rho.accuracy, r.with_rho_if.accuracy))

    def to_json(self) -> dict[str, object]:
        """Summary numbers, the per-category breakdown of the best policy, and a few failure examples."""
        best = self.best_row()
        out: dict[str, Any] = {
            "counts": self.counts,
            "embedding_policies": [
                {
                    "embedder": r.name,
                    "rho": round(r.rho, 4),
                    "rho_if": round(r.rho_if, 4),
                    "rho_if_relative": r.rho_if_relative,
                    "with_rho": r.with_rho.to_json(),
                    "with_rho_if": r.with_rho_if.to_json(),
                    "oracle_stop": r.oracle_stop.to_json(),
                    "product_policy": _product_json(r),
                }
                for r in self.rows
            ],
            "baselines": [b.to_json() for b in self.baselines],
            "skipped": self.skipped,
            "seconds": {k: round(v, 1) for k, v in self.seconds.items()},
            "finetuned": self.finetuned,
        }
        if self.rows:
            out["product_policy"] = {"embedder": self.rows[0].name, **_product_json(self.rows[0])}
        if best is not None:
            score = best.with_rho_if if best.with_rho_if.accuracy >= best.with_rho.accuracy else best.with_rho
            out["best"] = {"policy": score.policy, "accuracy": round(score.accuracy, 4)}
            out["breakdown"] = {"best": _breakdown(score.episodes)}
            for b in self.baselines:
                out["breakdown"][b.policy] = _breakdown(b.episodes)
            out["failures"] = _failures(score.episodes)
        return out


def _product_json(row: EmbedderRow) -> dict[str, object]:
    return {
        "accuracy": round(row.product.accuracy, 4),
        "recall": round(row.product.recall, 4),
        "picks_per_state": round(row.product.picks_per_state, 3),
        "rho": round(row.product_rho, 3),
        "margin": round(row.product_margin, 3),
        "states_naming_an_item": round(row.product_named, 4),
        "recipe_similarity_only": row.recipe_similarity.to_json() if row.recipe_similarity else None,
    }


def state_category(state: IfState) -> str:
    """ "negation" (the step says not/without/reserve…), "multi" (≥ 3 relevant actions) or "single-few"."""
    if _NEGATION.search(state.instruction):
        return "negation"
    return "multi" if len(state.relevant) >= 3 else "single-few"


def _breakdown(episodes: Sequence[Episode]) -> dict[str, dict[str, float]]:
    out: dict[str, dict[str, float]] = {}
    for cat in ("negation", "multi", "single-few"):
        eps = [e for e in episodes if state_category(e.state) == cat]
        if eps:
            out[cat] = {
                "states": len(eps),
                "accuracy": round(float(np.mean([e.accuracy for e in eps])), 4),
                "recall": round(float(np.mean([e.recall for e in eps])), 4),
            }
    return out


def _failures(episodes: Sequence[Episode], per_category: int = 3) -> list[dict[str, object]]:
    out: list[dict[str, object]] = []
    for cat in ("negation", "multi"):
        bad = [e for e in episodes if state_category(e.state) == cat and e.accuracy < 1.0]
        bad.sort(key=lambda e: (e.accuracy, len(e.state.instruction)))
        for e in bad[:per_category]:
            out.append(
                {
                    "category": cat,
                    "recipe_id": e.state.recipe_id,
                    "instruction": e.state.instruction,
                    "relevant": sorted(e.state.relevant),
                    "picks": list(e.picks),
                    "accuracy": round(e.accuracy, 3),
                }
            )
    return out


def fit_intent_model(embedder: Embedder, train: Sequence[IfState]) -> Callable[[IfState], dict[str, float]]:
    """P(action needed | instruction): logistic regression on the similarity and its gap to the state's best."""
    from sklearn.linear_model import LogisticRegression

    def features(states: Sequence[IfState]) -> list[np.ndarray]:
        sc = state_scores(embedder, states)
        return [np.stack([s, r], axis=1) for s, r in zip(sc, relative_scores(sc), strict=True)]

    x = np.concatenate(features(train))
    y = np.concatenate([[a in s.relevant for a in s.available] for s in train])
    model = LogisticRegression(C=1.0).fit(x, y)

    def belief(state: IfState) -> dict[str, float]:
        (f,) = features([state])
        return dict(zip(state.available, map(float, model.predict_proba(f)[:, 1]), strict=True))

    return belief


def _embedding_row(
    name: str, emb: Embedder, train: Sequence[IfState], dev: Sequence[IfState], test: Sequence[IfState]
) -> EmbedderRow:
    from scone_bt.relevance.filter import RelevanceFilter

    train_sc = state_scores(emb, train)
    pooled = np.concatenate(train_sc)
    labels = np.concatenate([[a in s.relevant for a in s.available] for s in train])
    rho = RelevanceFilter.fit(pooled, labels, embedder=name).threshold
    rho_abs = fit_threshold(train_sc, train)
    rho_rel = fit_threshold(relative_scores(train_sc), train)
    relative = False
    rho_if = rho_abs
    if dev:
        dev_sc = state_scores(emb, dev)
        acc_abs = threshold_picks_score(dev_sc, dev, rho_abs)[0]
        acc_rel = threshold_picks_score(relative_scores(dev_sc), dev, rho_rel)[0]
        if acc_rel > acc_abs:
            relative, rho_if = True, rho_rel
    state_scores(emb, test)  # one batched pass; the policies then read the embedder's cache
    sel_opts = fit_selection_options(emb, train, name)
    product = RecipeAwarePolicy(emb, f"{name}, recipe-aware (product)", sel_opts)
    named = float(np.mean([bool(product.selection(s).named) for s in test]))
    similarity_only = fit_similarity_policy(emb, train, f"{name}, recipe-aware, similarity only")
    return EmbedderRow(
        name=name,
        rho=rho,
        rho_if=rho_if,
        rho_if_relative=relative,
        with_rho=evaluate(SimilarityPolicy(emb, f"{name} + ρ", threshold=rho), test),
        with_rho_if=evaluate(
            SimilarityPolicy(emb, f"{name} + ρ_IF", threshold=rho_if, relative=relative), test
        ),
        oracle_stop=evaluate(SimilarityPolicy(emb, f"{name}, oracle stop", oracle_count=True), test),
        product=evaluate(product, test),
        product_rho=sel_opts.rho,
        product_margin=sel_opts.margin,
        product_named=named,
        recipe_similarity=evaluate(similarity_only, test),
    )


@dataclass(frozen=True)
class _PartInputs:
    """What every part of the benchmark reads (shipped once per worker)."""

    train: tuple[IfState, ...]
    dev: tuple[IfState, ...]
    test: tuple[IfState, ...]
    options: BenchOptions


def _run_part(part: tuple[str, str], inputs: _PartInputs) -> tuple[str, str, object, float]:
    """One independent part: ("row", embedder), ("pddl", "") or ("ticc", embedder); (kind, name, result, s).

    A row whose embedder is not installed returns the reason as its result (a string).
    """
    from scone_bt.embedding import load_embedder

    kind, name = part
    t0 = time.perf_counter()
    if kind == "row":
        try:
            emb = load_embedder(name, inputs.options.cache_dir)
        except ModelUnavailableError as exc:
            return kind, name, str(exc), 0.0
        result: object = _embedding_row(name, emb, inputs.train, inputs.dev, inputs.test)
    elif kind == "pddl":
        result = evaluate(PddlPolicy(), inputs.test)
    else:
        belief = fit_intent_model(load_embedder(name, inputs.options.cache_dir), inputs.train)
        policy = TiccMctsPolicy(belief, inputs.options.mcts, name=f"TICC-style MCTS ({name})")
        result = evaluate(policy, inputs.test)
    return kind, name, result, time.perf_counter() - t0


def check_embedders(names: Sequence[str]) -> None:
    """Every name is an embedder the benchmark scores: a registry name but onehot (which it does not score),
    finetuned:<dir> or a model directory; else UnknownNameError listing exactly those (checked before any work).
    The registered names are those of this process (scone-bench registers mpnet-ft), as `load_embedder` sees them."""
    from scone_bt.embedding.registry import embedder_names, names_an_embedder

    known = [n for n in embedder_names() if n != "onehot"]
    for name in names:
        folder = Path(name.removeprefix("finetuned:")).expanduser()
        if (
            name.startswith("finetuned:") and not folder.is_dir()
        ):  # stricter than the registry: a model is trained
            raise SconeError(f"IF embedder {name!r}: no such folder {folder}")
        if name != "onehot" and names_an_embedder(name):
            continue
        raise UnknownNameError("IF embedder", name, [*known, "finetuned:<dir>", "<model directory>"])


def run_benchmark(
    test: Sequence[IfState],
    train: Sequence[IfState],
    dev: Sequence[IfState] = (),
    options: BenchOptions | None = None,
    log: Callable[[str], None] = lambda _m: None,
) -> BenchResult:
    """Fit on ``train`` (and select on ``dev``), score every policy on ``test``.

    The embedder rows and the PDDL and TICC baselines are independent tasks (run on ``options.engine``); the
    fine-tuned row is trained here, after them.

    Raises:
        SconeError: no test or no train states.
    """
    from scone_bt.distributed import EngineOptions, imap_tasks

    opts = options or BenchOptions()
    if not test or not train:
        raise SconeError(
            f"the IF benchmark needs train and test states; got {len(train)} train, {len(test)} test"
        )
    check_embedders(opts.embedders)
    parts = [("row", name) for name in opts.embedders]
    parts += [("pddl", "")] if opts.pddl else []
    parts += [("ticc", opts.ticc_embedder)] if opts.ticc else []
    inputs = _PartInputs(tuple(train), tuple(dev), tuple(test), replace(opts, engine=None))
    done: dict[tuple[str, str], tuple[Any, float]] = {}
    labels = {"row": "scoring {}", "pddl": "PDDL (LAMA)", "ticc": "TICC-style MCTS (intent model on {})"}
    for _i, (kind, name, result, sec) in imap_tasks(
        _run_part, parts, engine=opts.engine or EngineOptions(workers=1), shared=inputs
    ):
        done[kind, name] = (result, sec)
        log(labels[kind].format(name) + f": done ({sec:.0f} s)")
    rows: list[EmbedderRow] = []
    skipped: dict[str, str] = {}
    seconds: dict[str, float] = {}
    for name in opts.embedders:
        result, sec = done["row", name]
        if isinstance(result, str):
            skipped[name] = result
            log(f"skip {name}: {result}")
            continue
        rows.append(result)
        seconds[name] = sec
    finetuned: dict[str, object] = {}
    if opts.finetune:
        tuned = _finetuned_row(opts, skipped, train, dev, test, log)
        rows.append(tuned.row)
        seconds[tuned.row.name] = tuned.seconds
        finetuned = tuned.info
    baselines: list[IfScore] = []
    for kind, name in parts:
        if kind != "row":
            result, sec = done[kind, name]
            baselines.append(result)
            seconds[kind] = sec
    baselines.append(evaluate(SimilarityPolicy(None, "pick everything (chance)", score_fn=_zeros), test))
    return BenchResult(
        rows=tuple(rows),
        baselines=tuple(baselines),
        skipped=skipped,
        counts={"train": len(train), "dev": len(dev), "test": len(test)},
        seconds=seconds,
        finetuned=finetuned,
    )


@dataclass(frozen=True)
class _Finetuned:
    """The fine-tuned embedder's row, the seconds it took (training and scoring) and what the report says of it."""

    row: EmbedderRow
    seconds: float
    info: dict[str, object]


def _finetuned_row(
    opts: BenchOptions,
    skipped: Mapping[str, str],
    train: Sequence[IfState],
    dev: Sequence[IfState],
    test: Sequence[IfState],
    log: Callable[[str], None],
) -> _Finetuned:
    """Fine-tune ``opts.finetune_base`` (auto: mpnet when it was scored, else minilm) on ``train``, and score it."""
    from scone_bt.embedding import FinetuneOptions, load_embedder, train_finetuned

    base = opts.finetune_base
    if base == "auto":
        base = "mpnet" if "mpnet" in opts.embedders and "mpnet" not in skipped else "minilm"
    t0 = time.perf_counter()
    encoder = load_embedder(base, opts.cache_dir)
    log(f"fine-tuning on {base} ({len(train)} train states) ...")
    examples = [(s.instruction, tuple(sorted(s.relevant)), s.available) for s in train]
    ft_opts = FinetuneOptions()
    emb = train_finetuned(examples, encoder, opts.finetune_dir, options=ft_opts)
    row = _embedding_row(f"fine-tuned {base}", emb, train, dev, test)
    info: dict[str, object] = {
        "base": base,
        "dim": emb.dim,
        "epochs": ft_opts.epochs,
        "train_seconds": emb.meta.get("train_seconds"),
    }
    return _Finetuned(row, time.perf_counter() - t0, info)


def _zeros(state: IfState) -> dict[str, float]:
    return dict.fromkeys(state.available, 0.0)


def format_table(result: BenchResult) -> str:
    """A Markdown table in the layout of Table I's IF column, one policy per row."""
    lines = [
        "| Method | IF accuracy | recall | picks/state | stop rule |",
        "|---|---|---|---|---|",
    ]
    for r in result.rows:
        kind = "relative" if r.rho_if_relative else "absolute"
        lines.append(
            f"| {r.name}, ρ (RelevanceFilter) | {r.with_rho.accuracy:.2f} | {r.with_rho.recall:.2f} | "
            f"{r.with_rho.picks_per_state:.2f} | cos ≥ {r.rho:.3f} |"
        )
        lines.append(
            f"| {r.name}, ρ tuned for IF | {r.with_rho_if.accuracy:.2f} | {r.with_rho_if.recall:.2f} | "
            f"{r.with_rho_if.picks_per_state:.2f} | {kind} {r.rho_if:.3f} |"
        )
        lines.append(
            f"| {r.name}, oracle stop | {r.oracle_stop.accuracy:.2f} | {r.oracle_stop.recall:.2f} | "
            f"{r.oracle_stop.picks_per_state:.2f} | after len(relevant) picks |"
        )
        lines.append(
            f"| {r.name}, recipe-aware (the robot's policy) | {r.product.accuracy:.2f} | {r.product.recall:.2f} | "
            f"{r.product.picks_per_state:.2f} | named items, else cos ≥ {r.product_rho:.2f} |"
        )
        if r.recipe_similarity is not None:
            sim = r.recipe_similarity
            lines.append(
                f"| {r.name}, recipe items by similarity only (ablation) | {sim.accuracy:.2f} | {sim.recall:.2f} | "
                f"{sim.picks_per_state:.2f} | within δ of the best recipe item |"
            )
    for b in result.baselines:
        lines.append(f"| {b.policy} | {b.accuracy:.2f} | {b.recall:.2f} | {b.picks_per_state:.2f} | own |")
    for name, why in result.skipped.items():
        lines.append(f"| {name} | — | — | — | skipped: {why.split(';')[0]} |")
    return "\n".join(lines)
