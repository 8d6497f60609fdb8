"""Study planning by simulation: how likely is a study of N participants to find a stated effect?

For each N in a list, simulate ``repetitions`` studies with a known condition effect, analyse each with the
chosen model, and count how often the 95 % HDI of the condition contrast lies entirely outside the ROPE (the
decision "reject no difference"): that share is the power at N. Questionnaire answers come from the simulated
participants of trust.py with static trust (the episodes do not move it, so the stated effect is the whole
difference between conditions) and, by default, no per-session answer noise (so they follow Eq. (3)); intervention
counts are drawn from Eq. (4) itself (``simulate_counts``).

Every (N, repetition) work item gets its own seeds from ``numpy.random.SeedSequence([seed, N, repetition])``, so
the result does not depend on the number of worker processes or on the order the items finish in. The parallel
map is one function, ``parallel_map``, so another task engine can replace it.
"""

from __future__ import annotations

import math
import tempfile
import time
from collections.abc import Callable, Iterable, Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any, TypeVar

import numpy as np

from scone_bt.errors import SconeError, UnknownNameError
from scone_bt.strict_json import dumps

__all__ = [
    "MEASURES",
    "PowerOptions",
    "PowerPoint",
    "PowerResult",
    "WorkItem",
    "simulate_counts",
    "run_one",
    "parallel_map",
    "run_power",
    "check_power_outputs",
    "write_power",
]

MEASURES = ("mdmt", "tps_hri", "interventions")
MAX_PARTICIPANTS = 1000
"""Largest study `--n` plans for: each simulated study is fitted by MCMC, whose time grows with the data."""
MAX_EFFECT = 10.0
"""Largest |condition effect| (logit or log-rate), as `scone-study simulate --condition-effect`."""
_T = TypeVar("_T")
_R = TypeVar("_R")


@dataclass(frozen=True)
class PowerOptions:
    """What to simulate and how to analyse it.

    Attributes:
        participants: The participant numbers N to evaluate (each at least 2, one per group).
        repetitions: Simulated studies per N.
        effect: True condition effect (on - off), in logit (questionnaires) or log-rate (interventions) units.
        measure: mdmt, tps_hri or interventions.
        specification: Model fitted: paper or extended.
        rope: Region of practical equivalence.
        hdi_prob: HDI mass.
        chains: Chains per analysis (sequential inside a worker: the workers are the parallelism).
        tune: Warm-up draws per chain.
        draws: Kept draws per chain.
        workers: Worker processes (None: CPU count), or Ray workers with `ray` (None: the cluster's CPUs).
        ray: Ray address ("auto", "local", "ray://host:port") to run the studies on; None: local processes.
        seed: Root seed of every simulated study and sampler.
        response_noise_sd: Per-session noise of the simulated answers (logit). 0 draws them from Eq. (3) itself;
            the trust model's own default (0.3) adds a term the paper model lacks, whose HDIs are then too narrow
            and whose power is optimistic (docs/study.md).
        trust_params: The simulated participants' trust: "fitted" (to human ratings, scone_bt/trust/fitted.json)
            or "hand".
    """

    participants: tuple[int, ...] = (10, 20, 31, 50)
    repetitions: int = 20
    effect: float = 1.0
    measure: str = "mdmt"
    specification: str = "paper"
    rope: tuple[float, float] = (-0.18, 0.18)
    hdi_prob: float = 0.95
    chains: int = 2
    tune: int = 300
    draws: int = 300
    workers: int | None = None
    seed: int = 0
    ray: str | None = None
    response_noise_sd: float = 0.0
    trust_params: str = "fitted"

    def __post_init__(self) -> None:
        if not (math.isfinite(self.response_noise_sd) and self.response_noise_sd >= 0):
            raise SconeError(f"--answer-noise-sd must be 0 or more, got {self.response_noise_sd}")
        if not self.participants or min(self.participants) < 2 or max(self.participants) > MAX_PARTICIPANTS:
            raise SconeError(
                f"--n: participant numbers must be 2 to {MAX_PARTICIPANTS}, got {list(self.participants)}"
            )
        if self.repetitions < 1:
            raise SconeError(f"--repetitions must be at least 1, got {self.repetitions}")
        if self.trust_params not in ("fitted", "hand"):
            raise UnknownNameError("trust parameters", self.trust_params, ("fitted", "hand"))
        if self.measure not in MEASURES:
            raise UnknownNameError("measure", self.measure, MEASURES)
        if self.workers is not None and self.workers < 1:
            raise SconeError(f"--workers must be at least 1, got {self.workers}")
        if not (math.isfinite(self.effect) and abs(self.effect) <= MAX_EFFECT):
            # a log-rate of 25 overflowed the simulated counts (Poisson's lam) and the sampler
            raise SconeError(f"--effect must be in [-{MAX_EFFECT:g}, {MAX_EFFECT:g}], got {self.effect}")
        self.analysis_options(0)  # sampler, ROPE and model checks, before any work starts

    @classmethod
    def from_text(cls, n: str, **kwargs: Any) -> PowerOptions:
        """Options with N given as a comma list ("10,20,31")."""
        from scone_bt.checks import comma_list

        items = comma_list(n, "--n", "10,20,31")
        try:
            participants = tuple(sorted({int(x) for x in items}))
        except ValueError:
            raise SconeError(f"--n: {n!r} is not a comma list of whole numbers (e.g. 10,20,31)") from None
        return cls(participants=participants, **kwargs)

    def analysis_options(self, seed: int):  # -> AnalysisOptions
        from scone_bt.study.analysis import AnalysisOptions

        return AnalysisOptions(
            specification=self.specification,
            chains=self.chains,
            tune=self.tune,
            draws=self.draws,
            cores=1,
            rope=self.rope,
            hdi_prob=self.hdi_prob,
            seed=seed,
        )


