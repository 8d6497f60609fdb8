"""The paper's Bayesian analysis, with PyMC + ArviZ in place of R's rethinking/ulam.

Eq. (3), one ordered-logit model per questionnaire (or pooled over both with ``pooled=True``)::

    R_i ~ OrderedLogit(phi_i, c[questionnaire_i])
    phi_i = a_P[participant_i] + g_Q[question_i] + b_C * on_i + b_G * groupB_i + b_S * second_i
    a_P = sigma_P * z_P,  g_Q = sigma_Q * z_Q,  z ~ ZeroSumNormal(1),  sigma ~ Exponential(1)
    b_C, b_G, b_S ~ Normal(0, 1),   c ~ ordered, Normal(evenly spaced, 1.5)

Eq. (4), a Poisson model of the interventions per session::

    I_s ~ Poisson(lambda_s),  log lambda_s = a + a_P[participant_s] + b_C * on_s + b_G * groupB_s + b_S * second_s

Contrasts (condition on - off, group B - A, session 2 - 1) are the b coefficients, on the logit (Eq. 3) or log-rate
(Eq. 4) scale. Each gets a 95 % HDI and a decision about the null hypothesis "no difference" with a region of
practical equivalence (ROPE, default [-0.18, 0.18] as published: 0.1 sd of the logistic): HDI inside the ROPE =
accept, HDI outside the ROPE = reject, otherwise undecided.
"""

from __future__ import annotations

import json
import logging
import warnings
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

from scone_bt.errors import SconeError, UnknownNameError
from scone_bt.study.log import StudyLog
from scone_bt.study.questionnaires import QUESTIONNAIRES, get_questionnaire

__all__ = [
    "AnalysisOptions",
    "Contrast",
    "ModelFit",
    "AnalysisResult",
    "StudyData",
    "load_study",
    "decide",
    "fit_ordinal",
    "fit_poisson",
    "analyze",
    "MODELS",
    "CONTRASTS",
    "write_outputs",
]

MODELS = ("mdmt", "tps_hri", "trust", "interventions")
CUTPOINT_PRIOR_SD = 1.5  # around evenly spaced means; wide enough for any Likert use of the scale
CONTRASTS = {"b_C": "condition (on - off)", "b_G": "group (B - A)", "b_S": "session (2 - 1)"}


@dataclass(frozen=True)
class AnalysisOptions:
    """Sampler and decision settings; the defaults are the paper's.

    Attributes:
        chains: MCMC chains.
        tune: Warm-up draws per chain.
        draws: Kept draws per chain.
        cores: Processes for the chains (None: PyMC's default).
        rope: Region of practical equivalence around 0, on the model's scale.
        hdi_prob: Mass of the highest density interval.
        seed: Sampler seed.
        models: Which of mdmt, tps_hri, trust (both questionnaires pooled), interventions to fit.
    """

    chains: int = 6
    tune: int = 500
    draws: int = 500
    cores: int | None = None
    rope: tuple[float, float] = (-0.18, 0.18)
    hdi_prob: float = 0.95
    seed: int = 0
    models: tuple[str, ...] = ("mdmt", "tps_hri", "interventions")

    def __post_init__(self) -> None:
        if self.chains < 1 or self.tune < 0 or self.draws < 10:
            raise SconeError("sampler settings: chains >= 1, tune >= 0, draws >= 10")
        lo, hi = self.rope
        if not lo < hi:
            raise SconeError(f"ROPE must be an interval low < high, got [{lo}, {hi}]")
        if not 0.5 <= self.hdi_prob < 1:
            raise SconeError(f"hdi_prob must be in [0.5, 1), got {self.hdi_prob}")
        for m in self.models:
            if m not in MODELS:
                raise UnknownNameError("model", m, MODELS)


@dataclass(frozen=True)
class Contrast:
    """A posterior contrast with its decision about "no difference".

    Attributes:
        model: Which model ("mdmt", "tps_hri", "trust", "interventions").
        name: What is compared ("condition (on - off)", ...).
        parameter: The coefficient ("b_C", "b_G", "b_S").
        mean: Posterior mean (logit or log-rate units).
        sd: Posterior sd.
        hdi: (low, high) of the HDI.
        rope: The ROPE used.
        p_positive: Posterior probability that the contrast is > 0.
        decision: accept, reject or undecided (about the null hypothesis).
    """

    model: str
    name: str
    parameter: str
    mean: float
    sd: float
    hdi: tuple[float, float]
    rope: tuple[float, float]
    p_positive: float
    decision: str


