"""``scone-bench gate --unseen``: what a fleet prior and the robot's own store add on products it never saw.

Only decisions about a product κ̂ has **no outcome of** are scored: the product's first occurrence in the stream
(nothing earlier in the stream can have taught it), and every execution of it removed from whatever κ̂ learns
before the stream (leave-products-out: `leave_products_out`). The same decisions are scored under every condition,
so the comparisons are paired. The gate is the budget gate over the tree's κ̂ (the replay's `replay_stream`), at
α in `UNSEEN_TARGETS`.

Two designs:

- ``fleet`` (whole streams, the replay's warm-up not scored): ``cold`` (no prior), ``fleet`` (κ̂ first learns
  every execution of the other streams, the products of this stream removed), and, for contrast at the tree's α,
  ``fleet_with_products`` (the other streams kept whole: the same decisions, where the fleet may have seen the
  product).
- ``own_store`` (the second half of each stream, every decision scored): the robot's earlier run is the stream's
  first half, replayed cold by the same gate; its **attempts** (what an experience store holds: asked actions have
  no outcome) are its own store. Then, on the second half, a new episode: ``cold``, ``own_store`` (its own store,
  the second half's products removed), ``fleet`` (the other streams, the second half's products removed) and
  ``fleet_and_own_store`` (both; a fleet store a robot learns all of, ``--learn-from fleet``).

Per decision the nearest *seen* neighbour is measured in ζ (the highest cosine similarity to an action in the
fleet prior) and in the perceived size (the smallest distance, mm, over the detected width, height and depth that
both rows have), and the fleet's effect is reported per bin of each (`SIMILARITY_EDGES`, `SIZE_EDGES_MM`), with
how often that neighbour's outcome equals the decision's own. Differences come with a seeded paired bootstrap
over decisions (95 % interval).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np

from scone_bt.experience.types import CONTEXT_FIELDS

if TYPE_CHECKING:
    from scone_bt.gate.probe import ProbeOptions

__all__ = [
    "UNSEEN_TARGETS",
    "SIMILARITY_EDGES",
    "SIZE_EDGES_MM",
    "TOLERANCE",
    "Prior",
    "UnseenStreams",
    "stream_prior",
    "leave_products_out",
    "first_occurrences",
    "outcome_rates",
    "Neighbours",
    "nearest_seen",
    "unseen_report",
]

UNSEEN_TARGETS: tuple[float, ...] = (0.10, 0.15, 0.20)
"""Target failure rates α the section measures."""
SIMILARITY_EDGES: tuple[float, ...] = (0.7, 0.8, 0.9)
"""Bins of the nearest seen action's cosine similarity in ζ (MiniLM on the development streams: 10th, 50th and
90th percentiles 0.62, 0.78, 0.90)."""
SIZE_EDGES_MM: tuple[float, ...] = (0.5, 2.0, 5.0)
"""Bins of the nearest seen row's perceived-size distance, mm (a target not measured has its own bin; on the
development streams half the unseen products have a seen one within 0.15 mm: catalogue sizes repeat)."""
TOLERANCE = 0.02
"""The promise: the attempt failure rate stays ≤ α + this."""
_SIZE_COLUMNS = tuple(
    CONTEXT_FIELDS.index(c) for c in ("detected_width_m", "detected_height_m", "detected_depth_m")
)
_BOOTSTRAP = 2000


class UnseenStreams(Protocol):
    """The replay's loaded streams (benchmarks.replay_streams.Streams), as this section reads them."""

    @property
    def names(self) -> list[str]: ...
    @property
    def vectors(self) -> list[np.ndarray]: ...
    @property
    def context(self) -> list[np.ndarray]: ...
    @property
    def success(self) -> list[np.ndarray]: ...
    @property
    def products(self) -> list[tuple[str, ...]]: ...
    @property
    def readings(self) -> list[np.ndarray | None]: ...
    @property
    def foreseen(self) -> list[np.ndarray]: ...
    @property
    def slide_pinch(self) -> list[bool]: ...


