"""``scone-bench study-analysis``: one analysis of a simulated 31-participant study with the published sampler
settings (both questionnaires and the interventions), timed, plus recovery of known effects.

The answers come from simulated participants with static trust, no per-session noise and a known condition effect
(+1.0 logit), so they follow Eq. (3); the interventions of the same study come from the synthetic episodes. A second
Poisson fit on counts drawn from Eq. (4) with a known +1.0 log-rate effect checks the Poisson model. Prints JSON:
participants, wall_s (target <= 180 s on 2 cores), cpu_s (this process and its sampler processes), per-model
seconds, the condition contrasts with whether their 95 % HDI contains the truth, and the load average at the start.

``scone-bench study-recovery`` repeats the known-effect check over several seeds (simulated 31-participant studies,
the same answer model): per questionnaire the HDIs' coverage of the truth, the mean estimate and its bias, and,
where R's ordinal package is installed, the mean difference to clmm's maximum-likelihood estimate on the same data
(which separates what the data say from what the model's priors add); the Poisson model on Eq. (4) counts too.
Per measure it also compares the spread of the estimates over the seeds with the mean posterior sd (and clmm's
mean se): near 1 when the simulated data follow the fitted model (docs/study.md, "Known-effect recovery").
"""

from __future__ import annotations

import argparse
import os
import resource
import tempfile
import time
from pathlib import Path
from typing import Any

from scone_bt.argparsing import path_arg
from scone_bt.reporting import emit_report

__all__ = ["register"]

TARGET_WALL_S = 180.0


def _cpu_s() -> float:
    own = resource.getrusage(resource.RUSAGE_SELF)
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


def _bench(args: argparse.Namespace) -> int:
    from scone_bt.checks import check_output_dir
    from scone_bt.quiet import quiet_backends
    from scone_bt.study.analysis import (
        AnalysisOptions,
        analyze,
        check_outputs,
        contrasts_of,
        fit_poisson,
        load_study,
    )
    from scone_bt.study.outputs import write_outputs
    from scone_bt.study.power import simulate_counts
    from scone_bt.study.simulate import SimulationOptions, simulate_study
    from scone_bt.study.trust import trust_parameters

    quiet_backends(("pymc", "pytensor"))
    # Checked before the study is simulated and sampled: minutes of work are not lost to a bad setting or --out.
    options = AnalysisOptions(
        chains=args.chains, tune=args.tune, draws=args.draws, cores=args.cores, seed=args.seed
    )
    if args.out:
        check_output_dir(args.out, "--out")
        check_outputs(args.out, args.force)
    effect = 1.0
    trust = trust_parameters(args.trust_params).static(condition_effect=effect, response_noise_sd=0.0)
    load = os.getloadavg()[0]
    with tempfile.TemporaryDirectory(prefix="scone-bench-analysis-") as folder:
        log = simulate_study(
            Path(folder) / "sim.db",
            SimulationOptions(participants=args.participants, fast=True, trust=trust, seed=args.seed),
            printer=lambda _l: None,
        )
        data = load_study(log)
        log.close()
    cpu0, start = _cpu_s(), time.perf_counter()
    result = analyze(data, options)
    wall, cpu = time.perf_counter() - start, _cpu_s() - cpu0
    if args.out:
        write_outputs(result, data, args.out, force=args.force)
    counts = fit_poisson(simulate_counts(args.participants, effect, args.seed).sessions, options, "counts")
    known = contrasts_of(counts, options)[0]
    recovered = {}
    for model in ("mdmt", "tps_hri"):
        c = result.contrast(model, "condition")
        recovered[model] = {
            "mean": c.mean,
            "hdi": list(c.hdi),
            "contains_truth": c.hdi[0] <= effect <= c.hdi[1],
        }
    recovered["interventions_eq4_counts"] = {
        "mean": known.mean,
        "hdi": list(known.hdi),
        "contains_truth": known.hdi[0] <= effect <= known.hdi[1],
    }
    c = result.contrast("interventions", "condition")
    report = {
        "benchmark": "study-analysis",
        "data": "SIMULATED",
        "participants": args.participants,
        "trust_params": args.trust_params,
        "model": options.specification,
        "sampler": options.sampler_json(),
        "wall_s": round(wall, 1),
        "cpu_s": round(cpu, 1),
        "target_wall_s": TARGET_WALL_S,
        "wall_target_met": wall <= TARGET_WALL_S,
        "per_model_s": {m: round(f.seconds, 1) for m, f in result.fits.items()},
        "r_hat_max": max(f.r_hat_max for f in result.fits.values()),
        "divergences": sum(f.divergences for f in result.fits.values()),
        "true_condition_effect": effect,
        "recovered": recovered,
        "all_recovered": all(v["contains_truth"] for v in recovered.values()),
        "episode_interventions_condition": {"mean": c.mean, "hdi": list(c.hdi)},
        "load_average_at_start": round(load, 2),
        "cpu_count": os.cpu_count(),
    }
    emit_report(report, args.json, force=bool(getattr(args, "force", False)))
    return 0


