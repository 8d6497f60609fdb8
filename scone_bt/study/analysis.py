"""The paper's Bayesian analysis, with PyMC + ArviZ in place of R's rethinking/ulam.

The models are in models.py: ``paper`` (default) is Eq. (3), an index-coded ordered logit of every answer with
condition, session order (G), question and participant terms, and Eq. (4), a Poisson model of the interventions
per session; ``extended`` adds the counterbalancing group (A/B) and codes effects as single differences.

Contrasts (condition on - off, session 2 - 1, and group B - A in ``extended``) are on the logit (Eq. 3) or
log-rate (Eq. 4) scale. Each gets a 95 % HDI and a decision about the null hypothesis "no difference" with a region
of practical equivalence (ROPE, default [-0.18, 0.18] as published: 0.1 sd of the logistic): HDI inside the ROPE =
accept, HDI outside the ROPE = reject, otherwise undecided.

Data come from a StudyLog (``load_study``) or from anyone's CSV files (ratings_csv.py); both give a StudyData.
"""

from __future__ import annotations

import logging
import math
import os
import time
import warnings
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from scone_bt.errors import SconeError, UnknownNameError
from scone_bt.study.log import StudyLog
from scone_bt.study.models import (
    QUESTION_MEAN_SD,
    SPECIFICATIONS,
    CountDesign,
    Factor,
    OrdinalDesign,
    Priors,
    contrast_variable,
    count_model,
    ordinal_model,
)
from scone_bt.study.questionnaires import QUESTIONNAIRES, get_questionnaire

__all__ = [
    "AnalysisOptions",
    "Contrast",
    "ModelFit",
    "AnalysisResult",
    "convergence_text",
    "StudyData",
    "load_study",
    "decide",
    "check_models",
    "ordinal_design",
    "count_design",
    "sample_model",
    "fit_ordinal",
    "fit_poisson",
    "contrasts_of",
    "summarize_fit",
    "analyze",
    "MODELS",
    "CONTRASTS",
    "FACTORS",
    "output_paths",
    "check_outputs",
]

MODELS = ("mdmt", "tps_hri", "trust", "interventions")  # what a StudyLog holds; CSV data name their own
POOLED = "trust"  # all questionnaires in one model, each with its own cut-points
COUNTS = "interventions"
CONTRASTS = {"condition": "condition (on - off)", "session": "session (2 - 1)", "group": "group (B - A)"}
FACTORS = {"paper": ("condition", "session"), "extended": ("condition", "group", "session")}
_PARAMETERS = {
    ("paper", "condition"): "alpha_C[on] - alpha_C[off]",
    ("paper", "session"): "alpha_G[2] - alpha_G[1]",
    ("extended", "condition"): "b_C",
    ("extended", "group"): "b_G",
    ("extended", "session"): "b_S",
}
_LEVELS = {"condition": ("off", "on"), "session": ("1", "2"), "group": ("A", "B")}
# PyMC's default (diagonal mass matrix): the paper model is sampled without its location ridge (models.py), so a
# dense mass matrix is not needed, and it would need far more warm-up for studies with many participants.
NUTS_INIT = "jitter+adapt_diag"
OUTPUT_FILES = {
    "json": "results.json",
    "scores": "scores.csv",
    "figure": "fig3.png",
    "figure_pdf": "fig3.pdf",
}


