"""``scone-bench study-analysis``: one analysis of a simulated 31-participant study with the published sampler
settings (both questionnaires and the interventions), timed, plus recovery of known effects.

The answers come from simulated participants with static trust, no per-session noise and a known condition effect
(+1.0 logit), so they follow Eq. (3); the interventions of the same study come from the synthetic episodes. A second
Poisson fit on counts drawn from Eq. (4) with a known +1.0 log-rate effect checks the Poisson model. Prints JSON:
participants, wall_s (target <= 180 s on 2 cores), cpu_s (this process and its sampler processes), per-model
seconds, the condition contrasts with whether their 95 % HDI contains the truth, and the load average at the start.
"""

from __future__ import annotations

import argparse
import os
import resource
import tempfile
import time
from pathlib import Path

from scone_bt.cli.bench import emit_report

__all__ = ["register"]

TARGET_WALL_S = 180.0


def _cpu_s() -> float:
    own = resource.getrusage(resource.RUSAGE_SELF)
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


def _bench(args: argparse.Namespace) -> int:
    from scone_bt.quiet import quiet_backends
    from scone_bt.study.analysis import (
        AnalysisOptions,
        analyze,
        contrasts_of,
        fit_poisson,
        load_study,
        write_outputs,
    )
    from scone_bt.study.power import simulate_counts
    from scone_bt.study.simulate import SimulationOptions, simulate_study
    from scone_bt.study.trust import TrustParameters

    quiet_backends(("pymc", "pytensor"))
    effect = 1.0
    trust = TrustParameters(
        success_gain=0.0, failure_loss=0.0, help_gain=0.0, condition_effect=effect, response_noise_sd=0.0
    )
    load = os.getloadavg()[0]
    with tempfile.TemporaryDirectory(prefix="scone-bench-analysis-") as folder:
        log = simulate_study(
            Path(folder) / "sim.db",
            SimulationOptions(participants=args.participants, fast=True, trust=trust, seed=args.seed),
            printer=lambda _l: None,
        )
        data = load_study(log)
        log.close()
    options = AnalysisOptions(
        chains=args.chains, tune=args.tune, draws=args.draws, cores=args.cores, seed=args.seed
    )
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
    emit_report(report, args.json)
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``study-analysis`` to ``scone-bench``."""
    b = sub.add_parser("study-analysis", help="time one paper-model analysis of 31 simulated participants")
    b.add_argument("--participants", type=int, default=31)
    b.add_argument("--chains", type=int, default=6)
    b.add_argument("--tune", type=int, default=500)
    b.add_argument("--draws", type=int, default=500)
    b.add_argument("--cores", type=int, default=2, help="processes for the chains")
    b.add_argument("--seed", type=int, default=0)
    b.add_argument("--out", type=Path, help="also write results.json, scores.csv and Fig. 3 here")
    b.add_argument("--force", action="store_true", help="overwrite earlier results in --out")
    b.add_argument("--json", help="also write the JSON report to this file")
    b.set_defaults(func=_bench)
