"""The three evaluation protocols of κ̂ and the online robot that ε-greedy serves.

Rows are taken in the dataset's order (shuffle 0, the seed's protocol; a dataset's rows are already in random
execution order), or in a seeded permutation for shuffles 1, 2, … . With n_max = the largest n_train (80):

- **algorithm1** (the seed's Algorithm 1): training prefix = the first n_max rows, test = the last n_test (20).
  For n_train = 10, 20, …, 80 an estimator is fitted on the first n_train rows and scored on the test rows.
- **novel_products**: the same fits, scored only on the test rows whose product occurs nowhere in the training
  prefix (rows 0 … n_max − 1); every such product is new to every fit. What a robot meets on a new shelf.
- **leave_family_out**: for each packaging family f of a dataset, training stream = the rows of the training
  prefix whose family is not f (in row order), test = every row of f in the dataset. Fitted at each of
  `lofo_steps` (capped at the stream's length; default only the whole stream, ≈ 75 rows: one fit per family
  already costs about twice Algorithm 1's fits). A dataset's accuracy pools its folds, so every row of a known
  family is tested once, by a model that never saw its family.

Per dataset the accuracy curve's normalised area is the paper's number; `auc` is its mean and std over the
datasets (× shuffles). AUROC, Brier score and ECE (10 bins) are computed at the largest step on the test
predictions of all datasets pooled (20 rows per dataset are too few for a per-dataset AUROC).

**ε-greedy** (`eps-X`): the belief is X's probability, never altered; exploration only changes which actions the
robot attempts (scone_bt.confidence.epsilon). So eps-X is scored in the online setting it exists for: the robot
walks the training prefix; at each row it attempts the action if `decide` says so (belief ≥ threshold, or an
exploration draw) and only then observes the outcome; otherwise it asks for help and learns nothing. The belief
scored at n_train is X fitted on the labels collected among the first n_train rows. κ̂ is refitted every
`refit_every` rows (default 10, the curve's step, to keep the grid's cost at about one fit per step). Next to it
the greedy robot (the same X with ε = 0) walks the same rows; both robots' behaviour is reported (attempts,
successes, failures, help requests, missed successes, regret). In leave_family_out, eps-X's training set is what
its robot collected along the prefix, less family f. Plain X is scored as the seed states: fitted on every label
of the prefix (an offline upper bound for either robot).
"""

from __future__ import annotations

import enum
import json
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from scone_bt.benchmarks.self_confidence.evaldata import UNKNOWN_FAMILY, EvalDataset
from scone_bt.benchmarks.self_confidence.metrics import (
    ReliabilityBin,
    accuracy,
    auroc,
    brier_score,
    ece_noise_floor,
    expected_calibration_error,
    normalised_auc,
    reliability_bins,
)
from scone_bt.confidence.base import ConfidenceEstimator
from scone_bt.errors import ConfigError

__all__ = [
    "CellResult",
    "EstimatorFactory",
    "EvalOptions",
    "FamilyFold",
    "PairResult",
    "Protocol",
    "ProtocolScores",
    "RobotBehaviour",
    "aggregate_cells",
    "algorithm1_split",
    "evaluate_calibrated_cells",
    "evaluate_cell",
    "evaluate_protocols",
    "leave_family_out_folds",
    "novel_product_rows",
    "row_order",
    "run_online",
]

EstimatorFactory = Callable[[int], ConfidenceEstimator]
"""Builds a fresh, untrained estimator from a seed."""


class Protocol(enum.Enum):
    """An evaluation protocol (values are the JSON keys)."""

    ALGORITHM1 = "algorithm1"
    NOVEL_PRODUCTS = "novel_products"
    LEAVE_FAMILY_OUT = "leave_family_out"


