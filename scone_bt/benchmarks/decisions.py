"""``scone-bench decisions``: are the robot's choices ones a cook would trust? Prints JSON.

Two parts:

1. **Episodes** (relevance and asking): seeded episodes over corpus recipes with the product's defaults. Every
   fetch decision (ACT or ASK-HELP) is judged against the recipe's own stocking (`StockedStep.objects`, the
   simulated human's definition of what a step needs) and the human's current step at that moment (the
   ``step_done`` events before it):
   - wrong fetch: an item that neither the human's current step nor a later one needs (the recipe never uses
     it, or its step is over). ``wrong_fetch_rate`` = wrong fetches / decisions.
   - ``ahead_fetches``: fetches of items that only a later step needs (the robot working ahead: allowed, and
     counted apart).
   - ``never_used_fetches``: fetches of items the recipe does not use (target 0).
   - ``clarify_rate``: ASK-CLARIFY decisions / decisions.
2. **Gate metrics per estimator** (the ask-for-help literature's, KnowNo / IntroPlan): the online robot replayed over
   the self-confidence datasets (`tools/data/sc`, real physical executions with their outcomes, one per profile):
   the first ``--warmup`` executions of each stream are a calibration period (the robot attempts them all and
   learns; they are not scored), then for each execution in order κ̂ predicts, the gate acts (the outcome is
   observed and learnt) or asks (nothing is learnt; the recorded outcome says whether the robot would have
   succeeded). Rates are per decision:
   ``success_rate`` (acted, succeeded), ``help_rate`` (asked), ``over_ask_rate`` (asked, would have succeeded),
   ``over_step_rate`` (acted, failed), and ``attempted_failure_rate`` = P(act | would fail), the quantity a
   conformal gate with a target error rate bounds.

    scone-bench decisions --episodes 50 --recipes 20 --json docs/results/decisions.json
    scone-bench decisions --episodes 0            # the gate metrics only (a minute)
    scone-bench decisions --jobs 1                # everything in this process (the default: one per CPU)

Both parts are spread over ``--jobs`` processes (scone_bt.benchmarks.workers): the replays one (variant,
dataset) stream at a time, the episodes one seeded episode at a time; results are gathered in their serial
order, so the report is the same for any ``--jobs`` (its wall times aside). ``gate.replay_wall_s_by_estimator``
is each variant's replay time, summed over its streams.
"""

from __future__ import annotations

import argparse
import functools
import os
import sys
import time
from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from scone_bt.affordances.types import object_of_action
from scone_bt.argparsing import path_arg
from scone_bt.events import DecisionMade, Event, StepDone
from scone_bt.gate.types import DecisionKind
from scone_bt.reporting import emit_report

if TYPE_CHECKING:  # registration stays cheap: the estimators' package is imported by the replay itself
    from scone_bt.confidence.base import ConfidenceEstimator

__all__ = ["register", "GateCounts", "replay_gate", "judge_fetches", "pick_recipes"]


@dataclass(frozen=True)
class GateCounts:
    """What the online gate did over one stream of executions (counts of decisions)."""

    decisions: int
    acted_success: int
    acted_failure: int
    asked_would_succeed: int
    asked_would_fail: int

    def rates(self) -> dict[str, float]:
        n = max(self.decisions, 1)
        would_fail = self.acted_failure + self.asked_would_fail
        return {
            "success_rate": self.acted_success / n,
            "help_rate": (self.asked_would_succeed + self.asked_would_fail) / n,
            "over_ask_rate": self.asked_would_succeed / n,
            "over_step_rate": self.acted_failure / n,
            "attempted_failure_rate": self.acted_failure / would_fail if would_fail else 0.0,
        }