class _Replayed(Protocol):
    @property
    def trace(self) -> list[int]: ...


Replay = Callable[..., _Replayed]
"""benchmarks.replay.replay_stream (passed in by benchmarks.gate, which drives both)."""


@dataclass(frozen=True)
class Prior:
    """What κ̂ learns before a stream.

    Attributes:
        rows: (n, d + c) κ̂'s rows: the embedding, then the perceived context.
        success: (n,) the outcomes.
        products: (n,) the product of each row.
    """

    rows: np.ndarray
    success: np.ndarray
    products: tuple[str, ...]

    def __len__(self) -> int:
        return len(self.success)


def leave_products_out(prior: Prior, products: set[str] | frozenset[str]) -> Prior:
    """The prior without a single execution of any of ``products``."""
    keep = np.array([p not in products for p in prior.products], dtype=bool)
    return Prior(
        prior.rows[keep],
        prior.success[keep],
        tuple(p for p, k in zip(prior.products, keep, strict=True) if k),
    )


def first_occurrences(products: Sequence[str]) -> np.ndarray:
    """(n,) bool: whether each decision is the first of its product in the sequence."""
    seen: set[str] = set()
    out = np.zeros(len(products), dtype=bool)
    for i, p in enumerate(products):
        out[i] = p not in seen
        seen.add(p)
    return out


def outcome_rates(trace: np.ndarray) -> dict[str, Any]:
    """Rates of decisions coded 1 (acted, succeeded), 0 (acted, failed), -1 (asked; an aborted probe too)."""
    t = np.asarray(trace)
    n, attempts, failures = len(t), int((t >= 0).sum()), int((t == 0).sum())
    return {
        "decisions": n,
        "attempts": attempts,
        "success_rate": round(float((t == 1).sum()) / n, 4) if n else None,
        "help_rate": round(float((t < 0).sum()) / n, 4) if n else None,
        "attempt_failure_rate": round(failures / attempts, 4) if attempts else None,
    }


@dataclass(frozen=True)
class Neighbours:
    """Each decision's nearest seen neighbour in the prior.

    Attributes:
        similarity: (n,) the highest cosine similarity in ζ to a prior row (NaN: empty prior).
        similar_success: (n,) that row's outcome, 1 or 0 (NaN: empty prior).
        size_mm: (n,) the smallest perceived-size distance to a prior row, mm, over the detected width, height
            and depth both rows have (NaN: the decision's target has no perceived size, or no row has one).
        size_success: (n,) that row's outcome, 1 or 0 (NaN likewise).
    """

    similarity: np.ndarray
    similar_success: np.ndarray
    size_mm: np.ndarray
    size_success: np.ndarray


def nearest_seen(vectors: np.ndarray, context: np.ndarray, prior: Prior, dim: int) -> Neighbours:
    """The nearest seen neighbour of each row (``dim``: the embedding's width in the prior's rows)."""
    n = len(vectors)
    none = np.full(n, np.nan)
    if not len(prior):
        return Neighbours(none, none.copy(), none.copy(), none.copy())
    E = prior.rows[:, :dim].astype(np.float64)
    V = np.asarray(vectors, dtype=np.float64)
    sim = (V / np.linalg.norm(V, axis=1, keepdims=True)) @ (E / np.linalg.norm(E, axis=1, keepdims=True)).T
    outcome = prior.success.astype(np.float64)
    sizes = prior.rows[:, dim:][:, _SIZE_COLUMNS].astype(np.float64) * 1000.0
    mine = np.asarray(context, dtype=np.float64)[:, _SIZE_COLUMNS] * 1000.0
    size, size_success = none.copy(), none.copy()
    for i, row in enumerate(mine):
        cols = np.isfinite(row)
        usable = np.flatnonzero(np.isfinite(sizes[:, cols]).all(axis=1) & cols.any())
        if len(usable):
            dist = np.sqrt(((sizes[usable][:, cols] - row[cols]) ** 2).sum(axis=1))
            size[i] = float(dist.min())
            size_success[i] = outcome[usable[int(dist.argmin())]]
    return Neighbours(sim.max(axis=1), outcome[sim.argmax(axis=1)], size, size_success)