@dataclass(frozen=True)
class EvalOptions:
    """Protocol settings.

    Attributes:
        n_test: Rows at the end of each dataset's order used for testing (algorithm1, novel_products).
        steps: Training-set sizes n_train of algorithm1 / novel_products, increasing.
        lofo_steps: Training-set sizes of leave_family_out (fewer: it fits once per family and step).
        shuffles: Row orders: shuffle 0 is the dataset's own order, the others seeded permutations.
        seed: Base seed of the permutations, the estimators and ε-greedy draws.
        ece_bins: Equal-width bins of the calibration error and the reliability diagram.
        threshold: The robot attempts (and success is predicted) when the belief ≥ threshold.
        epsilon: ε₀ of the ε-greedy robot.
        half_life: Observed outcomes after which ε halves.
        refit_every: The online robots refit κ̂ every this many rows of the stream.
    """

    n_test: int = 20
    steps: tuple[int, ...] = (10, 20, 30, 40, 50, 60, 70, 80)
    lofo_steps: tuple[int, ...] = (80,)
    shuffles: int = 1
    seed: int = 0
    ece_bins: int = 10
    threshold: float = 0.5
    epsilon: float = 0.3
    half_life: float = 20.0
    refit_every: int = 10

    def __post_init__(self) -> None:
        if self.n_test < 1 or self.shuffles < 1 or not self.steps or not self.lofo_steps:
            raise ConfigError("n_test and shuffles must be ≥ 1 and steps, lofo_steps non-empty")
        for name in ("steps", "lofo_steps"):
            s = list(getattr(self, name))
            if s != sorted(set(s)) or s[0] < 1:
                raise ConfigError(f"{name} must be distinct, increasing and ≥ 1, got {s}")
        if self.refit_every < 1:
            raise ConfigError(f"refit_every must be ≥ 1, got {self.refit_every}")

    @property
    def min_rows(self) -> int:
        """Rows a dataset needs: the largest n_train plus the test rows."""
        return self.steps[-1] + self.n_test


# ----------------------------------------------------------------------------------------------- splits
def row_order(n: int, shuffle: int, dataset_index: int, seed: int = 0) -> np.ndarray:
    """The row order of one dataset: its own for shuffle 0, else a permutation seeded by (seed, shuffle, index)."""
    if shuffle == 0:
        return np.arange(n)
    return np.random.default_rng([seed, shuffle, dataset_index]).permutation(n)


def algorithm1_split(order: np.ndarray, options: EvalOptions) -> tuple[np.ndarray, np.ndarray]:
    """(training prefix, test rows): the first max(steps) and the last n_test rows of `order`."""
    if len(order) < options.min_rows:
        raise ConfigError(
            f"{len(order)} rows; n_train up to {options.steps[-1]} plus {options.n_test} test rows "
            f"needs {options.min_rows}"
        )
    return order[: options.steps[-1]], order[-options.n_test :]


def novel_product_rows(objects: Sequence[str], prefix: np.ndarray, test: np.ndarray) -> np.ndarray:
    """The test rows whose product occurs nowhere in the training prefix (in test order)."""
    seen = {objects[i] for i in prefix}
    return np.array([i for i in test if objects[i] not in seen], dtype=int)


@dataclass(frozen=True)
class FamilyFold:
    """One leave-one-family-out fold.

    Attributes:
        family: The held-out packaging family.
        train: Rows of every other family, in row order (the training stream).
        test: Rows of `family`.
    """

    family: str
    train: np.ndarray
    test: np.ndarray


def leave_family_out_folds(families: Sequence[str], prefix: np.ndarray, rows: np.ndarray) -> list[FamilyFold]:
    """One fold per known family among `rows`: train on the prefix rows of other families, test on its rows.

    A fold without training rows is dropped.
    """
    fam = np.asarray(families, dtype=object)
    folds = []
    for f in sorted({str(fam[i]) for i in rows} - {UNKNOWN_FAMILY}):
        train = prefix[fam[prefix] != f]
        if len(train):
            folds.append(FamilyFold(f, train, rows[fam[rows] == f]))
    return folds