@dataclass(frozen=True)
class ModelFit:
    """One fitted model: samples of its contrasts and convergence diagnostics.

    Attributes:
        model: Model name.
        n_observations: Ratings (Eq. 3) or sessions (Eq. 4).
        samples: Coefficient name → flattened posterior draws.
        r_hat_max: Largest split R-hat over all parameters.
        ess_bulk_min: Smallest bulk effective sample size.
        divergences: Divergent transitions.
    """

    model: str
    n_observations: int
    samples: dict[str, np.ndarray]
    r_hat_max: float
    ess_bulk_min: float
    divergences: int


@dataclass(frozen=True)
class StudyData:
    """The study in long form.

    Attributes:
        ratings: One row per answered item: session_id, participant, group, condition, session_index,
            questionnaire, item, category (0..K-1, higher = more trust), n_categories.
        sessions: One row per finished session: session_id, participant, group, condition, session_index,
            interventions, and one score column per questionnaire (published scoring).
        simulated: Whether the log is labelled SIMULATED.
    """

    ratings: Any  # pandas.DataFrame
    sessions: Any  # pandas.DataFrame
    simulated: bool


@dataclass(frozen=True)
class AnalysisResult:
    """Everything `scone-study analyze` reports."""

    simulated: bool
    options: AnalysisOptions
    contrasts: tuple[Contrast, ...]
    fits: dict[str, ModelFit]
    scores: list[dict[str, Any]]

    def contrast(self, model: str, parameter: str = "b_C") -> Contrast:
        for c in self.contrasts:
            if c.model == model and c.parameter == parameter:
                return c
        raise UnknownNameError(
            "contrast", f"{model}/{parameter}", [f"{c.model}/{c.parameter}" for c in self.contrasts]
        )

    def to_json(self) -> dict[str, Any]:
        return {
            "data": "SIMULATED" if self.simulated else "real",
            "options": asdict(self.options),
            "contrasts": [asdict(c) for c in self.contrasts],
            "diagnostics": {
                m: {
                    "n_observations": f.n_observations,
                    "r_hat_max": f.r_hat_max,
                    "ess_bulk_min": f.ess_bulk_min,
                    "divergences": f.divergences,
                }
                for m, f in self.fits.items()
            },
            "scores": self.scores,
        }

    def format(self) -> str:
        label = "SIMULATED DATA" if self.simulated else "study data"
        lines = [f"── analysis of {label}: {len({s['participant'] for s in self.scores})} participants ──"]
        lo, hi = self.options.rope
        lines.append(
            f"{'model':14} {'contrast':22} {'mean':>7} {'sd':>6} {'95% HDI':>17}  {'P(>0)':>6}  decision (ROPE [{lo:g}, {hi:g}])"
        )
        for c in self.contrasts:
            lines.append(
                f"{c.model:14} {c.name:22} {c.mean:7.3f} {c.sd:6.3f} [{c.hdi[0]:7.3f}, {c.hdi[1]:7.3f}]  {c.p_positive:6.3f}  {c.decision}"
            )
        for m, f in self.fits.items():
            flag = "" if f.r_hat_max < 1.05 and f.divergences == 0 else "  <- check convergence"
            lines.append(
                f"{m:14} n={f.n_observations:<6} R-hat max {f.r_hat_max:.3f}  ESS min {f.ess_bulk_min:.0f}  divergences {f.divergences}{flag}"
            )
        return "\n".join(lines)


# --------------------------------------------------------------------------------------------- data
def load_study(log: StudyLog) -> StudyData:
    """Long-form ratings and per-session table from a StudyLog (unfinished sessions are left out)."""
    import pandas as pd

    sessions = [s for s in log.sessions() if s.ended is not None]
    if not sessions:
        raise SconeError(f"{log.path} has no finished sessions to analyse")
    by_id = {s.id: s for s in sessions}
    rows = []
    answers: dict[tuple[int, str], dict[str, float | None]] = {}
    for r in log.responses():
        s = by_id.get(r.session_id)
        if s is None:
            continue
        answers.setdefault((r.session_id, r.questionnaire), {})[r.item] = r.value
        if r.value is None:
            continue  # "does not fit"
        q = get_questionnaire(r.questionnaire)
        rows.append(
            {
                "session_id": s.id,
                "participant": s.participant,
                "group": s.group,
                "condition": s.condition,
                "session_index": s.session_index,
                "questionnaire": q.name,
                "item": r.item,
                "category": q.category(r.item, r.value),
                "n_categories": q.n_categories,
            }
        )
    table = []
    for s in sessions:
        row: dict[str, Any] = {
            "session_id": s.id,
            "participant": s.participant,
            "group": s.group,
            "condition": s.condition,
            "session_index": s.session_index,
            "interventions": log.interventions(s.id),
        }
        for name, q in QUESTIONNAIRES.items():
            row[name] = q.score(answers.get((s.id, name), {}))
        table.append(row)
    return StudyData(pd.DataFrame(rows), pd.DataFrame(table), log.simulated)