def replay_gate(
    actions: Sequence[str],
    success: Sequence[bool],
    vectors: dict[str, np.ndarray],
    estimator: str,
    seed: int,
    confidence_threshold: float = 0.5,
    target_error_rate: float | None = None,
    warmup: int = 0,
) -> GateCounts:
    """The online robot over one stream of physical executions; see the module docstring.

    The first ``warmup`` executions are attempted whatever κ̂ says (calibration) and are not counted.
    """
    from scone_bt.confidence import make_estimator
    from scone_bt.gate import GateOptions, decide
    from scone_bt.gate.types import DecisionKind
    from scone_bt.relevance import RankedAction

    est = make_estimator(estimator, seed=seed)
    options = GateOptions(confidence_threshold=confidence_threshold, target_error_rate=target_error_rate)
    counts: Counter[str] = Counter()
    _warm_up(est, [vectors[a] for a in actions[:warmup]], success[:warmup])
    actions, success = actions[warmup:], success[warmup:]
    last = len(actions) - 1
    for i, (action, ok) in enumerate(zip(actions, success, strict=True)):
        x = vectors[action]
        conf = float(est.predict(x[None, :])[0])
        decision = decide([RankedAction(action, 1.0)], [conf], options)
        if decision.kind is DecisionKind.ACT:
            counts["acted_success" if ok else "acted_failure"] += 1
            if i < last:  # the last outcome's refit would never be read: no prediction follows it
                est.update(x, bool(ok))
        else:
            counts["asked_would_succeed" if ok else "asked_would_fail"] += 1
    return GateCounts(
        decisions=len(actions),
        acted_success=counts["acted_success"],
        acted_failure=counts["acted_failure"],
        asked_would_succeed=counts["asked_would_succeed"],
        asked_would_fail=counts["asked_would_fail"],
    )


def _refit_is_stateless(est: ConfidenceEstimator) -> bool:
    """Whether ``est`` (or the estimator an ε-greedy one wraps) refits from its rows and seed alone.

    These build a fresh model seeded by the estimator's seed on every refit, so one ``fit`` on n rows leaves them
    exactly as n ``update`` calls would. Not the GP: when it re-optimises its kernel depends on the sizes it was
    refitted at before (gp.py), so its warm-up must replay outcome by outcome.
    """
    from scone_bt.confidence import conformal, models
    from scone_bt.confidence.epsilon import EpsilonGreedy

    stateless = (
        models.KNNEstimator,
        models.LGBMEstimator,
        models.MLPEstimator,
        models.RandomForestEstimator,
        models.SVMEstimator,
        models.XGBEstimator,
        conformal.ConformalKNNEstimator,
    )
    inner = est.base if isinstance(est, EpsilonGreedy) else est
    return type(inner) in stateless


def _warm_up(est: ConfidenceEstimator, xs: Sequence[np.ndarray], success: Sequence[bool]) -> None:
    """Learn the calibration outcomes: one fit where that is the same as updating one by one (see above).

    Nothing is predicted between warm-up outcomes, so their intermediate refits (up to ``warmup`` - 1 model fits
    per stream, most of the replay's cost for the boosted and bagged trees) are never read.
    """
    if not xs:
        return
    if _refit_is_stateless(est):
        est.fit(np.stack(xs), np.asarray(success, dtype=bool))
        return
    for x, ok in zip(xs, success, strict=True):
        est.update(x, bool(ok))


def judge_fetches(events: Sequence[Event], steps: Sequence[Sequence[str]]) -> dict[str, int]:
    """Count decisions, fetches, wrong, ahead and never-used fetches and clarifications of one episode.

    Args:
        events: The episode's events in order (its decisions and the human's finished steps count).
        steps: Each step's needed objects (the recipe's stocking).
    """
    used = {o for s in steps for o in s}
    out: Counter[str] = Counter()
    human_step = 0
    for event in events:
        if isinstance(event, StepDone):
            human_step += 1
            continue
        if not isinstance(event, DecisionMade):
            continue
        out["decisions"] += 1
        if event.verdict is DecisionKind.CLARIFY:
            out["clarifications"] += 1
            continue
        if event.verdict not in (DecisionKind.ACT, DecisionKind.ASK) or not event.action:
            continue
        item = object_of_action(event.action)
        out["fetches"] += 1
        if item not in used:
            out["never_used"] += 1
            out["wrong"] += 1
        elif not any(item in s for s in steps[human_step:]):
            out["wrong"] += 1
        elif item not in (steps[human_step] if human_step < len(steps) else ()):
            out["ahead"] += 1
    return dict(out)


def pick_recipes(n: int, seed: int, max_needed: int) -> list[str]:
    """``n`` corpus recipe ids, drawn with ``seed`` from those whose stocked items fit ``max_needed``."""
    from scone_bt.config import load_kitchen
    from scone_bt.recipes.recipe import read_corpus
    from scone_bt.stocking import stock_recipe

    catalogue = load_kitchen().catalogue
    fits = []
    for recipe in read_corpus():
        stocked = stock_recipe(recipe, catalogue)
        if 2 <= len(stocked.needed) <= max_needed and any(s.objects for s in stocked.steps):
            fits.append(recipe.id)
    rng = np.random.default_rng(seed)
    return [str(r) for r in rng.choice(sorted(fits), size=min(n, len(fits)), replace=False)]