@dataclass(frozen=True)
class AnalysisOptions:
    """Model, priors, sampler and decision settings; the defaults are the paper's.

    Attributes:
        specification: "paper" (Eq. 3/4 as published) or "extended".
        priors: Prior scales (None: the specification's defaults, filled in on construction).
        chains: MCMC chains.
        tune: Warm-up draws per chain.
        draws: Kept draws per chain.
        cores: Processes for the chains (None: PyMC's default).
        rope: Region of practical equivalence around 0, on the model's scale.
        hdi_prob: Mass of the highest density interval.
        seed: Sampler seed.
        models: Questionnaires to fit, "trust" (all pooled) and/or "interventions" (None: every questionnaire in
            the data, plus interventions where the data have them).
    """

    specification: str = "paper"
    priors: Priors | None = None
    chains: int = 6
    tune: int = 500
    draws: int = 500
    cores: int | None = None
    rope: tuple[float, float] = (-0.18, 0.18)
    hdi_prob: float = 0.95
    seed: int = 0
    models: tuple[str, ...] | None = None

    def __post_init__(self) -> None:
        if self.specification not in SPECIFICATIONS:
            raise UnknownNameError("model", self.specification, SPECIFICATIONS)
        if self.priors is None:
            object.__setattr__(self, "priors", Priors.defaults(self.specification))
        # named by the flags that set them (scone-study's and scone-bench's alike)
        from scone_bt.checks import check_at_least

        for flag, value, least in (
            ("--chains", self.chains, 1),
            ("--tune", self.tune, 0),
            ("--draws", self.draws, 10),
        ):
            check_at_least(value, flag, least)
        if self.cores is not None:
            check_at_least(self.cores, "--cores", 1)
        lo, hi = self.rope
        if not lo < hi:
            raise SconeError(f"ROPE must be an interval low < high, got [{lo}, {hi}]")
        if not 0.5 <= self.hdi_prob < 1:
            raise SconeError(f"hdi_prob must be in [0.5, 1), got {self.hdi_prob}")
        if self.models is not None:
            object.__setattr__(self, "models", tuple(self.models))
            if not self.models:
                raise SconeError("no model to fit; name at least one questionnaire, trust or interventions")

    @property
    def factors(self) -> tuple[str, ...]:
        return FACTORS[self.specification]

    def priors_json(self) -> dict[str, Any]:
        assert self.priors is not None  # filled in on construction
        out: dict[str, Any] = asdict(self.priors)
        if self.specification == "paper":
            out["question_mean_sd"] = QUESTION_MEAN_SD
            out["scale_family"] = "HalfNormal"
        else:
            out["scale_family"] = "Exponential (mean scale_sd)"
        return out

    def sampler_json(self) -> dict[str, Any]:
        import pymc as pm

        return {
            "sampler": f"NUTS (PyMC {pm.__version__})",
            "init": NUTS_INIT,
            "chains": self.chains,
            "tune": self.tune,
            "draws": self.draws,
            "cores": self.cores,
            "seed": self.seed,
        }


@dataclass(frozen=True)
class Contrast:
    """A posterior contrast with its decision about "no difference".

    Attributes:
        model: What was fitted ("mdmt", "tps_hri", "trust", "interventions", or a CSV questionnaire).
        contrast: condition, session or group.
        label: What is compared ("condition (on - off)", ...).
        parameter: The model's expression for it ("alpha_C[on] - alpha_C[off]", "b_C", ...).
        specification: paper or extended.
        mean: Posterior mean (logit or log-rate units).
        sd: Posterior sd.
        hdi: (low, high) of the HDI.
        rope: The ROPE used.
        p_positive: Posterior probability that the contrast is > 0.
        decision: accept, reject or undecided (about the null hypothesis).
    """

    model: str
    contrast: str
    label: str
    parameter: str
    specification: str
    mean: float
    sd: float
    hdi: tuple[float, float]
    rope: tuple[float, float]
    p_positive: float
    decision: str


@dataclass(frozen=True)
class ModelFit:
    """One fitted model: samples of its contrasts and group-level sds, and convergence diagnostics.

    Attributes:
        model: Model name.
        n_observations: Ratings (Eq. 3) or sessions (Eq. 4).
        samples: Contrast name ("condition", ...) or sd name ("sigma_P", "sigma_Q") → flattened posterior draws.
        r_hat_max: Largest split R-hat over all parameters.
        ess_bulk_min: Smallest bulk effective sample size.
        divergences: Divergent transitions.
        seconds: Wall time of building, compiling and sampling the model.
    """

    model: str
    n_observations: int
    samples: dict[str, np.ndarray]
    r_hat_max: float
    ess_bulk_min: float
    divergences: int
    seconds: float = 0.0


