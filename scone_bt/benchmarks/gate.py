"""``scone-bench gate``: does the gate keep its promise on products it never saw, and how much does it ask for it?

The online robot is replayed over self-confidence datasets (``--datasets DIR``, any folder that
``scone-bench sc generate`` wrote; default tools/data/sc: 11 streams of 100 real physical executions). Each
stream starts cold (no fleet prior): for each execution in order κ̂ predicts from the action's embedding and the
context the robot perceived, the gate acts or asks, and **only an attempt is labelled** (censoring: an asked
action teaches nothing, as on the robot). All decisions are made by the gate from the first one on; the first
``--warmup`` decisions of each stream are not scored (the promise is about the robot after it has had a chance to
learn), and the same figures over every decision are reported beside them.

Per method and per target failure rate α (0.05 … 0.40), pooled over the streams after their warm-up:
``success_rate`` (acted and succeeded / decisions), ``help_rate`` (asked / decisions), ``over_ask_rate`` (asked,
would have succeeded), ``over_step_rate`` (acted, failed), ``attempt_failure_rate`` (failed attempts / attempts),
its split into ``attempt_failure_rate_novel`` (products κ̂ had no outcome of in the stream) and ``_seen``,
``help_rate_floor`` (the least help any gate could reach at the realised rate: a clairvoyant, `help_floor`) and
``help_rate_floor_without_failures`` (a clairvoyant that never fails; the data's alone), ``help_by_cause`` (the
decisions asked for, by the rule that asked: "too-wide", "missing", "infeasible", "unsure" for κ̂'s own ask, …, or
why a probe set the product back: "set-back-felt", "set-back-unsure", "set-back-missed"; each with its rate, how
many would have succeeded and how many were of a product perceived wider than the gripper:
`replay_rates.help_by_cause`),
``wide_attempts_after_first_wide_failure`` (attempts of products perceived wider than the gripper's opening after a
stream's first failed one, summed and the largest per stream), the realised rate per stream, and
``max_excess_failures``: the largest F − α · A reached at any point of any stream, warm-up included, and
``max_excess_failures_where_confident_held``: the same over only the streams in which no confident attempt failed
(null if there is none; ``streams_where_confident_held`` says how many). An attempt is *confident* when κ̂ at its
final decision was at or above the threshold τ (the gate's κ̂ for an action that was not probed, κ̂ on the
context after the probe, what the fingers felt, for one that was), or when it carried on by feel (the probe felt
the product held fast, on that rule's own record: ``by_feel_attempts``, ``by_feel_failures``). With the strict
promise on (``--exploration-credit``: gate.budget.has_credit, gate.after_probe) that key is ≤ 1 but for a probe
that failed before the fingers felt anything (a probe needs no credit; ``probe_failures_before_feeling`` counts
them).

The replay decides as the tree does where the robot knows before its arm moves that it cannot act (`benchmarks.replay_streams.foreseen`):
a target the camera did not detect is asked for (the tree has no affordance for it), and where no plan exists
the gate's ACT becomes an ask before the arm moves, learnt by κ̂ as a failure at planning (RecordInfeasible), not
an attempt. The datasets record both as failed executions: the generator attempts every row. Methods:

- ``budget:<κ̂>``: the failure-budget gate (scone_bt.gate.budget) over κ̂ (the tree's default: ``physical``);
- ``fixed:<κ̂>``: the same κ̂ and exploration with a threshold fixed at τ₀ (1 − 5α) (no online calibration);
- ``conformal``: the full conformal KNN gate at α (KnowNo-style; acts when 1 − p-value ≥ 1 − α), with the same
  exploration (without it a cold conformal gate never acts);
- ``paper``: the paper's ε-KNN at its fixed 0.5 threshold (one point: it states no rate);
- ``oracle``: the budget gate over κ̂ given the true width, height, mass and glass (the ceiling).

The tree's default (``default.*``) is ``budget:<the tree's estimator>`` at the tree's ``target_failure_rate``, cold
and fleet-warm (κ̂ first learns every execution of the other streams: a fleet's shared store).

``--prior DIR`` (the move to another body): before each stream, every κ̂ first learns the outcomes of the
same-named dataset in DIR (the same robot's executions on another engine; ``default.*`` is then the taught robot),
and the report adds ``cross_engine`` (`scone_bt.benchmarks.cross_engine`): per profile the success rates of the
same executions on both engines, the executions whose outcome flips, and per α in 0.10, 0.15, 0.20 the default
gate taught and cold (with the heft probe where ``default.*`` has it: ``cross_engine.probe``), with the decisions
its budget needs before the realised rate is back within α + 0.02.

    scone-bench gate --datasets tools/data/sc_mujoco --prior tools/data/sc --json docs/results/gate_mujoco.json

    scone-bench gate --json docs/results/gate.json --plot docs/results/gate.png

``--unseen`` adds the ``unseen`` section (`scone_bt.benchmarks.gate_unseen`): on decisions about products κ̂ has
no outcome of (leave-products-out), the default gate cold, after the fleet prior and after the robot's own store.

    scone-bench gate --no-sweep --unseen --json docs/results/unseen.json
"""