# ----------------------------------------------------------------------------------------------- online robot
@dataclass(frozen=True)
class RobotBehaviour:
    """What an online robot did along a training stream (counts of rows).

    Attributes:
        rows: Rows walked.
        attempts: Actions attempted (each gave a label).
        successes: Attempts that succeeded.
        failures: Attempts that failed.
        help_requests: Rows where the robot asked for help (no label).
        missed_successes: Help requests for actions that would have succeeded.
        explorations: Attempts made although the belief was below the threshold.
    """

    rows: int = 0
    attempts: int = 0
    successes: int = 0
    failures: int = 0
    help_requests: int = 0
    missed_successes: int = 0
    explorations: int = 0

    @property
    def regret(self) -> int:
        """Decisions an oracle that knows the outcome would have made otherwise: failures + missed successes."""
        return self.failures + self.missed_successes

    def __add__(self, other: RobotBehaviour) -> RobotBehaviour:
        return RobotBehaviour(*(a + b for a, b in zip(self._tuple(), other._tuple(), strict=True)))

    def _tuple(self) -> tuple[int, ...]:
        return (
            self.rows,
            self.attempts,
            self.successes,
            self.failures,
            self.help_requests,
            self.missed_successes,
            self.explorations,
        )

    def to_dict(self) -> dict[str, int]:
        """JSON-ready counts, regret included."""
        names = (
            "rows",
            "attempts",
            "successes",
            "failures",
            "help_requests",
            "missed_successes",
            "explorations",
        )
        return {**dict(zip(names, self._tuple(), strict=True)), "regret": self.regret}


def run_online(
    est: ConfidenceEstimator,
    stream: np.ndarray,
    X: np.ndarray,
    y: np.ndarray,
    stops: Sequence[int],
    eval_rows: np.ndarray,
    options: EvalOptions,
) -> tuple[dict[int, np.ndarray], RobotBehaviour, np.ndarray]:
    """Walk `stream` as the robot: attempt when `est.decide` says so, learn only from attempts.

    Returns:
        The belief on `eval_rows` after the first n rows of the stream, for each n in `stops` (capped at the
        stream's length); the robot's behaviour over the first max(stops) rows; the rows it attempted (the
        labels it collected), in stream order.
    """
    last = min(stops[-1], len(stream))
    observed: list[int] = []
    fitted_on = -1
    beliefs: dict[int, np.ndarray] = {}
    counts = dict.fromkeys(
        ("attempts", "successes", "failures", "help_requests", "missed_successes", "explorations"), 0
    )
    wanted = {min(s, last): s for s in stops}
    for i in range(last + 1):
        if (i % options.refit_every == 0 or i in wanted) and fitted_on != len(observed):
            est.fit(X[observed], y[observed])
            fitted_on = len(observed)
        if i in wanted:
            p = est.belief(X[eval_rows]) if len(eval_rows) else np.zeros(0)
            for s in stops:
                if min(s, last) == i:
                    beliefs[s] = p
        if i == last:
            break
        r = int(stream[i])
        x = X[r : r + 1]
        act = bool(est.decide(x, options.threshold)[0])
        if act:
            counts["attempts"] += 1
            counts["successes" if y[r] else "failures"] += 1
            counts["explorations"] += int(est.belief(x)[0] < options.threshold)
            observed.append(r)
        else:
            counts["help_requests"] += 1
            counts["missed_successes"] += int(y[r])
    return beliefs, RobotBehaviour(rows=last, **counts), np.array(observed, dtype=int)


def _base_of(est: ConfidenceEstimator) -> ConfidenceEstimator:
    """A wrapper's fitted base estimator (a calibrated estimator's `base`), which `with_base` scores too."""
    base = getattr(est, "base", None)
    if not isinstance(base, ConfidenceEstimator):
        raise ConfigError(
            f"{est.name}: with_base needs an estimator with a base estimator, not {type(est).__name__}"
        )
    return base


