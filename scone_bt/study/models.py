"""The study's PyMC models: the paper's Eq. (3) and Eq. (4), index-coded as published, and an extended variant.

``paper`` (the default), Eq. (3) for the ordinal answers R_i and Eq. (4) for the intervention counts I_s::

    R_i ~ OrderedLogit(phi_i, alpha)                    alpha_k ~ Normal(0, cutpoint_sd), ordered
    phi_i = alpha_C[C_i] + alpha_G[G_i] + alpha_Q[Q_i] + alpha_P[P_i]
    alpha_C[c] ~ Normal(0, effect_sd) for c in (off, on);  alpha_G[g] ~ Normal(0, effect_sd) for g in (1st, 2nd)
    alpha_Q[q] ~ Normal(alpha_bar, sigma_Q),  alpha_bar ~ Normal(0, 1.5),  sigma_Q ~ HalfNormal(scale_sd)
    alpha_P[p] ~ Normal(0, sigma_P),  sigma_P ~ HalfNormal(scale_sd)

    I_s ~ Poisson(lambda_s),  log lambda_s = alpha_C[C_s] + alpha_G[G_s] + alpha_P[P_s]   (same priors)

G is the session order. A contrast is the difference of a factor's two levels (on - off, 2nd - 1st): with
``effect_sd = 1`` its prior sd is sqrt(2). ``extended`` adds the counterbalancing group (A/B) as a third factor and
codes each factor as a single difference ``b ~ Normal(0, effect_sd)``, with zero-sum participant and question effects
(``Exponential`` scales of mean ``scale_sd``) and cut-points around evenly spaced means; docs/study.md lists every
difference. Both models accept any index-coded two-level factors, so the same code fits public ordinal data (the
R cross-check fits the wine data of R's ``ordinal`` package with temperature and contact as factors).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from scone_bt.errors import SconeError, UnknownNameError

__all__ = [
    "SPECIFICATIONS",
    "Priors",
    "Factor",
    "OrdinalDesign",
    "CountDesign",
    "ordinal_model",
    "count_model",
    "contrast_variable",
]

SPECIFICATIONS = ("paper", "extended")
QUESTION_MEAN_SD = 1.5  # Eq. (3): alpha_bar ~ Normal(0, 1.5)


@dataclass(frozen=True)
class Priors:
    """Prior scales, in logit (Eq. 3) or log-rate (Eq. 4) units.

    Attributes:
        effect_sd: sd of each factor level (paper) or of each single-difference coefficient (extended).
        cutpoint_sd: sd of the ordered cut-points (around 0 in the paper, around evenly spaced means in extended).
        scale_sd: HalfNormal scale (paper) or Exponential mean (extended) of the participant and question sds.
    """

    effect_sd: float = 1.0
    cutpoint_sd: float = 1.0
    scale_sd: float = 1.0

    def __post_init__(self) -> None:
        for name in ("effect_sd", "cutpoint_sd", "scale_sd"):
            v = getattr(self, name)
            if not (v > 0 and np.isfinite(v)):
                flag = "--" + name.removesuffix("_sd").replace("_", "-") + "-prior-sd"
                raise SconeError(f"{flag} must be a positive number, got {v}")

    @classmethod
    def defaults(cls, specification: str) -> Priors:
        """The published priors (paper) or the extended model's own."""
        if specification == "paper":
            return cls(1.0, 1.0, 1.0)
        if specification == "extended":
            return cls(1.0, 1.5, 1.0)
        raise UnknownNameError("model", specification, SPECIFICATIONS)


@dataclass(frozen=True)
class Factor:
    """A two-level fixed effect.

    Attributes:
        name: "condition", "session", "group", or a dataset's own factor name.
        levels: (reference, other); the contrast is other - reference.
        index: Per row, 0 (reference) or 1 (other).
    """

    name: str
    levels: tuple[str, str]
    index: np.ndarray


@dataclass(frozen=True)
class OrdinalDesign:
    """Ordinal answers and their design.

    Attributes:
        y: Per row, the category 0..K-1 (higher = more).
        blocks: (name, row indices, K) per questionnaire; each block has its own cut-points.
        factors: The fixed effects.
        participant: Per row, the participant index 0..n-1 (None: no participant term).
        question: Per row, the question index 0..m-1 (None: no question term).
    """

    y: np.ndarray
    blocks: tuple[tuple[str, np.ndarray, int], ...]
    factors: tuple[Factor, ...]
    participant: np.ndarray | None = None
    question: np.ndarray | None = None


