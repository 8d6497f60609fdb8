"""``scone-bench gate --episodes N``: seeded full episodes per condition (self-confidence on, as the tree and the
flags set the robot, and the paper's control), counted from their events (`episode_counts`, `run_episodes`)."""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Sequence
from typing import Any

import numpy as np

__all__ = ["episode_counts", "percentiles_ms", "run_episodes"]


def episode_counts(events: Sequence[Any]) -> dict[str, Any]:
    """What one episode showed the human: failed attempts, help requests, interventions, and infeasible plans
    of an action planned again (a PlanInfeasible, or a failure at planning, after the first for that action)."""
    from scone_bt.events import (
        ActOutcome,
        DecisionMade,
        HelpRequested,
        Intervention,
        PlanInfeasible,
        ProbeAborted,
    )
    from scone_bt.motion.types import FailureStage

    out = {
        "failures": 0,
        "help": 0,
        "interventions": 0,
        "attempts": 0,
        "repeated_infeasible_plans": 0,
        "aborted": 0,
        "probed": 0,
        "act_s": 0.0,
        "aborted_s": 0.0,
    }
    infeasible: set[str] = set()
    planning: list[float] = []
    for e in events:
        if isinstance(e, ActOutcome):
            out["attempts"] += 1
            out["act_s"] += e.duration_s
            out["failures"] += not e.success
            if e.stage == FailureStage.PLANNING:
                out["repeated_infeasible_plans"] += e.action in infeasible
                infeasible.add(e.action)
        elif isinstance(e, PlanInfeasible):
            out["repeated_infeasible_plans"] += e.action in infeasible
            infeasible.add(e.action)
        elif isinstance(e, HelpRequested):
            out["help"] += 1
        elif isinstance(e, Intervention):
            out["interventions"] += 1
        elif isinstance(e, ProbeAborted):
            out["aborted"] += 1
            out["aborted_s"] += e.duration_s
        elif isinstance(e, DecisionMade):
            out["probed"] += e.probe
            if e.planning_s is not None:
                planning.append(e.planning_s)
    return {**out, "planning_s": planning}


def run_episodes(args: argparse.Namespace) -> dict[str, Any]:
    """Seeded episodes over corpus recipes: self-confidence on, the robot as the tree and the flags set it (the
    heft test and the strict promise: on in the shipped tree, off with ``--no-probe``/``--no-exploration-credit``),
    and the paper's control."""
    from scone_bt.behaviours import BehaviourOptions
    from scone_bt.benchmarks.decisions import pick_recipes
    from scone_bt.config import load_kitchen
    from scone_bt.episode import EpisodeOptions, ModelPool, run_episode

    models = ModelPool()
    slots = len(load_kitchen().scene.shelf_slots())
    recipes = pick_recipes(args.recipes, args.seed, slots - args.distractors)
    out: dict[str, Any] = {"episodes": args.episodes, "recipes": len(set(recipes[: args.episodes]))}
    robot = {
        "probe": {"enabled": bool(getattr(args, "probe_on", False))},
        "exploration_credit": getattr(args, "excess_allowance", None) is not None,
    }
    conditions: dict[str, dict[str, Any]] = {
        "self_confidence_on": robot,
        "control": {"use_self_confidence": False, "gate": "paper"},
    }
    for label, extra in conditions.items():
        totals: dict[str, float] = {}
        planning: list[float] = []
        completed = 0
        sim_s = 0.0
        t0 = time.perf_counter()
        for i in range(args.episodes):
            events: list[Any] = []
            seed = args.seed + i
            summary = run_episode(
                EpisodeOptions(
                    arm=args.arm,
                    backend=args.robot,
                    recipe=recipes[i % len(recipes)],
                    seed=seed,
                    distractors=args.distractors,
                    behaviour=BehaviourOptions(seed=seed, **extra),
                ),
                printer=lambda _line: None,
                on_event=events.append,
                models=models,
            )
            counts = episode_counts(events)
            planning += counts.pop("planning_s")
            for k, v in counts.items():
                totals[k] = totals.get(k, 0) + v
            completed += bool(summary.completed)
            sim_s += summary.sim_time
            if not args.quiet:
                print(
                    f"{label} episode {i + 1}/{args.episodes}: {counts} sim_s={summary.sim_time:.2f}",
                    file=sys.stderr,
                )
        n = max(args.episodes, 1)
        out[label] = {
            "failures_per_episode": round(totals.get("failures", 0) / n, 3),
            "help_per_episode": round(totals.get("help", 0) / n, 3),
            "interventions_per_episode": round(totals.get("interventions", 0) / n, 3),
            "aborted_per_episode": round(totals.get("aborted", 0) / n, 3),
            "probed_per_episode": round(totals.get("probed", 0) / n, 3),
            "act_s_per_episode": round(totals.get("act_s", 0) / n, 2),
            "aborted_s_per_episode": round(totals.get("aborted_s", 0) / n, 2),
            "sim_s_per_episode": round(sim_s / n, 2),
            "repeated_infeasible_plans": int(totals.get("repeated_infeasible_plans", 0)),
            "attempts": int(totals.get("attempts", 0)),
            "attempt_success_rate": round(
                1 - totals.get("failures", 0) / max(totals.get("attempts", 0), 1), 4
            ),
            "completed": completed,
            "planning_before_commit_ms": percentiles_ms(planning),
            "wall_s": round(time.perf_counter() - t0, 1),
        }
    return out


def percentiles_ms(seconds: Sequence[float]) -> dict[str, float | int | None]:
    """p50 and p95 of ``seconds`` in milliseconds, and how many (None and 0 for none)."""
    if not seconds:
        return {"p50": None, "p95": None, "n": 0}
    ms = np.asarray(seconds) * 1000.0
    return {
        "p50": round(float(np.percentile(ms, 50)), 2),
        "p95": round(float(np.percentile(ms, 95)), 2),
        "n": len(ms),
    }