def decide(hdi: tuple[float, float], rope: tuple[float, float]) -> str:
    """Kruschke's HDI+ROPE rule for the null hypothesis "no difference"."""
    lo, hi = hdi
    if rope[0] <= lo and hi <= rope[1]:
        return "accept"
    if hi < rope[0] or lo > rope[1]:
        return "reject"
    return "undecided"


# --------------------------------------------------------------------------------------------- models
def _indicators(df: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, int]:
    participants = sorted(df["participant"].unique())
    pidx = df["participant"].map({p: i for i, p in enumerate(participants)}).to_numpy()
    on = (df["condition"] == "on").to_numpy(dtype=float)
    grp_b = (df["group"] == "B").to_numpy(dtype=float)
    second = (df["session_index"] == 2).to_numpy(dtype=float)
    return pidx, on, grp_b, second, len(participants)


def _sample(model: Any, options: AnalysisOptions) -> Any:
    import pymc as pm

    logging.getLogger("pymc").setLevel(logging.ERROR)
    with model, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return pm.sample(
            draws=options.draws,
            tune=options.tune,
            chains=options.chains,
            cores=options.cores,
            random_seed=options.seed,
            progressbar=False,
            compute_convergence_checks=False,
        )


def _fit(name: str, idata: Any, n_obs: int) -> ModelFit:
    import arviz as az

    post = idata.posterior
    samples = {k: post[k].values.reshape(-1) for k in CONTRASTS if k in post}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rhat = az.rhat(idata)
        ess = az.ess(idata, method="bulk")
    r_hat_max = float(max(np.nanmax(rhat[v].values) for v in rhat.data_vars))
    ess_min = float(min(np.nanmin(ess[v].values) for v in ess.data_vars))
    divergences = (
        int(idata.sample_stats["diverging"].values.sum()) if "diverging" in idata.sample_stats else 0
    )
    return ModelFit(name, n_obs, samples, round(r_hat_max, 4), round(ess_min, 1), divergences)


def _ordered_logit_logp(eta: Any, cuts: Any, y: np.ndarray) -> Any:
    """Sum of log P(y | eta, cuts) of the ordered logit, O(n) rather than pm.OrderedLogistic's O(n K).

    P(y = k) = sigmoid(c_k - eta) - sigmoid(c_{k-1} - eta) with c_{-1} = -inf and c_{K-1} = +inf, computed as
    log sigmoid(a) + log sigmoid(-b) + log(1 - exp(b - a)) for a = c_k - eta > b = c_{k-1} - eta.
    """
    import pytensor.tensor as pt

    big = np.array([1e6])
    ext = pt.concatenate([-big, cuts, big])
    a = ext[y + 1] - eta
    b = ext[y] - eta
    log_sigmoid = lambda x: -pt.softplus(-x)  # noqa: E731
    return pt.sum(log_sigmoid(a) + log_sigmoid(-b) + pt.log1mexp(b - a))


def fit_ordinal(ratings: Any, options: AnalysisOptions, name: str = "trust") -> ModelFit:
    """Eq. (3) on the given ratings (one or more questionnaires; each has its own cut-points)."""
    import pymc as pm

    if len(ratings) == 0:
        raise SconeError(f"model {name}: no questionnaire answers to analyse")
    df = ratings.reset_index(drop=True)
    pidx, on, grp_b, second, n_p = _indicators(df)
    items = sorted(df["item"].unique())
    qidx = df["item"].map({q: i for i, q in enumerate(items)}).to_numpy()
    with pm.Model() as model:
        # Zero-sum participant and question effects: the cut-points carry the location, which removes the ridge
        # between them and the effects' means (faster mixing; the contrasts are unchanged).
        # Non-centred (sigma * z) against the funnel of small studies.
        sigma_p = pm.Exponential("sigma_P", 1.0)
        a_p = pm.Deterministic("a_P", sigma_p * pm.ZeroSumNormal("z_P", sigma=1.0, shape=n_p))
        sigma_q = pm.Exponential("sigma_Q", 1.0)
        g_q = pm.Deterministic("g_Q", sigma_q * pm.ZeroSumNormal("z_Q", sigma=1.0, shape=len(items)))
        b_c = pm.Normal("b_C", 0.0, 1.0)
        b_g = pm.Normal("b_G", 0.0, 1.0)
        b_s = pm.Normal("b_S", 0.0, 1.0)
        phi = a_p[pidx] + g_q[qidx] + b_c * on + b_g * grp_b + b_s * second
        for qname in sorted(df["questionnaire"].unique()):
            rows = np.flatnonzero((df["questionnaire"] == qname).to_numpy())
            k = int(df["n_categories"].iloc[rows[0]])
            mu = np.linspace(-2.5, 2.5, k - 1)
            cuts = pm.Normal(
                f"c_{qname}",
                mu=mu,
                sigma=CUTPOINT_PRIOR_SD,
                shape=k - 1,
                transform=pm.distributions.transforms.ordered,
                initval=mu,
            )
            pm.Potential(f"R_{qname}", _ordered_logit_logp(phi[rows], cuts, df["category"].to_numpy()[rows]))
    return _fit(name, _sample(model, options), len(df))