def _seed_runs(args: argparse.Namespace, seed: int, priors: Any, without_r: str | None) -> dict[str, dict]:
    """One simulated study at ``seed``: each questionnaire's condition contrast (and clmm's), and Eq. (4)'s."""
    from scone_bt.study.analysis import AnalysisOptions, contrasts_of, fit_ordinal, fit_poisson, load_study
    from scone_bt.study.power import simulate_counts
    from scone_bt.study.r_clmm import fit_clmm
    from scone_bt.study.simulate import SimulationOptions, simulate_study
    from scone_bt.study.trust import TrustParameters

    trust = TrustParameters(
        success_gain=0.0, failure_loss=0.0, help_gain=0.0, condition_effect=args.effect, response_noise_sd=0.0
    )
    options = AnalysisOptions(
        chains=args.chains, tune=args.tune, draws=args.draws, cores=args.cores, seed=seed, priors=priors
    )
    with tempfile.TemporaryDirectory(prefix="scone-bench-recovery-") as folder:
        log = simulate_study(
            Path(folder) / "sim.db",
            SimulationOptions(participants=args.participants, fast=True, trust=trust, seed=seed),
            printer=lambda _l: None,
        )
        data = load_study(log)
        log.close()
    runs: dict[str, dict] = {}
    for q in ("mdmt", "tps_hri"):
        ratings = data.ratings[data.ratings["questionnaire"] == q].reset_index(drop=True)
        c = contrasts_of(fit_ordinal(ratings, options, q), options)[0]
        run = {"seed": seed, "mean": c.mean, "sd": c.sd, "hdi": list(c.hdi)}
        if without_r is None:
            ml = fit_clmm(
                ratings[["category", "condition", "session_index", "participant", "item"]],
                "category ~ condition + session_index + (1|participant) + (1|item)",
            )
            run["clmm"], run["clmm_se"] = (round(v, 4) for v in ml.fixed["conditionon"])
        runs[q] = run
    counts = fit_poisson(simulate_counts(args.participants, args.effect, seed).sessions, options, "counts")
    c = contrasts_of(counts, options)[0]
    runs["interventions_eq4_counts"] = {"seed": seed, "mean": c.mean, "sd": c.sd, "hdi": list(c.hdi)}
    return runs


def _recovery_summary(rs: list[dict], effect: float) -> dict[str, Any]:
    """One measure over the seeds: coverage, bias, calibration of the spread, and the gap to clmm."""
    import numpy as np

    means = np.array([r["mean"] for r in rs])
    entry: dict[str, Any] = {
        "coverage": sum(r["hdi"][0] <= effect <= r["hdi"][1] for r in rs) / len(rs),
        "mean_estimate": round(float(means.mean()), 4),
        "bias": round(float(means.mean() - effect), 4),
        "bias_se": round(float(means.std(ddof=1) / np.sqrt(len(rs))), 4) if len(rs) > 1 else None,
        "mean_posterior_sd": round(float(np.mean([r["sd"] for r in rs])), 4),
    }
    if len(rs) > 1:
        # Calibration: if the data follow the model, the estimates spread across studies as much as one
        # study's posterior sd says (ratio near 1; with n studies the ratio's own se is about 1/sqrt(2(n-1))).
        entry["sd_of_estimates"] = round(float(means.std(ddof=1)), 4)
        entry["sd_of_estimates_over_mean_sd"] = round(
            float(means.std(ddof=1)) / entry["mean_posterior_sd"], 3
        )
    if rs and "clmm" in rs[0]:
        ml = np.array([r["clmm"] for r in rs])
        diff = means - ml
        entry["clmm_mean_estimate"] = round(float(ml.mean()), 4)
        entry["clmm_mean_se"] = round(float(np.mean([r["clmm_se"] for r in rs])), 4)
        if len(rs) > 1:
            entry["clmm_sd_of_estimates"] = round(float(ml.std(ddof=1)), 4)
        entry["mean_minus_clmm"] = round(float(diff.mean()), 4)
        entry["mean_minus_clmm_range"] = [round(float(diff.min()), 4), round(float(diff.max()), 4)]
    return entry