_TRUST_LABEL = {
    "fitted": "trust fitted to human ratings (Soh et al.); take-overs and help requests assumed",
    "hand": "hand-set trust parameters",
}


@dataclass(frozen=True)
class WorkItem:
    """One simulated study: N participants, repetition r, with its derived seeds."""

    participants: int
    repetition: int
    study_seed: int
    sampler_seed: int


@dataclass(frozen=True)
class PowerPoint:
    """The outcome at one N.

    Attributes:
        participants: N.
        repetitions: Studies simulated.
        power: Share whose HDI excludes the ROPE (decision reject) in the effect's direction.
        power_ci: 95 % Wilson interval of that share.
        coverage: Share whose HDI contains the true effect.
        mean_estimate: Mean of the posterior means.
        mean_hdi_width: Mean HDI width.
    """

    participants: int
    repetitions: int
    power: float
    power_ci: tuple[float, float]
    coverage: float
    mean_estimate: float
    mean_hdi_width: float


@dataclass(frozen=True)
class PowerResult:
    """Everything `scone-study power` reports."""

    options: PowerOptions
    points: tuple[PowerPoint, ...]
    runs: tuple[dict[str, Any], ...]
    seconds: float
    workers: int

    def to_json(self) -> dict[str, Any]:
        return {
            "data": "SIMULATED",
            "options": asdict(self.options),
            "workers": self.workers,
            "seconds": round(self.seconds, 1),
            "power": [asdict(p) for p in self.points],
            "runs": list(self.runs),
        }

    def format(self) -> str:
        o = self.options
        lines = [
            f"── power (SIMULATED): {o.measure}, {o.specification} model, true effect {o.effect:+g}, "
            f"ROPE [{o.rope[0]:g}, {o.rope[1]:g}], {o.repetitions} studies per N ──",
            f"participants: {_TRUST_LABEL[o.trust_params]}",
            f"{'N':>5} {'power':>6} {'95% CI':>15} {'coverage':>9} {'mean est.':>10} {'HDI width':>10}",
        ]
        for p in self.points:
            lines.append(
                f"{p.participants:>5} {p.power:6.2f} [{p.power_ci[0]:5.2f}, {p.power_ci[1]:5.2f}] "
                f"{p.coverage:9.2f} {p.mean_estimate:10.3f} {p.mean_hdi_width:10.3f}"
            )
        lines.append(f"{len(self.runs)} analyses in {self.seconds:.0f} s on {self.workers} worker processes")
        return "\n".join(lines)


def work_items(options: PowerOptions) -> list[WorkItem]:
    """All (N, repetition) items, each seeded from SeedSequence([seed, N, repetition])."""
    items = []
    for n in options.participants:
        for r in range(options.repetitions):
            study, sampler = np.random.SeedSequence([options.seed, n, r]).generate_state(2)
            items.append(WorkItem(n, r, int(study), int(sampler)))
    return items