_MODELS: list[Any] = []
"""This process's ModelPool (one per process: the episodes it runs share one embedder, MiniLM loads once)."""


def _models() -> Any:
    """This process's ModelPool, made on first use."""
    from scone_bt.episode import ModelPool

    if not _MODELS:
        _MODELS.append(ModelPool())
    return _MODELS[0]


@functools.lru_cache(maxsize=1)
def _catalogue() -> Any:
    """The kitchen's catalogue (read once per process)."""
    from scone_bt.config import load_kitchen

    return load_kitchen().catalogue


def _episode(
    recipe_id: str,
    seed: int,
    distractors: int,
    estimator: str,
    relevance_threshold: float | None,
    arm: str = "panda",
    backend: str = "sim",
) -> dict[str, Any]:
    """One seeded episode, judged: its per-episode row plus ``attempted``, ``successes`` and ``help``.

    Everything it depends on is in its arguments (the seed included), so it runs the same in any process.
    """
    from scone_bt.behaviours import BehaviourOptions
    from scone_bt.episode import EpisodeOptions, run_episode
    from scone_bt.recipes import load_recipe
    from scone_bt.stocking import stock_recipe

    events: list[Event] = []
    summary = run_episode(
        EpisodeOptions(
            arm=arm,
            backend=backend,
            recipe=recipe_id,
            seed=seed,
            distractors=distractors,
            behaviour=BehaviourOptions(
                estimator=estimator, relevance_threshold=relevance_threshold, seed=seed
            ),
        ),
        printer=lambda _line: None,
        on_event=events.append,
        models=_models(),
    )
    stocked = stock_recipe(load_recipe(recipe_id), _catalogue())
    counts = judge_fetches(events, [s.objects for s in stocked.steps])
    return {
        "row": {"recipe": recipe_id, "seed": seed, "completed": summary.completed, **counts},
        "attempted": summary.attempted,
        "successes": summary.successes,
        "help": summary.help_requests,
    }


def _episodes(args: argparse.Namespace, pool: Any) -> dict[str, Any]:
    """The seeded episodes (spread over ``pool``'s workers, or here when None), aggregated in episode order."""
    from scone_bt.benchmarks.workers import ordered_map
    from scone_bt.config import load_kitchen, load_robot

    slots = len(load_kitchen().scene.shelf_slots())
    recipes = pick_recipes(args.recipes, args.seed, slots - args.distractors)
    load_robot(args.arm)
    calls = [
        (
            recipes[i % len(recipes)],
            args.seed + i,
            args.distractors,
            args.estimator,
            args.relevance_threshold,
            args.arm,
            args.robot,
        )
        for i in range(args.episodes)
    ]
    totals: Counter[str] = Counter()
    outcomes: Counter[str] = Counter()
    per_recipe = []
    t0 = time.perf_counter()
    for i, result in enumerate(ordered_map(pool, _episode, calls)):
        row = result["row"]
        counts = {k: v for k, v in row.items() if k not in ("recipe", "seed", "completed")}
        totals.update(counts)
        outcomes.update({k: result[k] for k in ("attempted", "successes", "help")})
        per_recipe.append(row)
        if not args.quiet:
            print(f"episode {i + 1}/{args.episodes} {row['recipe']}: {counts}", file=sys.stderr)
    n = max(totals["decisions"], 1)
    return {
        "episodes": args.episodes,
        # What the episodes ran with, so a report says which κ̂ its rates belong to.
        "estimator": args.estimator,
        "distractors": args.distractors,
        "relevance_threshold": args.relevance_threshold,
        "recipes": len(set(recipes[: max(args.episodes, 1)])),
        "decisions": totals["decisions"],
        "fetches": totals["fetches"],
        "wrong_fetch_rate": round(totals["wrong"] / n, 4),
        "ahead_fetches": totals["ahead"],
        "never_used_fetches": totals["never_used"],
        "clarify_rate": round(totals["clarifications"] / n, 4),
        "robot_success_rate": round(outcomes["successes"] / max(outcomes["attempted"], 1), 4),
        "help_requests": outcomes["help"],
        "completed": sum(r["completed"] for r in per_recipe),
        "wall_s": round(time.perf_counter() - t0, 1),
        "per_episode": per_recipe,
    }