@dataclass(frozen=True)
class CountDesign:
    """Counts (interventions per session) and their design.

    Attributes:
        counts: Per row, a non-negative count.
        factors: The fixed effects.
        participant: Per row, the participant index (None: no participant term).
    """

    counts: np.ndarray
    factors: tuple[Factor, ...]
    participant: np.ndarray | None = None


def contrast_variable(factor: str) -> str:
    """Name of the posterior variable that holds a factor's contrast (other level - reference)."""
    return f"d_{factor}"


def _n(index: np.ndarray) -> int:
    return int(index.max()) + 1


def _ordered_logit_logp(eta, cuts, y: np.ndarray):  # noqa: ANN001, ANN202 - pytensor tensors
    """Sum of log P(y | eta, cuts), O(n) rather than pm.OrderedLogistic's O(n K).

    P(y = k) = sigmoid(c_k - eta) - sigmoid(c_{k-1} - eta) with c_{-1} = -inf and c_{K-1} = +inf, computed as
    log sigmoid(a) + log sigmoid(-b) + log(1 - exp(b - a)) for a = c_k - eta > b = c_{k-1} - eta.
    """
    import pytensor.tensor as pt

    big = np.array([1e6])
    ext = pt.concatenate([-big, cuts, big])
    a = ext[y + 1] - eta
    b = ext[y] - eta
    return pt.sum(-pt.softplus(-a) - pt.softplus(b) + pt.log1mexp(b - a))


def _paper_terms(factors: tuple[Factor, ...], priors: Priors):  # noqa: ANN202
    """The index-coded levels alpha_X[l] ~ Normal(0, effect_sd), written as midpoint + half the contrast.

    alpha_X[0], alpha_X[1] iid Normal(0, sd) is the same as a midpoint h_X ~ Normal(0, sd / sqrt 2) and a contrast
    d_X ~ Normal(0, sd sqrt 2), independent: alpha_X[l] = h_X + d_X (l - 1/2). The midpoints only shift the
    location, so they are summed into one location term by the caller (see _location_sd).
    """
    import pymc as pm

    total = 0.0
    for f in factors:
        d = pm.Normal(contrast_variable(f.name), 0.0, priors.effect_sd * math.sqrt(2.0))
        total = total + d * (f.index.astype(float) - 0.5)
    return total


def _location_sd(n_factors: int, priors: Priors, question_mean: bool) -> float:
    """sd of the sum of the level midpoints (each sd / sqrt 2) and, in Eq. (3), the question mean alpha_bar."""
    var = n_factors * priors.effect_sd**2 / 2.0 + (QUESTION_MEAN_SD**2 if question_mean else 0.0)
    return math.sqrt(var)


def _extended_terms(factors: tuple[Factor, ...], priors: Priors):  # noqa: ANN202
    """Single-difference coefficients b_X ~ Normal(0, effect_sd)."""
    import pymc as pm

    total = 0.0
    for f in factors:
        b = pm.Normal(contrast_variable(f.name), 0.0, priors.effect_sd)
        total = total + b * f.index.astype(float)
    return total


def _group_effect(  # noqa: ANN202
    name: str,
    index: np.ndarray,
    specification: str,
    priors: Priors,
    zero_sum: bool = True,
    fixed_sd: float | None = None,
):
    """A group-level effect, non-centred (sigma * z) against the funnel of small studies.

    ``fixed_sd`` replaces the sd's prior by a known value (the conditional fit of the R cross-check).
    """
    import pymc as pm

    n = _n(index)
    if fixed_sd is not None:
        sigma = float(fixed_sd)
        z = pm.Normal(f"z_{name}", 0.0, 1.0, shape=n)
    elif specification == "paper":
        sigma = pm.HalfNormal(f"sigma_{name}", priors.scale_sd)
        z = pm.Normal(f"z_{name}", 0.0, 1.0, shape=n)
    else:
        sigma = pm.Exponential(f"sigma_{name}", 1.0 / priors.scale_sd)
        # Zero-sum in Eq. (3): the cut-points carry the location, which removes a ridge between them.
        z = (
            pm.ZeroSumNormal(f"z_{name}", sigma=1.0, shape=n)
            if zero_sum
            else pm.Normal(f"z_{name}", 0.0, 1.0, shape=n)
        )
    effect = pm.Deterministic(f"a_{name}", sigma * z)
    return effect[index]