def simulate_counts(
    participants: int,
    effect: float,
    seed: int,
    base_rate: float = 1.5,
    participant_sd: float = 0.5,
    session_effect: float = 0.0,
):  # -> StudyData
    """A SIMULATED per-session table from Eq. (4): I ~ Poisson(exp(log base_rate + effect·on + session + a_P)).

    Groups alternate A, B, A, ...; group A has self-confidence on in session 1.
    """
    import pandas as pd

    from scone_bt.study.analysis import StudyData

    rng = np.random.default_rng([seed, 4])
    rows = []
    for i in range(participants):
        pid, group = f"SIM{i + 1:03d}", "AB"[i % 2]
        a_p = rng.normal(0.0, participant_sd)
        for session in (1, 2):
            on = (group == "A") == (session == 1)
            log_rate = math.log(base_rate) + effect * on + session_effect * (session == 2) + a_p
            rows.append(
                {
                    "session_id": f"{pid}/{session}",
                    "participant": pid,
                    "group": group,
                    "condition": "on" if on else "off",
                    "session_index": session,
                    "interventions": int(rng.poisson(math.exp(log_rate))),
                }
            )
    ratings = pd.DataFrame(columns=["questionnaire"])
    return StudyData(ratings, pd.DataFrame(rows), True, "simulate_counts", ())


def _simulate_answers(options: PowerOptions, item: WorkItem, folder: Path):  # -> StudyData
    from scone_bt.study.analysis import load_study
    from scone_bt.study.simulate import SimulationOptions, simulate_study
    from scone_bt.study.trust import trust_parameters

    trust = trust_parameters(options.trust_params).static(
        condition_effect=options.effect, response_noise_sd=options.response_noise_sd
    )
    sim = SimulationOptions(participants=item.participants, fast=True, trust=trust, seed=item.study_seed)
    log = simulate_study(folder / "study.db", sim, printer=lambda _l: None)
    try:
        return load_study(log)
    finally:
        log.close()


def run_one(options: PowerOptions, item: WorkItem) -> dict[str, Any]:
    """Simulate and analyse one study; returns its condition contrast and decision."""
    from scone_bt.quiet import quiet_backends
    from scone_bt.study.analysis import decide, fit_ordinal, fit_poisson

    quiet_backends(("pymc", "pytensor"))
    start = time.perf_counter()
    analysis = options.analysis_options(item.sampler_seed)
    if options.measure == "interventions":
        fit = fit_poisson(
            simulate_counts(item.participants, options.effect, item.study_seed).sessions, analysis
        )
    else:
        with tempfile.TemporaryDirectory(prefix="scone-power-") as folder:
            data = _simulate_answers(options, item, Path(folder))
        ratings = data.ratings[data.ratings["questionnaire"] == options.measure]
        fit = fit_ordinal(ratings, analysis, options.measure)
    import arviz as az

    s = fit.samples["condition"]
    lo, hi = (float(x) for x in az.hdi(s, hdi_prob=options.hdi_prob))
    return {
        "participants": item.participants,
        "repetition": item.repetition,
        "study_seed": item.study_seed,
        "sampler_seed": item.sampler_seed,
        "mean": round(float(s.mean()), 4),
        "hdi": [round(lo, 4), round(hi, 4)],
        "decision": decide((lo, hi), options.rope),
        "r_hat_max": fit.r_hat_max,
        "divergences": fit.divergences,
        "seconds": round(time.perf_counter() - start, 2),
    }


def _call(job: tuple[Callable[..., _R], tuple[Any, ...]]) -> _R:
    fn, args = job
    return fn(*args)


def parallel_map(
    fn: Callable[..., _R], jobs: Iterable[tuple[Any, ...]], workers: int | None, ray: str | None = None
) -> list[_R]:
    """``[fn(*args) for args in jobs]``, in order, over ``workers`` processes (spawned: PyMC is not fork-safe).

    The one place that knows how work is distributed; fn must be a module-level function. With `ray` (an
    address) the jobs are Ray tasks (scone_bt.distributed): same results, any number of machines.
    """
    jobs = list(jobs)
    if ray is not None:
        from scone_bt.distributed import EngineKind, EngineOptions, map_tasks

        engine = EngineOptions(EngineKind.RAY, workers=workers, address=ray)
        return map_tasks(_call, [(fn, args) for args in jobs], engine=engine)
    workers = workers or 1
    if workers <= 1 or len(jobs) <= 1:
        return [fn(*args) for args in jobs]
    import multiprocessing

    context = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(max_workers=min(workers, len(jobs)), mp_context=context) as pool:
        return list(pool.map(_call, [(fn, args) for args in jobs]))