def _offline(
    make: EstimatorFactory,
    seed: int,
    stream: np.ndarray,
    X: np.ndarray,
    y: np.ndarray,
    stops: Sequence[int],
    eval_rows: np.ndarray,
    with_base: bool = False,
) -> list[dict[int, np.ndarray]]:
    """Belief on eval_rows of a fresh estimator fitted on the first n rows of the stream, per n in stops.

    Returns [the estimator's beliefs], or with `with_base` [its beliefs, its fitted `base` estimator's beliefs].
    """
    out: list[dict[int, np.ndarray]] = [{}, {}] if with_base else [{}]
    for n in stops:
        rows = stream[: min(n, len(stream))]
        est = make(seed)
        est.fit(X[rows], y[rows])
        views = (est, _base_of(est)) if with_base else (est,)
        for beliefs, view in zip(out, views, strict=True):
            beliefs[n] = view.belief(X[eval_rows]) if len(eval_rows) else np.zeros(0)
    return out


# ----------------------------------------------------------------------------------------------- results
@dataclass(frozen=True)
class ProtocolScores:
    """One protocol's numbers for one pair.

    Attributes:
        protocol: Which protocol.
        steps: n_train values of the curve.
        auc: Normalised area of each dataset's accuracy curve (datasets × shuffles with test rows).
        curve_mean: Accuracy per step, mean over those datasets.
        curve_std: Its std over them.
        final_accuracy: Accuracy at the largest step per dataset.
        auroc: AUROC at the largest step, all test predictions pooled (NaN with one class).
        brier: Brier score at the largest step, pooled.
        ece: Expected calibration error at the largest step, pooled.
        ece_floor: (mean, 95th percentile) ECE of a perfectly calibrated predictor with the same pooled
            predictions (metrics.ece_noise_floor): the ECE that sampling noise alone gives on n_test rows.
        reliability: The reliability diagram's bins at the largest step, pooled.
        n_test: Test predictions pooled at the largest step (all datasets and shuffles).
        n_datasets: Datasets × shuffles with at least one test row.
        groups: The dataset (index into the evaluated datasets) of each `auc` value.
    """

    protocol: Protocol
    steps: tuple[int, ...]
    auc: tuple[float, ...]
    curve_mean: tuple[float, ...]
    curve_std: tuple[float, ...]
    final_accuracy: tuple[float, ...]
    auroc: float
    brier: float
    ece: float
    ece_floor: tuple[float, float]
    reliability: tuple[ReliabilityBin, ...]
    n_test: int
    n_datasets: int
    groups: tuple[int, ...]

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready numbers (NaN stays NaN; the writer turns it into null)."""
        return {
            # per dataset (its shuffles averaged), with the datasets' indices: pairs are compared dataset by dataset
            "auc": {**_mean_std(self.auc), **_per_dataset(self.auc, self.groups)},
            "auroc": self.auroc,
            "brier": self.brier,
            "ece": self.ece,
            "ece_noise_floor": {"mean": self.ece_floor[0], "p95": self.ece_floor[1]},
            "final_accuracy": _mean_std(self.final_accuracy),
            "accuracy_curve": {
                "n_train": list(self.steps),
                "mean": list(self.curve_mean),
                "std": list(self.curve_std),
            },
            "n_test": self.n_test,
            "n_datasets": self.n_datasets,
            "reliability": [
                {
                    "lower": b.lower,
                    "upper": b.upper,
                    "count": b.count,
                    "mean_predicted": b.mean_predicted,
                    "observed_rate": b.observed_rate,
                }
                for b in self.reliability
            ],
        }


def _per_dataset(auc: Sequence[float], groups: Sequence[int]) -> dict[str, list]:
    """AUC per dataset, the mean over its shuffles, and the datasets' indices (shuffles are not independent)."""
    index = sorted(set(groups))
    values = [float(np.mean([a for a, k in zip(auc, groups, strict=True) if k == i])) for i in index]
    return {"per_dataset": values, "dataset_index": index}