def _recovery(args: argparse.Namespace) -> int:
    from scone_bt.checks import check_positive_int, check_range
    from scone_bt.quiet import quiet_backends
    from scone_bt.study.analysis import AnalysisOptions
    from scone_bt.study.models import Priors
    from scone_bt.study.r_clmm import r_unavailable

    check_positive_int(args.seeds, "--seeds", maximum=10_000)
    check_range(args.effect, "--effect", -10.0, 10.0)  # as scone-study simulate --condition-effect
    quiet_backends(("pymc", "pytensor"))
    effect = args.effect
    priors = Priors(args.effect_prior_sd, args.cutpoint_prior_sd, args.scale_prior_sd)
    # the sampler settings, checked before any study is simulated (each seed's run builds its own options)
    AnalysisOptions(chains=args.chains, tune=args.tune, draws=args.draws, cores=args.cores, priors=priors)
    without_r = r_unavailable()
    load, start = os.getloadavg()[0], time.perf_counter()
    runs: dict[str, list[dict]] = {"mdmt": [], "tps_hri": [], "interventions_eq4_counts": []}
    for seed in range(args.first_seed, args.first_seed + args.seeds):
        for name, run in _seed_runs(args, seed, priors, without_r).items():
            runs[name].append(run)
    summary = {name: _recovery_summary(rs, effect) for name, rs in runs.items()}
    report = {
        "benchmark": "study-recovery",
        "data": "SIMULATED",
        "participants": args.participants,
        "true_condition_effect": effect,
        "seeds": [args.first_seed, args.first_seed + args.seeds - 1],
        "model": "paper",
        "priors": {
            "effect_sd": priors.effect_sd,
            "cutpoint_sd": priors.cutpoint_sd,
            "scale_sd": priors.scale_sd,
        },
        "sampler": {"chains": args.chains, "tune": args.tune, "draws": args.draws, "cores": args.cores},
        "clmm": "ordinal::clmm (ML) on the same ratings" if without_r is None else f"skipped: {without_r}",
        "summary": summary,
        "runs": runs,
        "wall_s": round(time.perf_counter() - start, 1),
        "load_average_at_start": round(load, 2),
    }
    emit_report(report, args.json, force=bool(getattr(args, "force", False)))
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``study-analysis`` and ``study-recovery`` to ``scone-bench``."""
    b = sub.add_parser("study-analysis", help="time one paper-model analysis of 31 simulated participants")
    b.add_argument("--participants", type=int, default=31)
    b.add_argument("--chains", type=int, default=6)
    b.add_argument("--tune", type=int, default=500)
    b.add_argument("--draws", type=int, default=500)
    b.add_argument("--cores", type=int, default=2, help="processes for the chains")
    b.add_argument("--seed", type=int, default=0)
    b.add_argument("--out", type=path_arg, help="also write results.json, scores.csv and Fig. 3 here")
    b.add_argument(
        "--force",
        action="store_true",
        help="overwrite earlier results in --out, and let --json replace an existing file of another kind",
    )
    b.add_argument(
        "--trust-params",
        choices=("fitted", "hand"),
        default="fitted",
        help="simulated participants: fitted to human ratings (scone_bt/trust/fitted.json) or hand-set",
    )
    b.add_argument("--json", help="also write the JSON report to this file")
    b.set_defaults(func=_bench)

    r = sub.add_parser("study-recovery", help="coverage and bias of the known condition effect over seeds")
    r.add_argument(
        "--seeds", type=int, default=5, help="simulated studies (seeds first-seed, first-seed+1, ...)"
    )
    r.add_argument("--first-seed", type=int, default=0)
    r.add_argument("--participants", type=int, default=31)
    r.add_argument("--effect", type=float, default=1.0, help="true condition effect (logit and log-rate)")
    r.add_argument("--chains", type=int, default=2)
    r.add_argument("--tune", type=int, default=300)
    r.add_argument("--draws", type=int, default=300)
    r.add_argument("--cores", type=int, default=2)
    r.add_argument("--effect-prior-sd", type=float, default=1.0)
    r.add_argument("--cutpoint-prior-sd", type=float, default=1.0)
    r.add_argument("--scale-prior-sd", type=float, default=1.0)
    r.add_argument("--json", help="also write the JSON report to this file")
    r.set_defaults(func=_recovery)