def _agreement(neighbour_success: np.ndarray, success: np.ndarray) -> np.ndarray:
    """1 where the neighbour's outcome equals the decision's, 0 where not, NaN where there is no neighbour."""
    return np.where(np.isnan(neighbour_success), np.nan, (neighbour_success == success).astype(float))


def _bins(values: np.ndarray, edges: Sequence[float], unit: str) -> list[tuple[str, np.ndarray]]:
    """Labelled masks of ``values`` between consecutive edges (and a bin for NaN if any)."""
    bounds = [-np.inf, *edges, np.inf]
    out = []
    for lo, hi in zip(bounds[:-1], bounds[1:], strict=True):
        label = (
            f"< {hi:g}{unit}"
            if lo == -np.inf
            else f">= {lo:g}{unit}"
            if hi == np.inf
            else f"{lo:g}-{hi:g}{unit}"
        )
        out.append((label, (values >= lo) & (values < hi)))
    if np.isnan(values).any():
        out.append(("not measured", np.isnan(values)))
    return out


def _paired_difference(
    base: np.ndarray, other: np.ndarray, seed: int, reps: int = _BOOTSTRAP
) -> dict[str, Any]:
    """other − base on the same decisions: success, help and attempt-failure rates, with a paired bootstrap's
    95 % interval (seeded)."""

    def rates(t: np.ndarray) -> np.ndarray:
        att = (t >= 0).sum(axis=-1)
        return np.stack(
            [
                (t == 1).mean(axis=-1),
                (t < 0).mean(axis=-1),
                np.where(att > 0, (t == 0).sum(axis=-1) / np.maximum(att, 1), np.nan),
            ]
        )

    if not len(base):
        return {}
    point = rates(other) - rates(base)
    idx = np.random.default_rng(seed).integers(0, len(base), size=(reps, len(base)))
    boot = rates(other[idx]) - rates(base[idx])
    keys = ("success_rate", "help_rate", "attempt_failure_rate")
    return {
        k: {
            "difference": round(float(point[i]), 4),
            "ci95": [round(float(np.nanpercentile(boot[i], q)), 4) for q in (2.5, 97.5)],
        }
        for i, k in enumerate(keys)
    }


@dataclass(frozen=True)
class _Setup:
    """How each stream is replayed (the gate's own arguments)."""

    replay: Replay
    estimator: str
    seed: int
    warmup: int
    opening_m: float
    probe: ProbeOptions | None
    excess_allowance: float | None


def stream_prior(streams: UnseenStreams, which: Sequence[int], foreseen: bool = False) -> Prior:
    """The streams' executions as a fleet's store holds them: none whose target was not detected
    (benchmarks.replay_streams.foreseen: "missing"), unless ``foreseen`` (every row, aligned with the stream)."""
    if not which:
        d = streams.vectors[0].shape[1] + len(CONTEXT_FIELDS)
        return Prior(np.zeros((0, d), dtype=np.float32), np.zeros(0, dtype=bool), ())
    keep = {
        i: streams.foreseen[i] != "missing"
        if streams.foreseen and not foreseen
        else np.ones(len(streams.success[i]), bool)
        for i in which
    }
    return Prior(
        np.vstack([np.hstack([streams.vectors[i], streams.context[i]])[keep[i]] for i in which]),
        np.concatenate([streams.success[i][keep[i]] for i in which]).astype(bool),
        tuple(p for i in which for p, k in zip(streams.products[i], keep[i], strict=True) if k),
    )