def _mean_std(values: Sequence[float]) -> dict[str, float]:
    v = np.asarray(values, dtype=float)
    if len(v) == 0 or np.all(np.isnan(v)):
        return {"mean": float("nan"), "std": float("nan")}
    return {"mean": float(np.nanmean(v)), "std": float(np.nanstd(v))}


@dataclass(frozen=True, eq=False)
class PairResult:
    """Every protocol's numbers for one embedder × estimator pair.

    Attributes:
        embedder: Embedder name.
        estimator: Estimator name.
        scores: Per protocol evaluated.
        robot: For eps-X: {"epsilon": behaviour of the ε-greedy robot, "greedy": of the same X with ε = 0,
            "greedy_auc": the greedy robot's belief scored by algorithm1}, summed over datasets; else None.
        wall_s: Wall time of this pair's evaluation, seconds (not compared).
    """

    embedder: str
    estimator: str
    scores: dict[Protocol, ProtocolScores]
    robot: dict[str, Any] | None = None
    wall_s: float = field(default=0.0, compare=False)

    @property
    def auc(self) -> tuple[float, ...]:
        """Algorithm 1's per-dataset AUCs (the paper's number), or the first protocol's."""
        s = self.scores.get(Protocol.ALGORITHM1) or next(iter(self.scores.values()))
        return s.auc

    def entry(self, protocol: Protocol) -> dict[str, Any]:
        """The JSON entry of one protocol: {embedder, estimator, auc: {mean, std}, auroc, brier, ece, …}."""
        out = {"embedder": self.embedder, "estimator": self.estimator, **self.scores[protocol].to_dict()}
        if self.robot is not None and protocol is Protocol.ALGORITHM1:
            out["robot"] = self.robot
        out["pair_wall_s"] = round(self.wall_s, 2)  # every protocol of the pair together
        return out

    def to_dict(self) -> dict[str, Any]:
        """Every protocol's entry, keyed by protocol value."""
        return {p.value: self.entry(p) for p in self.scores}

    def __eq__(self, other: object) -> bool:  # NaN-safe: compare the serialised numbers
        if not isinstance(other, PairResult):
            return NotImplemented
        mine, theirs = self.to_dict(), other.to_dict()
        for d in (*mine.values(), *theirs.values()):
            d.pop("pair_wall_s", None)
        return json.dumps(mine, sort_keys=True) == json.dumps(theirs, sort_keys=True)

    def __hash__(self) -> int:
        return hash((self.embedder, self.estimator))


def _scores(
    protocol: Protocol,
    steps: Sequence[int],
    cells: list[tuple[dict[int, np.ndarray], np.ndarray]],
    groups: Sequence[int] = (),
    *,
    options: EvalOptions,
) -> ProtocolScores:
    """Scores from (beliefs per step, labels) of each dataset × shuffle cell; `groups`: each cell's dataset."""
    groups = list(groups) if len(groups) == len(cells) else list(range(len(cells)))
    kept = [i for i, (_, y) in enumerate(cells) if len(y)]
    cells, groups = [cells[i] for i in kept], [groups[i] for i in kept]
    curves = np.array([[accuracy(b[n], y, options.threshold) for n in steps] for b, y in cells]).reshape(
        len(cells), len(steps)
    )
    last = steps[-1]
    p_all = np.concatenate([b[last] for b, _ in cells]) if cells else np.zeros(0)
    y_all = np.concatenate([y for _, y in cells]) if cells else np.zeros(0, dtype=bool)
    nan_row = [float("nan")] * len(steps)
    return ProtocolScores(
        protocol=protocol,
        steps=tuple(steps),
        auc=tuple(normalised_auc(steps, c) for c in curves),
        curve_mean=tuple(float(v) for v in curves.mean(axis=0)) if len(cells) else tuple(nan_row),
        curve_std=tuple(float(v) for v in curves.std(axis=0)) if len(cells) else tuple(nan_row),
        final_accuracy=tuple(float(c[-1]) for c in curves),
        auroc=auroc(p_all, y_all),
        brier=brier_score(p_all, y_all),
        ece=expected_calibration_error(p_all, y_all, options.ece_bins),
        ece_floor=ece_noise_floor(p_all, options.ece_bins, seed=options.seed),
        reliability=tuple(reliability_bins(p_all, y_all, options.ece_bins)),
        n_test=len(y_all),
        n_datasets=len(cells),
        groups=tuple(groups),
    )