from __future__ import annotations

import argparse
import math
import time
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from scone_bt.argparsing import path_arg
from scone_bt.benchmarks.gate_episodes import percentiles_ms, run_episodes
from scone_bt.benchmarks.replay import StreamResult, feature_rows, replay_stream
from scone_bt.benchmarks.replay_rates import pooled_rates
from scone_bt.benchmarks.replay_streams import (
    Streams,
    check_probe_readings,
    datasets_folder,
    load_streams,
    rotated,
    stream_rows,
)
from scone_bt.files import write_via
from scone_bt.reporting import emit_report

if TYPE_CHECKING:
    from scone_bt.gate.probe import ProbeOptions

__all__ = ["register", "stream_results", "results_over_starts", "TARGETS"]

TARGETS: tuple[float, ...] = (0.05, 0.10, 0.15, 0.20, 0.25, 0.30, 0.40)
"""Target failure rates the report sweeps."""

OVER_STARTS_STEP = 10
"""``default.over_starts`` starts each stream at every this many rows (`_over_starts`)."""


def _method(
    streams: Streams,
    estimator: str,
    gate: str,
    alpha: float,
    args: argparse.Namespace,
    fleet: bool = False,
    taught: Streams | None = None,
    probe: ProbeOptions | None = None,
) -> dict[str, Any]:
    """One method's pooled rates over every stream (`stream_results`, then `pooled_rates`)."""
    return pooled_rates(stream_results(streams, estimator, gate, alpha, args, fleet, taught, probe))


def stream_results(
    streams: Streams,
    estimator: str,
    gate: str,
    alpha: float,
    args: argparse.Namespace,
    fleet: bool = False,
    taught: Streams | None = None,
    probe: ProbeOptions | None = None,
) -> list[StreamResult]:
    """Every stream replayed (`replay_stream`, stream j seeded ``args.seed + j``, ``args.warmup``, ``args.opening``,
    the strict rule's ``args.excess_allowance`` if set, the budget's start and step ``args.budget`` if set, a
    `BudgetOptions`: tools/budget_start_sweep.py); ``taught`` (--prior): κ̂ first learns the same-named stream
    of it; ``fleet``: the other streams first; ``probe``: the budget gate's heft test (None: none)."""
    results = []
    for j in range(len(streams.names)):
        parts = []
        if taught is not None:
            parts.append(stream_rows(taught, [taught.names.index(streams.names[j])]))
        others = [i for i in range(len(streams.names)) if i != j]
        if fleet and others:
            parts.append(stream_rows(streams, others))
        prior = (np.vstack([x for x, _ in parts]), np.concatenate([y for _, y in parts])) if parts else None
        results.append(
            replay_stream(
                streams.vectors[j],
                streams.context[j],
                streams.success[j],
                streams.products[j],
                estimator,
                gate,
                alpha,
                args.seed + j,
                args.warmup,
                args.opening,
                prior,
                probe=probe,
                readings=streams.readings[j] if streams.readings else None,
                excess_allowance=getattr(args, "excess_allowance", None),
                foreseen=streams.foreseen[j] if streams.foreseen else None,
                budget=getattr(args, "budget", None),
                slide_pinch=bool(streams.slide_pinch and streams.slide_pinch[j]),
            )
        )
    return results