def _replay(
    actions: Sequence[str],
    success: Sequence[bool],
    vectors: dict[str, np.ndarray],
    estimator: str,
    seed: int,
    target_error_rate: float | None,
    warmup: int,
) -> tuple[GateCounts, float]:
    """``replay_gate`` over one stream, and the seconds it took (a worker's unit of gate work)."""
    t0 = time.perf_counter()
    counts = replay_gate(
        actions, success, vectors, estimator, seed, target_error_rate=target_error_rate, warmup=warmup
    )
    return counts, time.perf_counter() - t0


def _gate_metrics(args: argparse.Namespace, pool: Any) -> dict[str, Any]:
    """Gate metrics per estimator variant; its (variant, dataset) replays spread over ``pool`` (None: here)."""
    from scone_bt.benchmarks.self_confidence.dataset import load_datasets
    from scone_bt.benchmarks.workers import ordered_map
    from scone_bt.confidence import BASE_ESTIMATORS
    from scone_bt.embedding import load_embedder
    from scone_bt.resources import repo_root

    folder = Path(args.datasets) if args.datasets else (repo_root() or Path(".")) / "tools" / "data" / "sc"
    datasets = load_datasets(folder)
    emb = load_embedder(args.embedder)
    actions = sorted({a for d in datasets for a in d.actions})
    vectors = dict(zip(actions, emb.embed(actions), strict=True))
    names = [e for e in args.estimators.split(",") if e] or [
        *BASE_ESTIMATORS,
        *(f"eps-{b}" for b in BASE_ESTIMATORS),
    ]
    variants = [(name, None) for name in names] + [("conformal", t) for t in args.target_error_rates]
    # A worker gets only its stream's vectors (each call is pickled on its own).
    streams = [(d.actions, d.success, {a: vectors[a] for a in set(d.actions)}) for d in datasets]
    calls = [
        (*stream, name, args.seed + j, target, args.warmup)
        for name, target in variants
        for j, stream in enumerate(streams)
    ]
    results = ordered_map(pool, _replay, calls)
    out: dict[str, Any] = {}
    seconds: dict[str, float] = {}
    for name, target in variants:
        label = name if target is None else f"conformal@{target:g}"
        pairs = [next(results) for _ in datasets]
        per = [counts for counts, _ in pairs]
        seconds[label] = round(sum(s for _, s in pairs), 1)  # its replays' own time, summed over workers
        total = GateCounts(*(sum(getattr(c, f) for c in per) for f in GateCounts.__dataclass_fields__))
        out[label] = {k: round(v, 4) for k, v in total.rates().items()} | {"decisions": total.decisions}
        if target is not None:
            out[label]["target_error_rate"] = target
            out[label]["meets_target"] = total.rates()["attempted_failure_rate"] <= target
    return {
        "embedder": args.embedder,
        "warmup": args.warmup,
        "datasets": [d.name for d in datasets],
        "estimators": out,
        "replay_wall_s_by_estimator": seconds,
    }


def _run(args: argparse.Namespace) -> int:
    from scone_bt.benchmarks.workers import process_pool
    from scone_bt.checks import check_at_least
    from scone_bt.errors import SconeError

    for flag, value, low in (
        ("--episodes", args.episodes, 0),
        ("--recipes", args.recipes, 1),
        ("--jobs", args.jobs, 1),
    ):
        check_at_least(value, flag, low)
    for target in args.target_error_rates:  # the gate's own range (GateOptions), checked before any replay
        if not 0.0 < target < 1.0:
            raise SconeError(f"--target-error-rates {target}: must be a number in (0, 1)")
    _check_modes(args)
    _check_names_and_threshold(args)
    started = time.perf_counter()
    report: dict[str, Any] = {
        "benchmark": "decisions",
        "seed": args.seed,
        "machine": {"cpus": os.cpu_count(), "load_average_1min": round(os.getloadavg()[0], 2)},
    }
    # One pool for both parts: its workers start once (each loads the embedder once, for all its episodes).
    with process_pool(args.jobs) as pool:
        if not args.no_gate:
            report["gate"] = _gate_metrics(args, pool)
            report["per_estimator"] = report["gate"]["estimators"]
        if args.episodes:
            ep = _episodes(args, pool)
            report.update({k: ep[k] for k in ("wrong_fetch_rate", "never_used_fetches", "clarify_rate")})
            report["episodes"] = ep
    report["jobs"] = args.jobs
    report["wall_s"] = round(time.perf_counter() - started, 1)
    emit_report(report, args.json, force=args.force)
    return 0