@dataclass(frozen=True)
class StudyData:
    """The study in long form.

    Attributes:
        ratings: One row per answered item: session_id, participant, group, condition, session_index,
            questionnaire, item, category (0..K-1, higher = more trust), n_categories.
        sessions: One row per finished session: session_id, participant, group, condition, session_index,
            interventions (NaN where unknown), and one score column per questionnaire.
        simulated: Whether the data are labelled SIMULATED.
        source: Where the data came from (for messages and results.json).
        questionnaires: The questionnaires in the ratings, in order.
        score_units: Questionnaire → how its score column is scaled (for the figure's axis labels).
        notes: One-line warnings about the data the analysis was run on (e.g. participants left out).
    """

    ratings: Any  # pandas.DataFrame
    sessions: Any  # pandas.DataFrame
    simulated: bool
    source: str = ""
    questionnaires: tuple[str, ...] = tuple(QUESTIONNAIRES)
    score_units: dict[str, str] = field(default_factory=dict)
    notes: tuple[str, ...] = ()

    @property
    def has_interventions(self) -> bool:
        return "interventions" in self.sessions and bool(self.sessions["interventions"].notna().all())

    def available_models(self) -> tuple[str, ...]:
        pooled = (POOLED,) if len(self.questionnaires) > 1 else ()
        return (*self.questionnaires, *pooled, *((COUNTS,) if self.has_interventions else ()))


@dataclass(frozen=True)
class AnalysisResult:
    """Everything `scone-study analyze` reports."""

    simulated: bool
    options: AnalysisOptions
    contrasts: tuple[Contrast, ...]
    fits: dict[str, ModelFit]
    scores: list[dict[str, Any]]
    source: str = ""
    seconds: float = 0.0

    def contrast(self, model: str, contrast: str = "condition") -> Contrast:
        for c in self.contrasts:
            if c.model == model and c.contrast == contrast:
                return c
        raise UnknownNameError(
            "contrast", f"{model}/{contrast}", [f"{c.model}/{c.contrast}" for c in self.contrasts]
        )

    def to_json(self) -> dict[str, Any]:
        return {
            "data": "SIMULATED" if self.simulated else "real",
            "source": self.source,
            "model": self.options.specification,
            "priors": self.options.priors_json(),
            "sampler": self.options.sampler_json(),
            "rope": list(self.options.rope),
            "hdi_prob": self.options.hdi_prob,
            "options": asdict(self.options),
            "contrasts": [asdict(c) for c in self.contrasts],
            "diagnostics": {
                m: {
                    "n_observations": f.n_observations,
                    "r_hat_max": f.r_hat_max,
                    "ess_bulk_min": f.ess_bulk_min,
                    "divergences": f.divergences,
                    "seconds": round(f.seconds, 2),
                }
                for m, f in self.fits.items()
            },
            "seconds": round(self.seconds, 2),
            "scores": self.scores,
        }

    def format(self) -> str:
        label = "SIMULATED DATA" if self.simulated else "study data"
        n = len({s["participant"] for s in self.scores})
        lines = [f"── analysis of {label}: {n} participants, model {self.options.specification} ──"]
        lo, hi = self.options.rope
        lines.append(
            f"{'model':14} {'contrast':22} {'mean':>7} {'sd':>6} {'95% HDI':>17}  {'P(>0)':>6}  decision (ROPE [{lo:g}, {hi:g}])"
        )
        for c in self.contrasts:
            lines.append(
                f"{c.model:14} {c.label:22} {c.mean:7.3f} {c.sd:6.3f} [{c.hdi[0]:7.3f}, {c.hdi[1]:7.3f}]  {c.p_positive:6.3f}  {c.decision}"
            )
        for m, f in self.fits.items():
            lines.append(f"{m:14} n={f.n_observations:<6} {convergence_text(f)}")
        return "\n".join(lines)