def _tree_defaults(args: argparse.Namespace) -> tuple[str, float, ProbeOptions | None]:
    """The tree's κ̂, target failure rate and probe options (None: the probe is off; ``--probe``/``--no-probe``
    override the tree's ``probe.enabled``); sets ``args.excess_allowance`` from the tree's ``exploration_credit``
    (or ``--exploration-credit``/``--no-exploration-credit``): 1 when on, None when off."""
    from scone_bt.config.tree_parameters import TreeParameters
    from scone_bt.gate.probe import ProbeOptions
    from scone_bt.tree import load_tree_spec

    params = TreeParameters.model_validate(load_tree_spec("assistive_cooking").parameters)
    probing = params.probe.enabled if args.probe is None else args.probe
    credit = params.exploration_credit if args.exploration_credit is None else args.exploration_credit
    args.excess_allowance = 1.0 if credit else None
    args.probe_on = probing
    probe = ProbeOptions.of(params.probe.model_copy(update={"enabled": True})) if probing else None
    return params.estimator, params.target_failure_rate, probe


def _plot(report: dict[str, Any], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2))
    for name, per_target in report["methods"].items():
        pts = sorted(per_target.items(), key=lambda kv: float(kv[0]))
        helps = [m["help_rate"] for _, m in pts]
        succ = [m["attempt_success_rate"] or 0.0 for _, m in pts]
        left.plot(helps, succ, "o-" if len(pts) > 1 else "s", label=name)
        if len(pts) > 1:
            right.plot(
                [float(k) for k, _ in pts],
                [m["attempt_failure_rate"] or 0.0 for _, m in pts],
                "o-",
                label=name,
            )
    left.set_xlabel("help rate (asked / decisions)")
    left.set_ylabel("attempts that succeed")
    left.set_title("attempt success against asking (after warm-up)")
    left.grid(alpha=0.3)
    if report["methods"]:  # a report with no method has nothing to label
        left.legend(fontsize=7)
    lim = max(TARGETS) + 0.05
    right.plot([0, lim], [0, lim], "k--", lw=1, label="promise: realised = target")
    right.plot([0, lim], [0.02, lim + 0.02], "k:", lw=1, label="target + 0.02")
    right.set_xlabel("target failure rate α")
    right.set_ylabel("realised failure rate among attempts")
    right.set_title("the promise, on products never seen and seen")
    right.grid(alpha=0.3)
    right.legend(fontsize=7)
    fig.tight_layout()
    try:  # an existing figure stays whole until the new one is complete
        write_via(path, lambda tmp: fig.savefig(tmp, dpi=110))
    finally:
        plt.close(fig)


PLOT_SUFFIXES = (".png", ".svg", ".pdf")
"""The figure formats --plot writes, by the file's suffix."""


def check_plot_path(path: Path, inputs: dict[str, list[Path]], force: bool) -> None:
    """--plot before any work: a file of a known figure format, not an input, nothing else overwritten."""
    from scone_bt.checks import check_output_file
    from scone_bt.errors import SconeError

    if path.suffix.lower() not in PLOT_SUFFIXES and not path.is_dir():
        raise SconeError(
            f"--plot {path}: unknown figure format {path.suffix or '(no suffix)'!r}; "
            f"give a file ending in one of {', '.join(PLOT_SUFFIXES)}"
        )
    check_output_file(path, "--plot", kind="image", inputs=inputs, force=force)