_GATE_ONLY = {
    "embedder": "--embedder",
    "estimators": "--estimators",
    "target_error_rates": "--target-error-rates",
    "datasets": "--datasets",
    "warmup": "--warmup",
}
"""Options only the gate replay reads."""
_EPISODES_ONLY = {
    "recipes": "--recipes",
    "distractors": "--distractors",
    "estimator": "--estimator",
    "relevance_threshold": "--relevance-threshold",
    "robot": "--robot",
    "arm": "--arm",
}
"""Options only the episodes read."""


def _check_modes(args: argparse.Namespace) -> None:
    """Something to run, and no option given that neither part reads (one meaning per flag)."""
    from scone_bt.argparsing import refuse_unread, subcommand_defaults
    from scone_bt.errors import SconeError

    if args.no_gate and args.episodes == 0:
        raise SconeError(
            "--no-gate with --episodes 0: nothing to run; give episodes, or leave the gate replay on"
        )
    defaults = subcommand_defaults(register, "decisions")
    if args.no_gate:
        refuse_unread(args, defaults, _GATE_ONLY, "only the gate replay reads it, and --no-gate skips it")
    if args.episodes == 0:
        refuse_unread(args, defaults, _EPISODES_ONLY, "only the episodes read it, and --episodes 0 runs none")


def _check_names_and_threshold(args: argparse.Namespace) -> None:
    """--estimator, --estimators and --relevance-threshold, before the replay (they failed after it, ~20 s in)."""
    from scone_bt.checks import check_range
    from scone_bt.cli.run import _check_estimator  # the one check of registry names (scone-run's, gate's)

    _check_estimator(args.estimator)
    for name in (n for n in args.estimators.split(",") if n):
        _check_estimator(name, "--estimators")
    if args.relevance_threshold is not None:  # ρ is a cosine similarity
        check_range(args.relevance_threshold, "--relevance-threshold", -1.0, 1.0)


def _default_jobs() -> int:
    """One process per CPU, at least 1 (cheap: registration calls it)."""
    return max(os.cpu_count() or 1, 1)


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``decisions`` to ``scone-bench`` (its failure-budget replay, ``gate``, is scone_bt.benchmarks.gate)."""
    p = sub.add_parser(
        "decisions", help="wrong fetches, clarifications and gate metrics per estimator (JSON)"
    )
    p.add_argument("--episodes", type=int, default=50, help="seeded episodes (0: the gate metrics only)")
    p.add_argument("--recipes", type=int, default=20, help="corpus recipes the episodes cycle through")
    p.add_argument("--distractors", type=int, default=4, help="distractor products per episode")
    p.add_argument("--estimator", default="eps-knn", help="κ̂ in the episodes")
    from scone_bt.robot.flags import add_robot_options

    add_robot_options(p, arm_help="robot file of the episodes: a name in robots/ or a YAML path")
    p.add_argument(
        "--relevance-threshold", type=float, help="ρ of the semantic fallback (default: the tree file's)"
    )
    p.add_argument("--embedder", default="minilm", help="ζ of the gate replay")
    p.add_argument("--estimators", default="", help="comma-separated (default: all, with ε-greedy variants)")
    p.add_argument(
        "--target-error-rates",
        type=float,
        nargs="*",
        default=[0.1, 0.2],
        help="conformal gate targets to check",
    )
    p.add_argument(
        "--datasets", type=path_arg, help="self-confidence datasets folder (default tools/data/sc)"
    )
    p.add_argument("--warmup", type=int, default=20, help="calibration executions per stream, not scored")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--json", type=path_arg, help="also write the JSON report to this file")
    p.add_argument("--no-gate", action="store_true", help="skip the gate replay (episodes only)")
    p.add_argument("--quiet", action="store_true", help="no progress lines on stderr")
    p.add_argument(
        "--jobs",
        type=int,
        default=_default_jobs(),
        help="processes sharing the replays and the episodes (default: one per CPU; 1: all in this process; "
        "the report is the same)",
    )
    p.set_defaults(func=_run)