def fit_poisson(sessions: Any, options: AnalysisOptions, name: str = "interventions") -> ModelFit:
    """Eq. (4): intervention counts per session."""
    import pymc as pm

    df = sessions.reset_index(drop=True)
    pidx, on, grp_b, second, n_p = _indicators(df)
    with pm.Model() as model:
        a = pm.Normal("a", 0.0, 1.5)
        sigma_p = pm.Exponential("sigma_P", 1.0)
        a_p = pm.Deterministic("a_P", sigma_p * pm.Normal("z_P", 0.0, 1.0, shape=n_p))
        b_c = pm.Normal("b_C", 0.0, 1.0)
        b_g = pm.Normal("b_G", 0.0, 1.0)
        b_s = pm.Normal("b_S", 0.0, 1.0)
        pm.Poisson(
            "I",
            mu=pm.math.exp(a + a_p[pidx] + b_c * on + b_g * grp_b + b_s * second),
            observed=df["interventions"].to_numpy(),
        )
    return _fit(name, _sample(model, options), len(df))


def _contrasts(fit: ModelFit, options: AnalysisOptions) -> list[Contrast]:
    import arviz as az

    out = []
    for param, label in CONTRASTS.items():
        s = fit.samples[param]
        hdi = az.hdi(s, hdi_prob=options.hdi_prob)
        interval = (round(float(hdi[0]), 4), round(float(hdi[1]), 4))
        out.append(
            Contrast(
                model=fit.model,
                name=label,
                parameter=param,
                mean=round(float(s.mean()), 4),
                sd=round(float(s.std()), 4),
                hdi=interval,
                rope=options.rope,
                p_positive=round(float((s > 0).mean()), 4),
                decision=decide(interval, options.rope),
            )
        )
    return out


def analyze(
    source: StudyLog | StudyData,
    options: AnalysisOptions = AnalysisOptions(),
    printer: Callable[[str], None] = lambda _l: None,
) -> AnalysisResult:
    """Fit the requested models and compute contrasts, HDIs, decisions and the questionnaires' original scores."""
    data = load_study(source) if isinstance(source, StudyLog) else source
    fits: dict[str, ModelFit] = {}
    for m in options.models:
        printer(f"fitting {m} ({options.chains} chains, {options.tune} warm-up + {options.draws} draws)")
        if m == "interventions":
            fits[m] = fit_poisson(data.sessions, options, m)
        else:
            ratings = data.ratings if m == "trust" else data.ratings[data.ratings["questionnaire"] == m]
            fits[m] = fit_ordinal(ratings, options, m)
    contrasts = tuple(c for f in fits.values() for c in _contrasts(f, options))
    scores = [
        {k: (None if v != v else v) for k, v in row.items()} for row in data.sessions.to_dict("records")
    ]  # NaN → None
    return AnalysisResult(data.simulated, options, contrasts, fits, scores)


def write_outputs(result: AnalysisResult, data: StudyData, folder: str | Path) -> dict[str, Path]:
    """results.json, scores.csv and the Fig. 3-style figure in `folder`."""
    from scone_bt.study.figure import plot_results

    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    paths = {"json": out / "results.json", "scores": out / "scores.csv", "figure": out / "fig3.png"}
    paths["json"].write_text(json.dumps(result.to_json(), indent=2, default=_json_default))
    frame = data.sessions.copy()
    frame.insert(0, "data", "SIMULATED" if data.simulated else "real")
    frame.to_csv(paths["scores"], index=False)
    plot_results(result, data, paths["figure"])
    return paths


def _json_default(obj: Any) -> Any:
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, Sequence):
        return list(obj)
    return str(obj)