def ordinal_model(  # noqa: ANN201
    design: OrdinalDesign,
    specification: str = "paper",
    priors: Priors | None = None,
    participant_sd: float | None = None,
):
    """Eq. (3) (``paper``) or its extended variant, as a pm.Model.

    ``participant_sd`` fixes sigma_P at a given value instead of giving it a prior: the posterior is then the one
    conditional on that sd, which the R cross-check compares with clmm's maximum-likelihood fit (tests/study).

    The paper model is sampled in an equivalent parametrisation: the index-coded levels' midpoints, the question
    mean alpha_bar and the cut-points share one location that the answers do not fix (only cut-point minus
    location enters the likelihood), a ridge that slows NUTS. So the likelihood uses thresholds
    ``u = alpha - location``, the location gets its exact prior (the sum of the midpoints and alpha_bar), and the
    cut-points ``alpha = u + location`` get their Normal(0, cutpoint_sd) prior as a potential (a shift, Jacobian 1).
    The posterior of every contrast, sd and cut-point is the paper model's.
    """
    import pymc as pm

    if specification not in SPECIFICATIONS:
        raise UnknownNameError("model", specification, SPECIFICATIONS)
    priors = priors or Priors.defaults(specification)
    paper = specification == "paper"
    with pm.Model() as model:
        phi = (_paper_terms if paper else _extended_terms)(design.factors, priors)
        if design.participant is not None:
            phi = phi + _group_effect("P", design.participant, specification, priors, fixed_sd=participant_sd)
        if design.question is not None:
            phi = phi + _group_effect("Q", design.question, specification, priors)
        phi = phi + np.zeros(len(design.y))  # a tensor even without any term
        if paper:
            sd = _location_sd(len(design.factors), priors, design.question is not None)
            location = pm.Normal("location", 0.0, sd)
        for name, rows, k in design.blocks:
            if k < 2:
                raise SconeError(
                    f"questionnaire {name}: an ordinal scale needs at least 2 categories, got {k}"
                )
            if paper:
                u = pm.Flat(
                    f"thresholds_{name}",
                    shape=k - 1,
                    transform=pm.distributions.transforms.ordered,
                    initval=np.linspace(-1.0, 1.0, k - 1),
                )
                cuts = pm.Deterministic(f"cutpoints_{name}", u + location)
                prior = pm.logp(pm.Normal.dist(0.0, priors.cutpoint_sd), cuts).sum()
                pm.Potential(f"cutpoint_prior_{name}", prior)
            else:
                centre = np.linspace(-2.5, 2.5, k - 1)
                u = pm.Normal(
                    f"cutpoints_{name}",
                    mu=centre,
                    sigma=priors.cutpoint_sd,
                    shape=k - 1,
                    transform=pm.distributions.transforms.ordered,
                    initval=centre,
                )
            pm.Potential(f"R_{name}", _ordered_logit_logp(phi[rows], u, design.y[rows]))
    return model


def count_model(design: CountDesign, specification: str = "paper", priors: Priors | None = None):  # noqa: ANN201
    """Eq. (4) (``paper``: log-rate = sum of index-coded levels + participant) or its extended variant."""
    import pymc as pm

    if specification not in SPECIFICATIONS:
        raise UnknownNameError("model", specification, SPECIFICATIONS)
    priors = priors or Priors.defaults(specification)
    with pm.Model() as model:
        if specification == "paper":
            # The levels' midpoints sum to the intercept (see _paper_terms).
            intercept = pm.Normal("location", 0.0, _location_sd(len(design.factors), priors, False))
            log_rate = intercept + _paper_terms(design.factors, priors)
        else:
            log_rate = pm.Normal("a", 0.0, 1.5) + _extended_terms(design.factors, priors)
        if design.participant is not None:
            log_rate = log_rate + _group_effect(
                "P", design.participant, specification, priors, zero_sum=False
            )
        log_rate = log_rate + np.zeros(len(design.counts))
        pm.Poisson("I", mu=pm.math.exp(log_rate), observed=design.counts)
    return model
