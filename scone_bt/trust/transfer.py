"""Trust that transfers across actions through ζ, fitted to real human ratings (Soh et al., tools/data/trust).

A person's trust that the robot can do action ``t``, after seeing outcomes on actions ``o``, on the logit scale:

    logit trust(t) = bias + Σ_j w_j · cos(ζ(t), ζ(anchor_j)) + u_p + Σ_o k(t, o) · (g_s if o succeeded else -g_f)
    k(t, o) = exp(-(1 - cos(ζ(t), ζ(o))) / length_scale)

ζ is the project's embedder (MiniLM by default); the anchors are the tasks of the data set, so the prior (what a
person expects before seeing anything) generalises to any action text by its similarity to them; ``u_p ~ Normal(0,
disposition_sd)`` is a person's disposition. An outcome moves trust most in the action itself (k = 1) and less in
actions ζ places far from it. Ratings r (1-7) are on the paper's scale ``sigmoid(r - 3.5)``, so the logit is just
``r - 3.5``. Parameters are fitted by maximising the Bernoulli likelihood of the ratings on that scale (the paper's
loss) with an L2 penalty on the anchor weights; `scone-bench trust` evaluates the fit on the paper's splits.
"""

from __future__ import annotations

import functools
import json
from collections.abc import Callable, Iterator, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from scone_bt.errors import SconeError
from scone_bt.trust.data import TrustDataset, rating_to_trust

__all__ = [
    "CLIP",
    "FITTED_PARAMETERS",
    "Observation",
    "SPLITS",
    "TransferModel",
    "TransferParameters",
    "TrustRows",
    "disposition_sd",
    "fit_transfer",
    "fit_vector",
    "load_fitted",
    "paper_splits",
    "predict_rows",
    "rows_of",
]

FITTED_PARAMETERS = Path(__file__).with_name("fitted.json")
"""The household fit `scone-study simulate` and `power` use by default (written by `scone-bench trust --write`)."""
CLIP = (0.01, 0.99)
"""Predictions are clipped to this range before MAE and NLL, as the paper's models clip theirs."""
SPLITS: tuple[str, ...] = ("participants", "tasks")


@dataclass(frozen=True)
class Observation:
    """An outcome the person saw: the action text and whether the robot succeeded."""

    action: str
    success: bool


@dataclass(frozen=True)
class TransferParameters:
    """The fitted trust-transfer model (all effects on the logit scale of trust).

    Attributes:
        bias: Prior trust (logit) of an action unlike every anchor.
        success_gain: Logit gained per success seen on the same action (k = 1).
        failure_loss: Logit lost per failure seen on the same action.
        length_scale: Kernel width, in cosine distance (1 - cos) of ζ.
        anchors: Texts of the data set's tasks; the prior is linear in the cosines to them.
        anchor_weights: Logit per unit cosine to each anchor.
        disposition_sd: Between-person sd of trust (logit), from the before-ratings.
        embedder: ζ the cosines are taken in (a `load_embedder` name).
        source: What the parameters were fitted to.
    """

    bias: float
    success_gain: float
    failure_loss: float
    length_scale: float
    anchors: tuple[str, ...]
    anchor_weights: tuple[float, ...]
    disposition_sd: float
    embedder: str = "minilm"
    source: str = ""

    def __post_init__(self) -> None:
        if len(self.anchors) != len(self.anchor_weights):
            raise SconeError(
                f"trust transfer: {len(self.anchors)} anchors but {len(self.anchor_weights)} anchor_weights"
            )
        if self.length_scale <= 0 or self.disposition_sd < 0:
            raise SconeError("trust transfer: length_scale must be positive and disposition_sd non-negative")

    def to_json(self) -> str:
        return json.dumps(asdict(self), indent=1) + "\n"

    @classmethod
    def from_json(cls, text: str, where: str = "trust parameters") -> TransferParameters:
        try:
            raw = json.loads(text)
            raw["anchors"], raw["anchor_weights"] = tuple(raw["anchors"]), tuple(raw["anchor_weights"])
            return cls(**raw)
        except (ValueError, TypeError, KeyError) as exc:
            raise SconeError(f"{where}: not a trust-transfer parameter file ({exc})") from None