def _decision_path(
    streams: Streams, estimator: str, args: argparse.Namespace, reps: int = 40
) -> dict[str, Any]:
    """κ̂ on 21 objects (the kitchen's shelf: grounded rows) plus the gate's rule, right after an update (nothing
    memoised), the way the tree decides each cycle; planning before commitment is timed apart (episodes)."""
    from scone_bt.confidence import make_estimator
    from scone_bt.confidence.grounded import is_grounded
    from scone_bt.gate import GateOptions, decide
    from scone_bt.relevance import RankedAction

    est = make_estimator(estimator, seed=args.seed)
    V, C, y = streams.vectors[0], streams.context[0], streams.success[0]
    X = feature_rows(V, C, is_grounded(est))
    n = len(X)
    for t in range(n // 2):
        est.update(X[t], bool(y[t]))
    ranked = [RankedAction(f"a{i}", 1.0 - i / 100) for i in range(21)]
    samples = []
    for r in range(reps):
        i = n // 2 + r % max(n - n // 2, 1)
        est.update(X[i % n], bool(y[i % n]))  # empties the memo, as after an outcome
        rows = X[(np.arange(21) + r) % len(X)]
        t0 = time.perf_counter()
        conf = est.predict(rows)
        decide(ranked, [float(c) for c in conf], GateOptions(confidence_threshold=0.7))
        samples.append(time.perf_counter() - t0)
    return {"objects": 21, "estimator": estimator, **percentiles_ms(samples), "target_p50_ms": 10.0}


def _replay(
    args: argparse.Namespace,
    streams: Streams,
    estimators: list[str],
    default_estimator: str,
    default_target: float,
    probe: ProbeOptions | None = None,
) -> dict[str, Any]:
    """The online replay of every method over the datasets (the report's replay part)."""
    taught, taught_oracle = _taught(args, streams)
    methods = {} if args.no_sweep else _sweep(args, streams, estimators, taught, taught_oracle)
    default = methods.get(f"budget:{default_estimator}")
    if default is None or f"{default_target:g}" not in default:
        plain = _method(streams, default_estimator, "budget", default_target, args, taught=taught)
    else:
        plain = default[f"{default_target:g}"]
    probing = probe is not None and any(r is not None for r in streams.readings)
    if (
        probing
    ):  # the tree's gate hefts what it is unsure of (gate.probe): its own sweep beside the plain budget
        methods[f"budget+probe:{default_estimator}"] = {
            f"{a:g}": _method(streams, default_estimator, "budget", a, args, taught=taught, probe=probe)
            for a in TARGETS
        }
        cold = methods[f"budget+probe:{default_estimator}"][f"{default_target:g}"]
    else:
        cold = plain
    # The fleet-warm variant relearns the other streams' 1,000 rows at every update: --no-sweep leaves it out.
    warm = (
        None
        if args.no_sweep
        else _method(
            streams, default_estimator, "budget", default_target, args, fleet=True, taught=taught, probe=probe
        )
    )
    extra: dict[str, Any] = {}
    if taught is not None:
        extra["cross_engine"] = _cross_engine(
            args, streams, taught, default_estimator, probe if probing else None
        )
    return {
        "datasets": streams.names,
        **({"prior": str(args.prior), "prior_datasets": taught.names} if taught is not None else {}),
        "targets": list(TARGETS),
        "default": {
            "estimator": default_estimator,
            "target_failure_rate": default_target,
            "attempt_failure_rate": cold["attempt_failure_rate"],
            "attempt_failure_rate_novel": cold["attempt_failure_rate_novel"],
            "attempt_failure_rate_seen": cold["attempt_failure_rate_seen"],
            "attempt_success_rate": cold["attempt_success_rate"],
            "help_rate": cold["help_rate"],
            "help_rate_floor": cold["help_rate_floor"],
            "help_rate_floor_without_failures": cold["help_rate_floor_without_failures"],
            "help_by_cause": cold["help_by_cause"],
            "max_excess_failures": cold["max_excess_failures"],
            "max_excess_failures_where_confident_held": cold["max_excess_failures_where_confident_held"],
            "streams_where_confident_held": cold["streams_where_confident_held"],
            "exploration_credit": getattr(args, "excess_allowance", None) is not None,
            **_probe_keys(cold, plain, probing),
            "over_starts": _over_starts(
                args, streams, default_estimator, default_target, taught, probe if probing else None
            ),
            "fleet_warm": None
            if warm is None
            else {
                k: warm[k]
                for k in (
                    "attempt_failure_rate",
                    "attempt_failure_rate_novel",
                    "attempt_success_rate",
                    "help_rate",
                    "aborted_rate",
                )
            },
        },
        "methods": methods,
        **extra,
        "decision_path_ms": _decision_path(streams, default_estimator, args),
    }


def results_over_starts(
    streams: Streams,
    step: int,
    estimator: str,
    alpha: float,
    args: argparse.Namespace,
    taught: Streams | None = None,
    probe: ProbeOptions | None = None,
) -> Iterator[tuple[int, list[StreamResult]]]:
    """(start, `stream_results` of every stream started at row ``start``, `rotated`) for every ``step``-th row of the
    shortest stream: each start a new cold robot, seeded as the first (`_over_starts`, tools/cold_starts.py)."""
    length = min(len(s) for s in streams.success)
    for start in range(0, length, step):
        yield (
            start,
            stream_results(
                rotated(streams, start), estimator, "budget", alpha, args, taught=taught, probe=probe
            ),
        )


def _over_starts(
    args: argparse.Namespace,
    streams: Streams,
    estimator: str,
    alpha: float,
    taught: Streams | None,
    probe: ProbeOptions | None,
) -> dict[str, Any]:
    """The default gate's pooled rates had every stream started at another row (`rotated`, every
    `OVER_STARTS_STEP` rows, each start a new cold robot seeded as the first): ``help_rate`` and
    ``attempt_failure_rate`` are the first start's alone, so a few outcomes early in a stream move them far (a cold
    robot whose first carries fail asks for much of the rest). The mean, least and most over the starts say how far;
    ``streams_that_never_attempted``: (stream, start) pairs whose robot attempted nothing after the warm-up."""
    helps, failures, never = [], [], []
    for start, results in results_over_starts(
        streams, OVER_STARTS_STEP, estimator, alpha, args, taught, probe
    ):
        rates = pooled_rates(results)
        helps.append(rates["help_rate"])
        failures.append(rates["attempt_failure_rate"])
        never += [f"{n}@{start}" for n, r in zip(streams.names, results, strict=True) if r.attempts == 0]
    known = [f for f in failures if f is not None]
    return {
        "step": OVER_STARTS_STEP,
        "starts": len(helps),
        "help_rate_mean": round(float(np.mean(helps)), 4),
        "help_rate_min": round(float(np.min(helps)), 4),
        "help_rate_max": round(float(np.max(helps)), 4),
        "attempt_failure_rate_mean": round(float(np.mean(known)), 4) if known else None,
        "streams_that_never_attempted": never,
    }


def _sweep(
    args: argparse.Namespace,
    streams: Streams,
    estimators: list[str],
    taught: Streams | None,
    taught_oracle: Streams | None,
) -> dict[str, dict[str, Any]]:
    """Every method at every target (the report's ``methods``)."""
    methods: dict[str, dict[str, Any]] = {}
    for est in estimators:
        for gate in ("budget", "fixed"):
            methods[f"{gate}:{est}"] = {
                f"{a:g}": _method(streams, est, gate, a, args, taught=taught) for a in TARGETS
            }
    methods["conformal"] = {
        f"{a:g}": _method(streams, "conformal", "conformal", a, args, taught=taught) for a in TARGETS
    }
    methods["paper"] = {"0.5": _method(streams, "eps-knn", "paper", 0.5, args, taught=taught)}
    oracle = load_streams(args, oracle=True)
    methods["oracle"] = {
        f"{a:g}": _method(oracle, "physical", "budget", a, args, taught=taught_oracle) for a in TARGETS
    }
    return methods


def _probe_keys(cold: dict[str, Any], plain: dict[str, Any], probing: bool) -> dict[str, Any]:
    """The heft test's ``default.*`` keys: what it cost and caught, and the same gate without it."""
    return {
        "probe": probing,
        "aborted_rate": cold["aborted_rate"],
        "probe_s_mean": cold["probe_s_mean"],
        "probes": cold["probes"],
        "aborted_would_have_succeeded": cold["aborted_would_have_succeeded"],
        "aborted_would_have_failed": cold["aborted_would_have_failed"],
        "by_feel_attempts": cold["by_feel_attempts"],
        "by_feel_failures": cold["by_feel_failures"],
        "probe_failures_before_feeling": cold["probe_failures_before_feeling"],
        "help_rate_per_stream": cold["help_rate_per_stream"],
        "help_rate_floor_per_stream": cold["help_rate_floor_per_stream"],
        "without_probe": {
            k: plain[k]
            for k in ("attempt_failure_rate", "attempt_success_rate", "help_rate", "max_excess_failures")
        },
    }


def _taught(args: argparse.Namespace, streams: Streams) -> tuple[Streams | None, Streams | None]:
    """--prior's datasets (κ̂ learns the same-named one before each stream) and their oracle view, or None."""
    from scone_bt.errors import SconeError

    if args.prior is None:
        return None, None
    taught = load_streams(args, oracle=False, folder=Path(args.prior))
    taught_oracle = None if args.no_sweep else load_streams(args, oracle=True, folder=Path(args.prior))
    missing = [n for n in streams.names if n not in taught.names]
    if missing:
        raise SconeError(
            f"--prior {args.prior}: no dataset {missing[0]!r} (it holds {', '.join(taught.names)}); "
            "κ̂ learns the same-named dataset before each stream"
        )
    return taught, taught_oracle


def _cross_engine(
    args: argparse.Namespace,
    streams: Streams,
    taught: Streams,
    estimator: str,
    probe: ProbeOptions | None = None,
) -> dict[str, Any]:
    """The gap between the engines per profile, and the default gate taught (--prior) and cold after the move,
    with the heft test where the default gate has it (``probe``; None: none)."""
    from dataclasses import asdict

    from scone_bt.benchmarks.cross_engine import (
        CROSS_ENGINE_TARGETS,
        TOLERANCE,
        engine_gap,
        recovery_decisions,
    )

    gaps = engine_gap(Path(args.prior), datasets_folder(args), streams.names)
    by_target: dict[str, Any] = {}
    for alpha in CROSS_ENGINE_TARGETS:
        row: dict[str, Any] = {}
        for label, prior in (("prior", taught), ("cold", None)):
            results = stream_results(streams, estimator, "budget", alpha, args, taught=prior, probe=probe)
            rates = pooled_rates(results)
            recovery = {
                n: recovery_decisions(r.trace, alpha) for n, r in zip(streams.names, results, strict=True)
            }
            row[label] = {
                "attempt_failure_rate": rates["attempt_failure_rate"],
                "help_rate": rates["help_rate"],
                "attempt_success_rate": rates["attempt_success_rate"],
                "attempt_failure_rate_per_stream": dict(
                    zip(streams.names, rates["attempt_failure_rate_per_stream"], strict=True)
                ),
                "meets_target": rates["attempt_failure_rate"] is not None
                and rates["attempt_failure_rate"] <= alpha + TOLERANCE + 1e-12
                and rates["help_rate"] <= 0.50,
                "all_decisions": rates["all_decisions"],
                "recovery_decisions": recovery,
                "recovered_streams": sum(v is not None for v in recovery.values()),
            }
        by_target[f"{alpha:g}"] = row
    return {
        "prior": str(args.prior),
        "probe": probe is not None,
        "tolerance": TOLERANCE,
        "help_rate_limit": 0.50,
        "recovery_definition": (
            "decisions on this engine (warm-up included) before the budget's realised attempt failure rate, "
            "counted from the move, is within alpha + tolerance and stays there to the end of the stream; "
            "0: never above; null: ends above"
        ),
        "default": by_target,
        "profiles": {
            n: {
                **{k: v for k, v in asdict(g).items() if k != "flips"},
                "flipped": [asdict(f) for f in g.flips],
            }
            for n, g in gaps.items()
        },
        "pooled": {
            "matched": sum(g.matched for g in gaps.values()),
            "to_failure": sum(g.to_failure for g in gaps.values()),
            "to_success": sum(g.to_success for g in gaps.values()),
        },
    }


def _run(args: argparse.Namespace) -> int:
    from scone_bt.errors import SconeError

    if args.warmup < 0:
        raise SconeError(f"--warmup {args.warmup}: must be 0 or more")
    if args.episodes < 0:
        raise SconeError(f"--episodes {args.episodes}: must be 0 or more")
    if args.recipes < 1:
        raise SconeError(f"--recipes {args.recipes}: must be 1 or more")
    from scone_bt.config.robot import MAX_GRIPPER_OPENING_M

    if not (math.isfinite(args.opening) and 0 < args.opening < MAX_GRIPPER_OPENING_M):  # physical κ̂'s range
        raise SconeError(f"--opening {args.opening}: must be in (0, {MAX_GRIPPER_OPENING_M:g}) metres")
    if args.no_replay and not args.episodes and not args.unseen:
        raise SconeError("--no-replay with --episodes 0 and no --unseen: nothing to run; give --episodes N")
    if args.episodes:  # the episodes' robot, checked before minutes of replay
        from scone_bt.config import load_robot
        from scone_bt.resources import resolve_file

        load_robot(resolve_file("robots", args.arm, (".yaml", ".yml"), flag="--arm"))
    started = time.perf_counter()
    default_estimator, default_target, probe = _tree_defaults(args)
    estimators = [e for e in args.estimators.split(",") if e] or [default_estimator]
    from scone_bt.cli.run import _check_estimator  # one check of registry names, before any work

    for e in estimators:
        _check_estimator(e, "--estimators")
    if args.plot is not None:
        from scone_bt.cli.bench import _inputs

        check_plot_path(args.plot, _inputs(args, ("plot", "json")), bool(getattr(args, "force", False)))
    report: dict[str, Any] = {
        "benchmark": "gate",
        "seed": args.seed,
        "embedder": args.embedder,
        "warmup": args.warmup,
        "gripper_opening_m": args.opening,
    }
    # the datasets, loaded and embedded once for the replay and the unseen section
    streams = load_streams(args, oracle=False) if not args.no_replay or args.unseen else None
    if streams is not None:
        check_probe_readings(args, streams)
        shortest = min(len(v) for v in streams.vectors)
        if args.warmup >= shortest:
            raise SconeError(
                f"--warmup {args.warmup}: leaves no decision to score (the shortest stream has {shortest}); "
                f"give 0..{shortest - 1}"
            )
    if streams is not None and not args.no_replay:
        report.update(_replay(args, streams, estimators, default_estimator, default_target, probe))
    if streams is not None and args.unseen:  # products κ̂ has no outcome of: cold, the fleet, its own store
        from scone_bt.benchmarks.gate_unseen import unseen_report

        report["unseen"] = unseen_report(
            streams,
            replay_stream,
            default_estimator,
            default_target,
            args.seed,
            args.warmup,
            args.opening,
            probe,
            args.excess_allowance,
        )
    if args.episodes:
        report["episodes"] = run_episodes(args)
    report["wall_s"] = round(time.perf_counter() - started, 1)
    # the report first: a figure that cannot be drawn loses no numbers
    emit_report(report, args.json, force=args.force)
    if args.plot is not None:
        _plot(report, args.plot)
    return 0


def replay_args(datasets: str) -> argparse.Namespace:
    """The arguments with which ``scone-bench gate --datasets DATASETS`` replays the shipped gate: its own defaults
    (ζ, seed, warm-up, the gripper's opening) and the tree's strict promise (``excess_allowance``, `_tree_defaults`).
    For tools that replay the shipped gate with one thing changed (tools/cold_starts.py and its kin)."""
    parser = argparse.ArgumentParser()
    register(parser.add_subparsers())
    args = parser.parse_args(["gate", "--datasets", datasets])
    _tree_defaults(args)
    return args


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``gate`` to ``scone-bench``."""
    from scone_bt.confidence.physical import DEFAULT_OPENING_M
    from scone_bt.robot.flags import add_robot_options

    p = sub.add_parser(
        "gate", help="does the gate keep its failure budget on new products, and at what help rate"
    )
    p.add_argument(
        "--datasets",
        type=path_arg,
        help="self-confidence datasets folder (default tools/data/sc_probe, with the heft test's readings, "
        "where the replay probes; tools/data/sc with --no-probe)",
    )
    p.add_argument(
        "--prior",
        type=path_arg,
        default=None,
        metavar="DIR",
        help="datasets κ̂ learns before each same-named stream (the robot's outcomes on another engine)",
    )
    p.add_argument("--embedder", default="minilm", help="ζ (default: %(default)s)")
    p.add_argument(
        "--estimators",
        default="",
        help="comma-separated κ̂ names for the budget and fixed gates (default: the tree's)",
    )
    p.add_argument(
        "--warmup", type=int, default=20, help="decisions per stream not scored (default: %(default)s)"
    )
    p.add_argument(
        "--opening",
        type=float,
        default=DEFAULT_OPENING_M,
        help="gripper opening, metres (default: the Panda's)",
    )
    p.add_argument(
        "--episodes",
        type=int,
        default=0,
        help="seeded episodes per condition, on and control (default: 0, none)",
    )
    p.add_argument("--recipes", type=int, default=20, help="corpus recipes the episodes cycle through")
    p.add_argument("--distractors", type=int, default=4, help="distractor products per episode")
    add_robot_options(p, arm_help="robot file of the episodes (--episodes): a name in robots/ or a YAML path")
    p.add_argument("--no-replay", action="store_true", help="episodes only (skip the dataset replay)")
    p.add_argument(
        "--no-sweep",
        action="store_true",
        help="replay only the tree's default gate, cold (and --prior's cross-engine figures): no method sweep, "
        "no fleet-warm variant",
    )
    p.add_argument(
        "--unseen",
        action="store_true",
        help="also measure what the fleet prior and the robot's own store add on products κ̂ has no outcome of "
        "(leave-products-out; the report's unseen section)",
    )
    p.add_argument(
        "--probe",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="the heft test, in the replay (datasets with probe readings: tools/data/sc_probe by default) and the "
        "episodes (default: the tree's probe.enabled)",
    )
    p.add_argument(
        "--exploration-credit",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="the strict promise: explore only while one more failure keeps F ≤ α·A + 1 (default: the tree's "
        "exploration_credit)",
    )
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--quiet", action="store_true", help="no progress lines on stderr")
    p.add_argument("--json", type=path_arg, help="also write the JSON report to this file")
    p.add_argument("--plot", type=path_arg, help="write the curves as a figure (.png, .svg or .pdf)")
    p.add_argument(
        "--force", action="store_true", help="let --json or --plot replace an existing file of another kind"
    )
    p.set_defaults(func=_run)