def _run(
    setup: _Setup,
    streams: UnseenStreams,
    j: int,
    window: slice,
    alpha: float,
    prior: Prior | None,
    warmup: int,
) -> np.ndarray:
    """Stream ``j``'s decisions in ``window`` replayed after ``prior`` (None: cold): the trace, 1 / 0 / -1."""
    readings = streams.readings[j] if streams.readings else None
    foreseen = streams.foreseen[j] if streams.foreseen else None
    result = setup.replay(
        streams.vectors[j][window],
        streams.context[j][window],
        streams.success[j][window],
        streams.products[j][window],
        setup.estimator,
        "budget",
        alpha,
        setup.seed + j,
        warmup,
        setup.opening_m,
        (prior.rows, prior.success) if prior is not None and len(prior) else None,
        probe=setup.probe,
        readings=readings[window] if readings is not None else None,
        excess_allowance=setup.excess_allowance,
        foreseen=foreseen[window] if foreseen is not None else None,
        slide_pinch=bool(streams.slide_pinch and streams.slide_pinch[j]),
    )
    return np.asarray(result.trace, dtype=np.int8)


def _fleet_design(setup: _Setup, streams: UnseenStreams, default_alpha: float) -> dict[str, Any]:
    """Whole streams: cold, the fleet without the stream's products, and (at the tree's α) the fleet whole."""
    n_streams = len(streams.names)
    full = slice(None)
    scored = [first_occurrences(p) & (np.arange(len(p)) >= setup.warmup) for p in streams.products]
    priors = [stream_prior(streams, [i for i in range(n_streams) if i != j]) for j in range(n_streams)]
    lpo = [leave_products_out(priors[j], set(streams.products[j])) for j in range(n_streams)]
    dim = streams.vectors[0].shape[1]
    near = [
        nearest_seen(streams.vectors[j][scored[j]], streams.context[j][scored[j]], lpo[j], dim)
        for j in range(n_streams)
    ]
    outcomes = [streams.success[j][scored[j]].astype(float) for j in range(n_streams)]
    similarity = np.concatenate([nb.similarity for nb in near])
    similar_agrees = np.concatenate(
        [_agreement(nb.similar_success, y) for nb, y in zip(near, outcomes, strict=True)]
    )
    size_mm = np.concatenate([nb.size_mm for nb in near])
    size_agrees = np.concatenate(
        [_agreement(nb.size_success, y) for nb, y in zip(near, outcomes, strict=True)]
    )
    per_alpha: dict[str, Any] = {}
    for alpha in UNSEEN_TARGETS:
        traces = {
            "cold": [_run(setup, streams, j, full, alpha, None, setup.warmup) for j in range(n_streams)],
            "fleet": [_run(setup, streams, j, full, alpha, lpo[j], setup.warmup) for j in range(n_streams)],
        }
        if abs(alpha - default_alpha) < 1e-9:
            traces["fleet_with_products"] = [
                _run(setup, streams, j, full, alpha, priors[j], setup.warmup) for j in range(n_streams)
            ]
        pooled = {
            k: np.concatenate([t[m] for t, m in zip(v, scored, strict=True)]) for k, v in traces.items()
        }
        per_alpha[f"{alpha:g}"] = {
            **{k: _with_promise(outcome_rates(v), alpha) for k, v in pooled.items()},
            "fleet_minus_cold": _paired_difference(pooled["cold"], pooled["fleet"], setup.seed),
            "by_similarity": _binned(pooled, similarity, similar_agrees, SIMILARITY_EDGES, ""),
            "by_size_mm": _binned(pooled, size_mm, size_agrees, SIZE_EDGES_MM, " mm"),
        }
    return {
        "scored_decisions": int(sum(m.sum() for m in scored)),
        "prior_rows": [len(p) for p in lpo],
        "prior_rows_removed": [len(p) - len(q) for p, q in zip(priors, lpo, strict=True)],
        "nearest_similarity": _quantiles(similarity),
        "nearest_size_mm": _quantiles(size_mm),
        "similar_outcome_agrees": _mean(similar_agrees),
        "size_outcome_agrees": _mean(size_agrees),
        "targets": per_alpha,
    }


