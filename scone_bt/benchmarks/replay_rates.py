"""The replay's pooled rates (`pooled_rates`) and the least help any gate could reach (`help_floor`)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from scone_bt.benchmarks.replay import HelpTally, StreamResult

__all__ = ["help_by_cause", "help_floor", "pooled_rates", "stream_successes"]


def stream_successes(r: StreamResult) -> int:
    """Scored decisions of one stream that would have succeeded, whatever the gate did with them."""
    return r.attempts - r.failures + r.asked_ok + r.aborted_would_succeed


def pooled_rates(results: Sequence[StreamResult]) -> dict[str, Any]:
    """One method's rates pooled over the streams' scored decisions (the report's keys: benchmarks.gate's module
    docstring), each stream's realised rate, help and clairvoyant floor, and the same over every decision."""
    tot = {
        k: sum(getattr(r, k) for r in results)
        for k in StreamResult.__dataclass_fields__
        if k not in ("thresholds", "trace", "max_excess", "probe_s", "help_causes")
    }
    probe_s = sum(r.probe_s for r in results)
    held = [r.max_excess for r in results if r.confident_failures == 0]
    n = max(tot["decisions"], 1)
    att = tot["attempts"]
    seen_att = att - tot["novel_attempts"]
    seen_fail = tot["failures"] - tot["novel_failures"]

    def ratio(a: int, b: int) -> float | None:
        return round(a / b, 4) if b else None

    successes = sum(stream_successes(r) for r in results)
    return {
        "decisions": tot["decisions"],
        "attempts": att,
        "success_rate": round((att - tot["failures"]) / n, 4),
        # an aborted probe is an ask for the person: counted in the help rate (and apart, aborted_rate)
        "help_rate": round((tot["asked_ok"] + tot["asked_fail"] + tot["aborted"]) / n, 4),
        "aborted_rate": round(tot["aborted"] / n, 4),
        "help_rate_floor": help_floor(successes, tot["decisions"], ratio(tot["failures"], att)),
        # a clairvoyant that never fails: it attempts exactly what would succeed (help below it needs failures)
        "help_rate_floor_without_failures": help_floor(successes, tot["decisions"], 0.0),
        "probes": tot["probes"],
        "probe_s_mean": round(probe_s / tot["probes_felt"], 3) if tot["probes_felt"] else None,
        "help_by_cause": help_by_cause(results),
        "aborted_would_have_succeeded": tot["aborted_would_succeed"],
        "aborted_would_have_failed": tot["probe_caught"],
        "over_ask_rate": round(tot["asked_ok"] / n, 4),
        "over_step_rate": round(tot["failures"] / n, 4),
        "attempt_failure_rate": ratio(tot["failures"], att),
        "attempt_success_rate": ratio(att - tot["failures"], att),
        "attempt_failure_rate_novel": ratio(tot["novel_failures"], tot["novel_attempts"]),
        "attempt_failure_rate_seen": ratio(seen_fail, seen_att),
        "novel_attempts": tot["novel_attempts"],
        "seen_attempts": seen_att,
        "exploration_attempts": tot["explored"],
        "wide_attempts_after_first_wide_failure": tot["wide_after_failure"],
        "wide_attempts_after_first_wide_failure_max_per_stream": max(r.wide_after_failure for r in results),
        "attempt_failure_rate_per_stream": [ratio(r.failures, r.attempts) for r in results],
        "help_rate_per_stream": [ratio(r.asked_ok + r.asked_fail + r.aborted, r.decisions) for r in results],
        # each stream's clairvoyant at that stream's own realised rate: where the help goes beyond what any gate needs
        "help_rate_floor_per_stream": [
            help_floor(stream_successes(r), r.decisions, ratio(r.failures, r.attempts)) for r in results
        ],
        "by_feel_attempts": tot["by_feel"],
        "by_feel_failures": tot["by_feel_failures"],
        "probe_failures_before_feeling": tot["unfelt_probe_failures"],
        "max_excess_failures": round(max(r.max_excess for r in results), 4),
        # the promise's condition: streams where every failed attempt had κ̂ < τ at its final decision
        "max_excess_failures_where_confident_held": round(max(held), 4) if held else None,
        "streams_where_confident_held": len(held),
        "all_decisions": {
            "attempt_failure_rate": ratio(tot["all_failures"], tot["all_attempts"]),
            "help_rate": round(tot["all_asked"] / max(tot["all_decisions"], 1), 4),
        },
    }


def help_by_cause(results: Sequence[StreamResult]) -> dict[str, dict[str, float | int]]:
    """The scored decisions the person fetched for, pooled over the streams by cause, most first: the rule that
    asked ("too-wide", "missing", "infeasible", …), "unsure" for κ̂'s own ask, or why a heft test set the product
    back ("set-back-felt": the fingers felt it slip or strain; "set-back-unsure": κ̂'s doubt after a probe that
    held, with no credit to carry on; "set-back-missed": the fingers closed on nothing; `replay.SET_BACK_CAUSES`).
    For each: how many, their share of the decisions (the counts add up to the asks ``help_rate`` counts, the
    rounded rates to within 0.001), how many would have succeeded had the robot carried them (what a better
    judgement could still take off), and how many were of a product perceived wider than the gripper opens (what no
    judgement can)."""
    pooled: dict[str, HelpTally] = {}
    for r in results:
        for cause, tally in r.help_causes.items():
            pooled.setdefault(cause, HelpTally()).add(tally)
    n = max(sum(r.decisions for r in results), 1)
    return {
        cause: {
            "decisions": c.decisions,
            "rate": round(c.decisions / n, 4),
            "would_have_succeeded": c.would_have_succeeded,
            "wider_than_gripper": c.wider_than_gripper,
        }
        for cause, c in sorted(pooled.items(), key=lambda kv: (-kv[1].decisions, kv[0]))
    }


def help_floor(successes: int, decisions: int, failure_rate: float | None) -> float | None:
    """The least help rate any gate could reach on these decisions at this attempt failure rate: a clairvoyant
    attempts every decision that would succeed and as many that would fail as the rate allows, A = S / (1 − f),
    and asks for the rest. None without decisions or attempts."""
    if not decisions or failure_rate is None or failure_rate >= 1.0:
        return None
    return round(1.0 - min(decisions, successes / (1.0 - failure_rate)) / decisions, 4)