def convergence_text(fit: ModelFit) -> str:
    """R-hat, ESS, divergences and time of one fit for the report, flagged when they call for a look.

    R-hat compares chains: with one chain it is undefined (NaN), which says nothing about convergence, so the
    line says what it needs instead of printing "nan" next to the flag.
    """
    one_chain = math.isnan(fit.r_hat_max)
    r_hat = "R-hat: needs ≥ 2 chains" if one_chain else f"R-hat max {fit.r_hat_max:.3f}"
    ok = (one_chain or fit.r_hat_max < 1.05) and fit.divergences == 0
    flag = "" if ok else "  <- check convergence"
    return (
        f"{r_hat}  ESS min {fit.ess_bulk_min:.0f}  divergences {fit.divergences}  {fit.seconds:.0f} s{flag}"
    )


# --------------------------------------------------------------------------------------------- data
def load_study(log: StudyLog) -> StudyData:
    """Long-form ratings and per-session table from a StudyLog (unfinished sessions are left out)."""
    import pandas as pd

    sessions = [s for s in log.sessions() if s.ended is not None]
    if not sessions:
        raise SconeError(f"{log.path} has no finished sessions to analyse")
    sessions, notes = check_crossover(sessions, str(log.path))
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
    units = {"mdmt": "score (0-7)", "tps_hri": "score (%)"}
    return StudyData(
        pd.DataFrame(rows), pd.DataFrame(table), log.simulated, str(log.path), score_units=units, notes=notes
    )


def check_crossover(sessions: Sequence[Any], source: str) -> tuple[list[Any], tuple[str, ...]]:
    """The finished sessions of a study log as the crossover design needs them, as the CSV route checks its files.

    A participant without both conditions (one session so far) is left out, said in one line; data of one group
    only are refused: every "on" session would also be a session 1 (or every one a session 2), so condition and
    session order are confounded and no contrast could be decided.

    Returns:
        The sessions kept, and the one-line notes.
    """
    by_participant: dict[str, list[Any]] = {}
    for s in sessions:
        by_participant.setdefault(s.participant, []).append(s)
    partial = {p: ss for p, ss in by_participant.items() if {s.condition for s in ss} != {"on", "off"}}
    notes: list[str] = []
    if partial:
        said = ", ".join(
            f"{p} ({'/'.join(sorted({s.condition for s in ss}))} only)" for p, ss in sorted(partial.items())
        )
        notes.append(
            f"{source}: {len(partial)} participant(s) with one condition only, left out of the analysis: {said}; "
            "every participant needs both sessions (on and off)"
        )
    kept = [s for s in sessions if s.participant not in partial]
    if not kept:
        raise SconeError(
            f"{source}: no participant has finished both sessions (on and off); nothing to analyse yet"
        )
    groups = sorted({s.group for s in kept})
    if len(groups) == 1:
        order = "/".join(
            s.condition for s in sorted(by_participant[kept[0].participant], key=lambda s: s.session_index)
        )
        raise SconeError(
            f"{source}: every participant is in group {groups[0]} (order {order}); the design needs both groups A "
            "and B, so that each condition is seen in session 1 and in session 2, else condition and session "
            "order are confounded"
        )
    return kept, tuple(notes)


def decide(hdi: tuple[float, float], rope: tuple[float, float]) -> str:
    """Kruschke's HDI+ROPE rule for the null hypothesis "no difference"."""
    lo, hi = hdi
    if rope[0] <= lo and hi <= rope[1]:
        return "accept"
    if hi < rope[0] or lo > rope[1]:
        return "reject"
    return "undecided"


def check_models(models: Sequence[str], available: Sequence[str], source: str = "the data") -> None:
    """Every requested model must be one the data can support."""
    for m in models:
        if m not in available:
            raise UnknownNameError(f"model for {source}", m, available)


# --------------------------------------------------------------------------------------------- designs
def _factors(df: Any, names: Sequence[str]) -> tuple[Factor, ...]:
    columns = {"condition": "condition", "session": "session_index", "group": "group"}
    out = []
    for name in names:
        values = df[columns[name]].astype(str).to_numpy()
        out.append(Factor(name, _LEVELS[name], (values == _LEVELS[name][1]).astype(np.int64)))
    return tuple(out)