def _wilson(successes: int, n: int, z: float = 1.96) -> tuple[float, float]:
    p = successes / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return round(max(0.0, centre - half), 4), round(min(1.0, centre + half), 4)


def _summarise(options: PowerOptions, runs: Sequence[dict[str, Any]]) -> tuple[PowerPoint, ...]:
    points = []
    for n in options.participants:
        mine = [r for r in runs if r["participants"] == n]
        # Power in the effect's direction: an HDI wholly on the wrong side of the ROPE is not a finding.
        sign = 1.0 if options.effect >= 0 else -1.0
        found = sum(r["decision"] == "reject" and sign * r["mean"] > 0 for r in mine)
        covered = sum(r["hdi"][0] <= options.effect <= r["hdi"][1] for r in mine)
        points.append(
            PowerPoint(
                participants=n,
                repetitions=len(mine),
                power=round(found / len(mine), 4),
                power_ci=_wilson(found, len(mine)),
                coverage=round(covered / len(mine), 4),
                mean_estimate=round(float(np.mean([r["mean"] for r in mine])), 4),
                mean_hdi_width=round(float(np.mean([r["hdi"][1] - r["hdi"][0] for r in mine])), 4),
            )
        )
    return tuple(points)


def run_power(options: PowerOptions, printer: Callable[[str], None] = lambda _l: None) -> PowerResult:
    """Simulate and analyse every (N, repetition) in parallel; summarise power per N."""
    import os

    items = work_items(options)
    workers = options.workers or os.cpu_count() or 1
    printer(
        f"power: {len(items)} simulated studies ({options.repetitions} per N in {list(options.participants)}) "
        f"on {min(workers, len(items))} processes"
    )
    start = time.perf_counter()
    if options.ray is not None:
        workers = options.workers or 0  # 0: every CPU of the Ray cluster
    runs = parallel_map(run_one, [(options, item) for item in items], workers or None, ray=options.ray)
    return PowerResult(options, _summarise(options, runs), tuple(runs), time.perf_counter() - start, workers)


def check_power_outputs(folder: str | Path, force: bool = False) -> dict[str, Path]:
    """Refuse, before any simulation, an output folder that would lose earlier results."""
    from scone_bt.study.analysis import check_output_folder

    out = Path(folder)
    paths = {"json": out / "power.json", "plot": out / "power.png"}
    return check_output_folder(out, paths, force, "power.json and power.png")


def write_power(result: PowerResult, folder: str | Path, force: bool = False) -> dict[str, Path]:
    """power.json and power.png (power against N with 95 % Wilson intervals), labelled SIMULATED."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    paths = check_power_outputs(folder, force)
    paths["json"].write_text(dumps(result.to_json(), indent=2))
    o = result.options
    n = [p.participants for p in result.points]
    power = np.array([p.power for p in result.points])
    ci = np.array([p.power_ci for p in result.points])
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.errorbar(n, power, yerr=[power - ci[:, 0], ci[:, 1] - power], fmt="o-", color="#2a6f97", capsize=4)
    ax.axhline(0.8, color="grey", lw=0.8, ls="--")
    ax.text(n[0], 0.81, "0.8", color="grey", fontsize=8)
    ax.set_ylim(-0.02, 1.02)
    ax.set_xlabel("participants (N)")
    ax.set_ylabel("P(95 % HDI excludes the ROPE)")
    unit = "log-rate" if o.measure == "interventions" else "logit"
    ax.set_title(
        f"SIMULATED: power for {o.measure}, effect {o.effect:+g} {unit}\n"
        f"{o.specification} model, ROPE [{o.rope[0]:g}, {o.rope[1]:g}], {o.repetitions} studies per N",
        fontsize=9,
        color="#b00020",
    )
    fig.tight_layout()
    fig.savefig(paths["plot"], dpi=100)
    plt.close(fig)
    return paths