def load_fitted(path: Path | None = None) -> TransferParameters:
    """The committed fit (FITTED_PARAMETERS) or another parameter file."""
    path = path or FITTED_PARAMETERS
    if not path.is_file():
        raise SconeError(f"{path}: trust parameter file not found (write it with scone-bench trust --write)")
    return TransferParameters.from_json(path.read_text(), str(path))


@functools.lru_cache(maxsize=4)
def _embedder(name: str):  # noqa: ANN202 - an Embedder, imported lazily (sentence-transformers is heavy)
    from scone_bt.embedding import load_embedder

    return load_embedder(name)


class TransferModel:
    """Trust per action from what a person saw: the fitted model with ζ's cosines.

    Args:
        params: The model.
        embed: Texts -> unit vectors (default: the parameters' embedder, loaded once per process).
    """

    def __init__(
        self, params: TransferParameters, embed: Callable[[Sequence[str]], np.ndarray] | None = None
    ) -> None:
        self.params = params
        self._embed = embed or (lambda texts: _embedder(params.embedder).embed(list(texts)))
        self._anchors = self._embed(params.anchors)
        self._weights = np.asarray(params.anchor_weights, dtype=float)

    def vectors(self, texts: Sequence[str]) -> np.ndarray:
        return np.asarray(self._embed(list(texts)), dtype=float)

    def prior_logit(self, texts: Sequence[str]) -> np.ndarray:
        """Trust (logit) before seeing anything, for a person of average disposition."""
        return self.params.bias + (self.vectors(texts) @ self._anchors.T) @ self._weights

    def kernel(self, targets: Sequence[str], seen: Sequence[str]) -> np.ndarray:
        """k(t, o) for every target t (rows) and seen action o (columns)."""
        if not seen:
            return np.zeros((len(targets), 0))
        cos = self.vectors(targets) @ self.vectors(seen).T
        return np.exp(-(1.0 - cos) / self.params.length_scale)

    def logit(
        self, targets: Sequence[str], seen: Sequence[Observation], disposition: float = 0.0
    ) -> np.ndarray:
        """Trust (logit) in each target after the observations, for a person with `disposition` (logit)."""
        p = self.params
        signs = np.array([p.success_gain if o.success else -p.failure_loss for o in seen], dtype=float)
        k = self.kernel(targets, [o.action for o in seen])
        return self.prior_logit(targets) + disposition + (k @ signs if len(seen) else 0.0)

    def trust(
        self, targets: Sequence[str], seen: Sequence[Observation], disposition: float = 0.0
    ) -> np.ndarray:
        """Trust (probability) in each target."""
        return 1.0 / (1.0 + np.exp(-self.logit(targets, seen, disposition)))


# ----------------------------------------------------------------------------------------------- fitting
@dataclass(frozen=True)
class TrustRows:
    """Ratings as rows in the paper's order (before-ratings of C, D, E by participant, then after-ratings).

    Attributes:
        task: 0-based index of the rated task (into the similarity matrix).
        observed: (n, 2) 0-based indices of the tasks seen, -1 where none (before-ratings).
        success: 1.0 where the seen outcomes were successes.
        target: Rating on the (0, 1) scale, sigmoid(r - 3.5).
        participant: 0-based participant index.
    """

    task: np.ndarray
    observed: np.ndarray
    success: np.ndarray
    target: np.ndarray
    participant: np.ndarray

    def __len__(self) -> int:
        return len(self.task)

    def take(self, index: Sequence[int]) -> TrustRows:
        i = np.asarray(index, dtype=int)
        return TrustRows(self.task[i], self.observed[i], self.success[i], self.target[i], self.participant[i])


def rows_of(data: TrustDataset) -> TrustRows:
    """The data set as rows, ordered exactly as the paper's createDataset orders its predictions."""
    ids = sorted(data.tasks)
    pos = {t: i for i, t in enumerate(ids)}
    task, observed, success, target, who = [], [], [], [], []
    for after in (False, True):
        for c in range(3):
            for r in data.records:
                task.append(pos[r.predicted[c]])
                observed.append([pos[o] for o in r.observed] if after else [-1, -1])
                success.append(float(r.success))
                target.append(rating_to_trust((r.after if after else r.before)[c]))
                who.append(r.participant)
    return TrustRows(np.array(task), np.array(observed), np.array(success), np.array(target), np.array(who))