Beliefs = dict[int, np.ndarray]
"""Belief on the evaluated rows per n_train."""


@dataclass(frozen=True)
class CellResult:
    """One dataset × shuffle of one pair: the beliefs and labels every protocol scores (what a cache stores).

    Attributes:
        a1: (beliefs on the test rows, their labels), or None if algorithm1/novel_products were not run.
        novel: (beliefs on the novel test rows, their labels), or None.
        lofo: (beliefs on every held-out row, their labels), or None (no known family, or not run).
        greedy: For eps-X, the greedy robot's (beliefs, labels) on the test rows; else None.
        robot_eps: For eps-X, the ε-greedy robot's behaviour; else None.
        robot_greedy: For eps-X, the greedy robot's behaviour; else None.
        wall_s: Seconds this cell took.
    """

    a1: tuple[Beliefs, np.ndarray] | None
    novel: tuple[Beliefs, np.ndarray] | None
    lofo: tuple[Beliefs, np.ndarray] | None
    greedy: tuple[Beliefs, np.ndarray] | None = None
    robot_eps: RobotBehaviour | None = None
    robot_greedy: RobotBehaviour | None = None
    wall_s: float = 0.0

    def to_json(self) -> dict[str, Any]:
        """Exact JSON form (floats round-trip through repr)."""

        def part(v: tuple[Beliefs, np.ndarray] | None) -> Any:
            if v is None:
                return None
            return {"beliefs": {str(n): b.tolist() for n, b in v[0].items()}, "labels": v[1].tolist()}

        def beh(b: RobotBehaviour | None) -> Any:
            return None if b is None else list(b._tuple())

        return {
            "a1": part(self.a1),
            "novel": part(self.novel),
            "lofo": part(self.lofo),
            "greedy": part(self.greedy),
            "robot_eps": beh(self.robot_eps),
            "robot_greedy": beh(self.robot_greedy),
            "wall_s": self.wall_s,
        }

    @classmethod
    def from_json(cls, d: dict[str, Any]) -> CellResult:
        """Inverse of to_json."""

        def part(v: Any) -> tuple[Beliefs, np.ndarray] | None:
            if v is None:
                return None
            beliefs = {int(n): np.asarray(b, dtype=float) for n, b in v["beliefs"].items()}
            return beliefs, np.asarray(v["labels"], dtype=bool)

        def beh(v: Any) -> RobotBehaviour | None:
            return None if v is None else RobotBehaviour(*v)

        return cls(
            part(d["a1"]),
            part(d["novel"]),
            part(d["lofo"]),
            part(d["greedy"]),
            beh(d["robot_eps"]),
            beh(d["robot_greedy"]),
            float(d.get("wall_s", 0.0)),
        )


def evaluate_cell(
    estimator: str,
    data: EvalDataset,
    X: np.ndarray,
    dataset_index: int,
    shuffle: int,
    make: EstimatorFactory,
    protocols: Sequence[Protocol] = tuple(Protocol),
    options: EvalOptions = EvalOptions(),
    make_greedy: EstimatorFactory | None = None,
) -> CellResult:
    """One dataset in one row order (see the module docstring); "eps-…" estimators run online."""
    cells = _evaluate_cells(estimator, data, X, dataset_index, shuffle, make, protocols, options, make_greedy)
    return cells[0]