_OWN_STORE_CONDITIONS = ("cold", "own_store", "fleet", "fleet_and_own_store")


def _own_store_stream(
    setup: _Setup, streams: UnseenStreams, j: int, alpha: float
) -> tuple[dict[str, np.ndarray], np.ndarray, int]:
    """Stream ``j``'s second half under each condition (its traces), the decisions scored there, and how many
    rows its own store holds."""
    n_streams = len(streams.names)
    half = len(streams.products[j]) // 2
    earlier, later = slice(0, half), slice(half, None)
    later_products = set(streams.products[j][later])
    # the earlier run: the same gate, cold; its store holds only what it attempted
    run = _run(setup, streams, j, earlier, alpha, None, 0)
    whole = stream_prior(streams, [j], foreseen=True)  # aligned with the run's trace, which asked for those
    attempted = np.zeros(len(whole), dtype=bool)
    attempted[:half] = run >= 0
    own = leave_products_out(
        Prior(
            whole.rows[attempted],
            whole.success[attempted],
            tuple(p for p, a in zip(whole.products, attempted, strict=True) if a),
        ),
        later_products,
    )
    fleet = leave_products_out(stream_prior(streams, [i for i in range(n_streams) if i != j]), later_products)
    both = Prior(
        np.vstack([fleet.rows, own.rows]),
        np.concatenate([fleet.success, own.success]),
        fleet.products + own.products,
    )
    priors = dict(zip(_OWN_STORE_CONDITIONS, (None, own, fleet, both), strict=True))
    traces = {k: _run(setup, streams, j, later, alpha, prior, 0) for k, prior in priors.items()}
    return traces, first_occurrences(streams.products[j][later]), len(own)


def _own_store_design(setup: _Setup, streams: UnseenStreams) -> dict[str, Any]:
    """Second halves: cold, the robot's own first-half attempts, the fleet, and both (products removed)."""
    per_alpha: dict[str, Any] = {}
    scored: list[np.ndarray] = []
    for alpha in UNSEEN_TARGETS:
        runs = [_own_store_stream(setup, streams, j, alpha) for j in range(len(streams.names))]
        scored = [m for _, m, _ in runs]
        pooled = {k: np.concatenate([t[k][m] for t, m, _ in runs]) for k in _OWN_STORE_CONDITIONS}
        per_alpha[f"{alpha:g}"] = {
            "own_store_rows": [n for _, _, n in runs],
            **{k: _with_promise(outcome_rates(v), alpha) for k, v in pooled.items()},
            "own_store_minus_cold": _paired_difference(pooled["cold"], pooled["own_store"], setup.seed),
            "fleet_minus_cold": _paired_difference(pooled["cold"], pooled["fleet"], setup.seed),
            "fleet_minus_own_store": _paired_difference(pooled["own_store"], pooled["fleet"], setup.seed),
            "fleet_and_own_store_minus_fleet": _paired_difference(
                pooled["fleet"], pooled["fleet_and_own_store"], setup.seed
            ),
        }
    return {
        "scored_decisions": int(sum(m.sum() for m in scored)),
        "targets": per_alpha,
    }


def _with_promise(rates: dict[str, Any], alpha: float) -> dict[str, Any]:
    afr = rates["attempt_failure_rate"]
    return {**rates, "keeps_promise": afr is not None and afr <= alpha + TOLERANCE + 1e-12}


def _mean(values: np.ndarray) -> float | None:
    v = values[np.isfinite(values)]
    return round(float(v.mean()), 4) if len(v) else None