def _index(values: Any) -> np.ndarray:
    levels = sorted(set(values))
    lookup = {v: i for i, v in enumerate(levels)}
    return np.array([lookup[v] for v in values], dtype=np.int64)


def ordinal_design(ratings: Any, specification: str = "paper") -> OrdinalDesign:
    """Eq. (3)'s design from long-form ratings; each questionnaire keeps its own cut-points."""
    df = ratings.reset_index(drop=True)
    questionnaire = df["questionnaire"].astype(str).to_numpy()
    blocks = []
    for name in sorted(set(questionnaire)):
        rows = np.flatnonzero(questionnaire == name)
        blocks.append((name, rows, int(df["n_categories"].iloc[rows[0]])))
    questions = list(zip(questionnaire, df["item"].astype(str), strict=True))
    return OrdinalDesign(
        y=df["category"].to_numpy(dtype=np.int64),
        blocks=tuple(blocks),
        factors=_factors(df, FACTORS[specification]),
        participant=_index(df["participant"].astype(str)),
        question=_index(questions),
    )


def count_design(sessions: Any, specification: str = "paper") -> CountDesign:
    """Eq. (4)'s design from the per-session table."""
    df = sessions.reset_index(drop=True)
    return CountDesign(
        counts=df["interventions"].to_numpy(dtype=np.int64),
        factors=_factors(df, FACTORS[specification]),
        participant=_index(df["participant"].astype(str)),
    )


# --------------------------------------------------------------------------------------------- fitting
def sample_model(model: Any, options: AnalysisOptions) -> Any:
    """NUTS with the options' sampler settings; returns ArviZ InferenceData."""
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
            init=NUTS_INIT,
            progressbar=False,
            compute_convergence_checks=False,
        )


def _drop_shape_validation(record: logging.LogRecord) -> bool:
    """A logging filter: False for ArviZ's "Shape validation failed" (too few chains for R-hat), True otherwise."""
    return not record.getMessage().startswith("Shape validation failed")


def summarize_fit(name: str, idata: Any, n_obs: int, factors: Sequence[str], seconds: float) -> ModelFit:
    """Contrast and group-sd draws plus R-hat, ESS and divergences of one sampled model."""
    import arviz as az

    post = idata.posterior
    samples = {f: post[contrast_variable(f)].values.reshape(-1) for f in factors}
    samples.update({k: post[k].values.reshape(-1) for k in ("sigma_P", "sigma_Q") if k in post})
    # With one chain (--chains 1, quick runs and power studies) ArviZ logs "Shape validation failed" to stderr for
    # R-hat: it needs two chains and is NaN then (null in results.json). Drop just that record, from
    # ArviZ's own logger and only around these two calls, so that its other messages still reach the user. ArviZ's
    # logger is `arviz._log`, a Logger outside the logging registry (getLogger("arviz") is another object).
    arviz_log = getattr(az, "_log", None) or logging.getLogger("arviz")
    arviz_log.addFilter(_drop_shape_validation)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            rhat = az.rhat(idata)
            ess = az.ess(idata, method="bulk")
            # One chain: every R-hat is NaN, and nanmax warns "All-NaN slice"; the NaN is the answer.
            r_hat_max = float(max(np.nanmax(rhat[v].values) for v in rhat.data_vars))
            ess_min = float(min(np.nanmin(ess[v].values) for v in ess.data_vars))
    finally:
        arviz_log.removeFilter(_drop_shape_validation)
    stats = idata.sample_stats
    divergences = int(stats["diverging"].values.sum()) if "diverging" in stats else 0
    return ModelFit(name, n_obs, samples, round(r_hat_max, 4), round(ess_min, 1), divergences, seconds)