def evaluate_calibrated_cells(
    estimator: str,
    data: EvalDataset,
    X: np.ndarray,
    dataset_index: int,
    shuffle: int,
    make: EstimatorFactory,
    protocols: Sequence[Protocol] = tuple(Protocol),
    options: EvalOptions = EvalOptions(),
) -> tuple[CellResult, CellResult]:
    """The cells of a calibrated "<name>-cal" estimator and of <name> itself, from the same fits.

    A calibrated estimator refits its base on every training row after the out-of-fold fits, with the same seed:
    that base is the plain estimator fitted on the same rows, so its beliefs are the plain estimator's cell
    without fitting it again. The calibrated cell's wall_s covers both; the base cell's is 0.
    """
    if not estimator.endswith("-cal"):
        raise ConfigError(f"{estimator} is not a calibrated estimator (<name>-cal)")
    cal, base = _evaluate_cells(
        estimator, data, X, dataset_index, shuffle, make, protocols, options, None, True
    )
    return cal, base


def _evaluate_cells(
    estimator: str,
    data: EvalDataset,
    X: np.ndarray,
    dataset_index: int,
    shuffle: int,
    make: EstimatorFactory,
    protocols: Sequence[Protocol],
    options: EvalOptions,
    make_greedy: EstimatorFactory | None,
    with_base: bool = False,
) -> list[CellResult]:
    """evaluate_cell, or with `with_base` (offline estimators only) [its cell, its fitted base's cell]."""
    t0 = time.perf_counter()
    online = estimator.startswith("eps-")
    if online and with_base:
        raise ConfigError(f"{estimator}: base cells come from offline fits only")
    steps = options.steps
    want_a1 = Protocol.ALGORITHM1 in protocols or Protocol.NOVEL_PRODUCTS in protocols
    seed = options.seed * 1000 + shuffle
    views = 2 if with_base else 1

    def make_plain(seed: int) -> ConfidenceEstimator:  # eps-X's belief is X's: fitting needs no exploration
        return _greedy_of(make(seed)) if online else make(seed)

    y = data.success
    order = row_order(len(data), shuffle, dataset_index, options.seed)
    prefix, test = algorithm1_split(order, options)
    collected = prefix  # the labels a learner had: every prefix row, or what its robot attempted
    a1: list[tuple[Beliefs, np.ndarray] | None] = [None] * views
    novel: list[tuple[Beliefs, np.ndarray] | None] = [None] * views
    lofo: list[tuple[Beliefs, np.ndarray] | None] = [None] * views
    greedy_cell = None
    beh = g_beh = None
    if want_a1 or online:
        if online:
            beliefs, beh, collected = run_online(make(seed), prefix, X, y, steps, test, options)
            greedy = make_greedy(seed) if make_greedy else _greedy_of(make(seed))
            g_beliefs, g_beh, _ = run_online(greedy, prefix, X, y, steps, test, options)
            greedy_cell = (g_beliefs, y[test])
            per_view = [beliefs]
        else:
            per_view = _offline(make, seed, prefix, X, y, steps, test, with_base)
        rows = novel_product_rows(data.objects, prefix, test)
        pos = {int(r): k for k, r in enumerate(test)}
        keep = np.array([pos[int(r)] for r in rows], dtype=int)
        for v, b in enumerate(per_view):
            a1[v] = (b, y[test])
            novel[v] = ({n: p[keep] for n, p in b.items()}, y[rows])
    if Protocol.LEAVE_FAMILY_OUT in protocols:
        lsteps = options.lofo_steps
        per_step: list[dict[int, list[np.ndarray]]] = [{n: [] for n in lsteps} for _ in range(views)]
        labels = []
        for fold in leave_family_out_folds(data.families, collected, order):
            fold_views = _offline(make_plain, seed, fold.train, X, y, lsteps, fold.test, with_base)
            for v, b in enumerate(fold_views):
                for n in lsteps:
                    per_step[v][n].append(b[n])
            labels.append(y[fold.test])
        if labels:
            for v in range(views):
                lofo[v] = ({n: np.concatenate(p) for n, p in per_step[v].items()}, np.concatenate(labels))
    wall = time.perf_counter() - t0
    cells = [CellResult(a1[0], novel[0], lofo[0], greedy_cell, beh, g_beh, wall)]
    if with_base:
        cells.append(CellResult(a1[1], novel[1], lofo[1], None, None, None, 0.0))
    return cells