def _quantiles(values: np.ndarray) -> dict[str, float | None]:
    v = values[np.isfinite(values)]
    if not len(v):
        return {"p10": None, "p50": None, "p90": None, "n": 0}
    return {
        **{f"p{q}": round(float(np.percentile(v, q)), 4) for q in (10, 50, 90)},
        "n": len(v),
    }


def _binned(
    pooled: dict[str, np.ndarray], values: np.ndarray, agrees: np.ndarray, edges: Sequence[float], unit: str
) -> dict[str, Any]:
    """Cold and fleet per bin of the nearest seen neighbour's distance, and the fleet's gain there."""
    out = {}
    for label, mask in _bins(values, edges, unit):
        cold, fleet = outcome_rates(pooled["cold"][mask]), outcome_rates(pooled["fleet"][mask])
        out[label] = {
            "decisions": int(mask.sum()),
            "neighbour_outcome_agrees": _mean(agrees[mask]),
            "cold": cold,
            "fleet": fleet,
            "success_gain": None
            if cold["success_rate"] is None
            else round(fleet["success_rate"] - cold["success_rate"], 4),
            "help_change": None
            if cold["help_rate"] is None
            else round(fleet["help_rate"] - cold["help_rate"], 4),
        }
    return out


def _verdict(fleet: dict[str, Any], own: dict[str, Any], default_alpha: float) -> dict[str, Any]:
    """Does a prior help on unseen products without breaking the promise, per α (both designs)?"""

    def helps(row: dict[str, Any], key: str, diff_key: str) -> bool:
        diff = row.get(diff_key, {}).get("success_rate")
        return bool(row[key]["keeps_promise"] and diff is not None and diff["ci95"][0] > 0)

    by_alpha = {
        a: {
            "fleet_helps": helps(fleet["targets"][a], "fleet", "fleet_minus_cold"),
            "own_store_helps": helps(own["targets"][a], "own_store", "own_store_minus_cold"),
            "fleet_helps_second_half": helps(own["targets"][a], "fleet", "fleet_minus_cold"),
        }
        for a in fleet["targets"]
    }
    return {
        "definition": (
            "helps: the prior's success rate on unseen-product decisions is higher than cold's with the paired "
            f"bootstrap's 95 % interval above 0, and its attempt failure rate is ≤ α + {TOLERANCE}"
        ),
        "by_alpha": by_alpha,
        "at_default": by_alpha.get(f"{default_alpha:g}"),
    }


def unseen_report(
    streams: UnseenStreams,
    replay: Replay,
    estimator: str,
    default_alpha: float,
    seed: int,
    warmup: int,
    opening_m: float,
    probe: ProbeOptions | None = None,
    excess_allowance: float | None = None,
) -> dict[str, Any]:
    """The ``unseen`` section of the gate report (module docstring).

    Args:
        streams: The replay's loaded streams (embeddings, perceived context, outcomes, products, probe readings).
        replay: benchmarks.replay.replay_stream.
        estimator: κ̂'s registry name (the tree's).
        default_alpha: The tree's target failure rate (where ``fleet_with_products`` is replayed).
        seed: Seeds each stream's replay (``seed + stream index``, as the gate report does) and the bootstrap.
        warmup: Decisions per stream not scored in the fleet design.
        opening_m: The gripper's opening, metres.
        probe: The heft test (None: off), as in the rest of the report.
        excess_allowance: The exploration credit (None: off).
    """
    setup = _Setup(replay, estimator, seed, warmup, opening_m, probe, excess_allowance)
    fleet = _fleet_design(setup, streams, default_alpha)
    own = _own_store_design(setup, streams)
    return {
        "estimator": estimator,
        "gate": "budget",
        "targets": list(UNSEEN_TARGETS),
        "tolerance": TOLERANCE,
        "unseen_definition": (
            "the product's first decision in its stream, every execution of it removed from the prior "
            "(leave-products-out)"
        ),
        "fleet": fleet,
        "own_store": own,
        "verdict": _verdict(fleet, own, default_alpha),
    }