def fit_ordinal(ratings: Any, options: AnalysisOptions, name: str = POOLED) -> ModelFit:
    """Eq. (3) on the given ratings (one or more questionnaires; each has its own cut-points)."""
    if len(ratings) == 0:
        raise SconeError(f"model {name}: no questionnaire answers to analyse")
    start = time.perf_counter()
    design = ordinal_design(ratings, options.specification)
    model = ordinal_model(design, options.specification, options.priors)
    idata = sample_model(model, options)
    return summarize_fit(name, idata, len(design.y), options.factors, time.perf_counter() - start)


def fit_poisson(sessions: Any, options: AnalysisOptions, name: str = COUNTS) -> ModelFit:
    """Eq. (4): intervention counts per session."""
    start = time.perf_counter()
    design = count_design(sessions, options.specification)
    model = count_model(design, options.specification, options.priors)
    idata = sample_model(model, options)
    return summarize_fit(name, idata, len(design.counts), options.factors, time.perf_counter() - start)


def contrasts_of(fit: ModelFit, options: AnalysisOptions) -> list[Contrast]:
    """The fit's contrasts with HDI, P(> 0) and the HDI+ROPE decision."""
    import arviz as az

    out = []
    for factor in options.factors:
        s = fit.samples[factor]
        hdi = az.hdi(s, hdi_prob=options.hdi_prob)
        interval = (round(float(hdi[0]), 4), round(float(hdi[1]), 4))
        out.append(
            Contrast(
                model=fit.model,
                contrast=factor,
                label=CONTRASTS[factor],
                parameter=_PARAMETERS[(options.specification, factor)],
                specification=options.specification,
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
    """Fit the requested models and compute contrasts, HDIs, decisions and the questionnaires' scores."""
    start = time.perf_counter()
    data = load_study(source) if isinstance(source, StudyLog) else source
    models = options.models if options.models is not None else data.available_models()
    if options.models is None:
        models = tuple(m for m in models if m != POOLED)
    check_models(models, data.available_models(), data.source or "the data")
    fits: dict[str, ModelFit] = {}
    for m in models:
        printer(
            f"fitting {m} ({options.specification} model; {options.chains} chains, "
            f"{options.tune} warm-up + {options.draws} draws)"
        )
        if m == COUNTS:
            fits[m] = fit_poisson(data.sessions, options, m)
        else:
            ratings = data.ratings if m == POOLED else data.ratings[data.ratings["questionnaire"] == m]
            fits[m] = fit_ordinal(ratings, options, m)
    contrasts = tuple(c for f in fits.values() for c in contrasts_of(f, options))
    scores = [
        {k: (None if v != v else v) for k, v in row.items()} for row in data.sessions.to_dict("records")
    ]  # NaN → None
    return AnalysisResult(
        data.simulated, options, contrasts, fits, scores, data.source, time.perf_counter() - start
    )


# --------------------------------------------------------------------------------------------- outputs
def output_paths(folder: str | Path) -> dict[str, Path]:
    """Where write_outputs puts results.json, scores.csv and the figure (PNG and PDF)."""
    out = Path(folder)
    return {key: out / name for key, name in OUTPUT_FILES.items()}


def check_outputs(folder: str | Path, force: bool = False) -> dict[str, Path]:
    """Refuse, before any sampling, an output folder that cannot be written or would lose earlier results."""
    out = Path(folder)
    return check_output_folder(out, output_paths(out), force, "results.json, scores.csv, fig3.png/pdf")


def check_output_folder(out: Path, paths: dict[str, Path], force: bool, holds: str) -> dict[str, Path]:
    """Refuse an output folder that is a file, would lose earlier results (unless ``force``), cannot be created
    or is not writable; ``holds`` names what goes there, for the message."""
    if out.exists() and not out.is_dir():
        raise SconeError(f"--out {out} is a file; give a folder for {holds}")
    existing = [p.name for p in paths.values() if p.exists()]
    if existing and not force:
        raise SconeError(
            f"--out {out} already holds {', '.join(existing)}; choose another folder or pass --force to overwrite"
        )
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise SconeError(f"--out {out}: cannot create the folder ({exc.strerror})") from None
    if not os.access(out, os.W_OK):
        raise SconeError(f"--out {out}: the folder is not writable")
    return paths