def paper_splits(data: TrustDataset, kind: str) -> Iterator[list[int]]:
    """Test rows of each fold of the paper's splits (runExperiment.getTrainTestValSplit), in its order.

    participants: 10 folds of int(N / 10) participants (0-2, 3-5, ...), each with all six of their ratings.
    tasks: one fold per task id 1-12: every rating of that task, and the after-ratings of those who saw it.
    """
    n = data.participants
    if kind == "participants":
        per = n // 10
        for k in range(10):
            yield [i * n + p for p in range(k * per, (k + 1) * per) for i in range(6)]
    elif kind == "tasks":
        rows = rows_of(data)
        ids = sorted(data.tasks)
        for t, tid in enumerate(ids):
            test = {i for i in range(len(rows)) if rows.task[i] == t}
            for r in data.records:
                if tid in r.observed:
                    test |= {3 * n + i * n + r.participant for i in range(3)}
            yield sorted(test)
    else:
        raise SconeError(f"unknown split {kind!r}; valid: {', '.join(SPLITS)}")


def _unpack(theta: np.ndarray) -> tuple[float, float, float, float, np.ndarray]:
    return theta[0], np.exp(theta[1]), np.exp(theta[2]), np.exp(theta[3]), theta[4:]


def predict_rows(theta: np.ndarray, sim: np.ndarray, rows: TrustRows) -> np.ndarray:
    """Trust (probability) for each row under the packed parameters θ = (bias, log g_s, log g_f, log ℓ, w...)."""
    bias, gs, gf, ell, w = _unpack(theta)
    mu = bias + sim[rows.task] @ w
    obs = rows.observed
    cos = sim[rows.task[:, None], np.maximum(obs, 0)]
    k = np.where(obs >= 0, np.exp(-(1.0 - cos) / ell), 0.0).sum(axis=1)
    return 1.0 / (1.0 + np.exp(-(mu + k * np.where(rows.success > 0, gs, -gf))))


def fit_vector(sim: np.ndarray, rows: TrustRows, l2: float = 1.0) -> np.ndarray:
    """Packed θ maximising the Bernoulli likelihood of the rows' ratings (L-BFGS, deterministic start)."""
    from scipy.optimize import minimize

    y = rows.target

    def loss(theta: np.ndarray) -> float:
        p = np.clip(predict_rows(theta, sim, rows), 1e-9, 1 - 1e-9)
        nll = -np.mean(y * np.log(p) + (1 - y) * np.log(1 - p))
        return float(nll + l2 * np.sum(theta[4:] ** 2) / len(rows))

    theta0 = np.concatenate([[0.5, 0.0, 0.0, np.log(0.3)], np.zeros(sim.shape[0])])
    return minimize(loss, theta0, method="L-BFGS-B").x


def disposition_sd(data: TrustDataset) -> float:
    """Between-person sd (logit) of the before-ratings, task means removed (one-way random-effects moments)."""
    logit = np.array([[b - 3.5 for b in r.before] for r in data.records], dtype=float)
    tasks = np.array([r.predicted for r in data.records])
    means = {t: logit[tasks == t].mean() for t in np.unique(tasks)}
    resid = logit - np.vectorize(means.get)(tasks)
    within = resid.var(axis=1, ddof=1).mean()
    between = resid.mean(axis=1).var(ddof=1) - within / resid.shape[1]
    return float(np.sqrt(max(between, 0.0)))


def fit_transfer(
    data: TrustDataset, vectors: np.ndarray, l2: float = 1.0, embedder: str = "minilm"
) -> TransferParameters:
    """Fit every rating of `data`; `vectors` are ζ of its tasks in task-id order (unit rows)."""
    theta = fit_vector(vectors @ vectors.T, rows_of(data), l2)
    bias, gs, gf, ell, w = _unpack(theta)
    ids = sorted(data.tasks)
    return TransferParameters(
        bias=round(float(bias), 6),
        success_gain=round(float(gs), 6),
        failure_loss=round(float(gf), 6),
        length_scale=round(float(ell), 6),
        anchors=tuple(data.tasks[t].text for t in ids),
        anchor_weights=tuple(round(float(v), 6) for v in w),
        disposition_sd=round(disposition_sd(data), 6),
        embedder=embedder,
        source=f"{data.source.name}: {data.participants} participants (Soh et al., IJRR 2020)",
    )
