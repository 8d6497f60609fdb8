"""The promise across bodies: how one robot's outcomes change when it moves to another engine, and how long its
failure budget takes to be kept again (``scone-bench gate --prior DIR``).

Execution *i* of a profile is the same task on every engine (the generator seeds the products, their slots, the
camera noise and the planner from the profile and *i* alone), so two dataset folders made by ``scone-bench sc
generate --robot sim`` and ``--robot mujoco`` pair row by row: the same product, on the same shelf, with the same
neighbours. `engine_gap` compares them; `recovery_decisions` reads a replayed stream's decisions.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from scone_bt.errors import ConfigError

__all__ = [
    "CROSS_ENGINE_TARGETS",
    "TOLERANCE",
    "EngineGap",
    "OutcomeFlip",
    "engine_gap",
    "realised_rates",
    "recovery_decisions",
]

CROSS_ENGINE_TARGETS: tuple[float, ...] = (0.10, 0.15, 0.20)
"""Target failure rates α at which the promise is checked after the move."""
TOLERANCE = 0.02
"""The promise holds when the realised attempt failure rate is at most α + this."""


@dataclass(frozen=True)
class OutcomeFlip:
    """One execution whose outcome differs between the engines.

    Attributes:
        index: Execution number within the profile (the same task on both engines).
        object: The target product.
        before: "success", or the failure stage, on the prior engine.
        after: The same on this engine.
    """

    index: int
    object: str
    before: str
    after: str


@dataclass(frozen=True)
class EngineGap:
    """One profile on two engines, execution by execution.

    Attributes:
        profile: Dataset name.
        matched: Executions present in both folders with the same target.
        success_rate_prior: Success rate of the matched executions on the prior engine.
        success_rate: Success rate of the matched executions on this engine.
        to_failure: Succeeded before, fail now.
        to_success: Failed before, succeed now.
        flips: Every execution whose outcome (success or failure) differs.
        stage_changes: Failed on both engines, at different stages.
    """

    profile: str
    matched: int
    success_rate_prior: float | None
    success_rate: float | None
    to_failure: int
    to_success: int
    flips: tuple[OutcomeFlip, ...]
    stage_changes: int


def _outcome(success: bool, stage: str | None) -> str:
    return "success" if success else (stage or "failure")


def engine_gap(prior_dir: Path, datasets_dir: Path, names: Sequence[str]) -> dict[str, EngineGap]:
    """Each named profile's executions paired by index between two generator folders.

    Raises:
        ConfigError: A profile has no generator CSV in one of the folders (names the file), or the two files
            give an execution different targets (they were not generated with the same seeds and products).
    """
    from scone_bt.benchmarks.self_confidence.dataset import read_records

    out: dict[str, EngineGap] = {}
    for name in names:
        files = (Path(prior_dir) / f"{name}.csv", Path(datasets_dir) / f"{name}.csv")
        for f in files:
            if not f.is_file():
                raise ConfigError(f"{f}: no such dataset; --prior and --datasets must hold the same profiles")
        before = {r.index: r for r in read_records(files[0])}
        after = {r.index: r for r in read_records(files[1])}
        common = sorted(set(before) & set(after))
        for i in common:
            if before[i].object != after[i].object:
                raise ConfigError(
                    f"{files[1]}: execution {i} is {after[i].object!r}, {files[0]} has {before[i].object!r}; "
                    "compare folders generated with the same seeds, products and catalogues"
                )
        flips = tuple(
            OutcomeFlip(
                i,
                after[i].object,
                _outcome(before[i].success, before[i].failure_stage),
                _outcome(after[i].success, after[i].failure_stage),
            )
            for i in common
            if before[i].success != after[i].success
        )
        n = len(common)
        out[name] = EngineGap(
            profile=name,
            matched=n,
            success_rate_prior=round(sum(before[i].success for i in common) / n, 4) if n else None,
            success_rate=round(sum(after[i].success for i in common) / n, 4) if n else None,
            to_failure=sum(f.after != "success" for f in flips),
            to_success=sum(f.after == "success" for f in flips),
            flips=flips,
            stage_changes=sum(
                not before[i].success
                and not after[i].success
                and before[i].failure_stage != after[i].failure_stage
                for i in common
            ),
        )
    return out


def realised_rates(trace: Sequence[int]) -> list[float | None]:
    """The budget's realised attempt failure rate after each decision, counted from the first decision on this
    engine (None before the first attempt).

    Args:
        trace: One entry per decision: 1 acted and succeeded, 0 acted and failed, -1 asked for help.
    """
    attempts = failures = 0
    rates: list[float | None] = []
    for d in trace:
        if d >= 0:
            attempts += 1
            failures += d == 0
        rates.append(failures / attempts if attempts else None)
    return rates


def recovery_decisions(trace: Sequence[int], alpha: float, tolerance: float = TOLERANCE) -> int | None:
    """Decisions on this engine before the realised rate is within α + tolerance and stays there to the end.

    0 when it never left (or no attempt was made); None when the stream ends above it.
    """
    rates = realised_rates(trace)
    limit = alpha + tolerance + 1e-12
    last_above = max((t for t, r in enumerate(rates) if r is not None and r > limit), default=-1)
    if last_above == len(rates) - 1:
        return None
    return last_above + 1