def aggregate_cells(
    embedder: str,
    estimator: str,
    cells: Sequence[CellResult],
    protocols: Sequence[Protocol],
    options: EvalOptions,
) -> PairResult:
    """A pair's scores from its cells (every dataset × shuffle)."""
    steps = options.steps
    # cells come shuffle by shuffle, each over every dataset in order (evaluate_protocols, the grid's tasks)
    n_data = max(len(cells) // options.shuffles, 1)

    def part(get: Callable[[CellResult], Any]) -> tuple[list, list[int]]:
        kept = [(get(c), i % n_data) for i, c in enumerate(cells) if get(c) is not None]
        return [k[0] for k in kept], [k[1] for k in kept]

    scores: dict[Protocol, ProtocolScores] = {}
    for p in protocols:
        if p is Protocol.ALGORITHM1:
            scores[p] = _scores(p, steps, *part(lambda c: c.a1), options=options)
        elif p is Protocol.NOVEL_PRODUCTS:
            scores[p] = _scores(p, steps, *part(lambda c: c.novel), options=options)
        else:
            scores[p] = _scores(p, options.lofo_steps, *part(lambda c: c.lofo), options=options)
    robot = None
    greedy = [c.greedy for c in cells if c.greedy is not None]
    if greedy:
        g = _scores(Protocol.ALGORITHM1, steps, greedy, options=options)
        eps_total, greedy_total = RobotBehaviour(), RobotBehaviour()
        for c in cells:
            eps_total += c.robot_eps or RobotBehaviour()
            greedy_total += c.robot_greedy or RobotBehaviour()
        robot = {
            "epsilon": eps_total.to_dict(),
            "greedy": greedy_total.to_dict(),
            "greedy_auc": _mean_std(g.auc),
            "epsilon0": options.epsilon,
            "half_life": options.half_life,
            "refit_every": options.refit_every,
        }
    return PairResult(embedder, estimator, scores, robot, sum(c.wall_s for c in cells))


def evaluate_protocols(
    embedder: str,
    estimator: str,
    datasets: Sequence[EvalDataset],
    features: Sequence[np.ndarray],
    make: EstimatorFactory,
    protocols: Sequence[Protocol] = tuple(Protocol),
    options: EvalOptions = EvalOptions(),
    make_greedy: EstimatorFactory | None = None,
) -> PairResult:
    """Evaluate one pair under each protocol (see the module docstring).

    Args:
        embedder: Name recorded in the result.
        estimator: Name recorded in the result; "eps-…" selects the online ε-greedy setting.
        datasets: The datasets.
        features: Input rows per dataset (embeddings, or embedding + context for grounded estimators).
        make: Fresh estimator from a seed.
        protocols: Which protocols to run.
        options: Settings.
        make_greedy: For eps-X, the same X without exploration (the greedy robot); default: make's base.
    """
    if not datasets:
        raise ConfigError("no datasets to evaluate")
    cells = [
        evaluate_cell(estimator, data, X, di, s, make, protocols, options, make_greedy)
        for s in range(options.shuffles)
        for di, (data, X) in enumerate(zip(datasets, features, strict=True))
    ]
    return aggregate_cells(embedder, estimator, cells, protocols, options)


def _greedy_of(est: ConfidenceEstimator) -> ConfidenceEstimator:
    """The estimator an ε-greedy wrapper explores with, used alone (ε = 0)."""
    return getattr(est, "base", est)
