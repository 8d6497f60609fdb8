"""The robot's decision settings: what `scone-run` options, the tree file's ``parameters:`` and scripts set."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

from scone_bt.defaults import EPISODE

if TYPE_CHECKING:
    from scone_bt.config.tree_parameters import GateName, ProbeParameters

__all__ = ["BehaviourOptions"]


PAPER_FAILURE_LIMIT = 3
"""Failures on one action after which the paper's robot asks: the control condition's (`BehaviourOptions.resolve`)."""


@dataclass(frozen=True)
class BehaviourOptions:
    """Settings the behaviours read.

    Attributes:
        embedder: Embedder name or local model path (ζ).
        estimator: κ̂ estimator name.
        confidence_threshold: Act when κ̂ ≥ this, else ask.
        relevance_threshold: Cosine similarity below which no action is relevant (ρ).
        use_self_confidence: False is the paper's control condition: always act.
        recipe_aware: Rank against the recipe the robot knows and track its step from observations; False is
            the paper's setting (the human's current step text alone, ρ on the similarity).
        clarify_margin: Unnamed candidates closer than this in cosine similarity are ambiguous (ASK-CLARIFY).
        max_failures_per_action: After this many failures on one action in an episode, ask (the tree's robot: 1,
            it never repeats a failure; unset in the control condition, the paper's `PAPER_FAILURE_LIMIT`).
        gate: "budget" (the threshold kept online so that at most target_failure_rate of attempts fail;
            scone_bt.gate.budget) or "paper" (the fixed confidence_threshold).
        target_failure_rate: The promise: the share of the robot's attempts that may fail, in (0, 1).
        trust_aware: Track the person's trust online (the model fitted to human ratings) and, before an act the
            person likely over-trusts, say the robot's confidence in words. The gate itself does not change.
        takeover_window_s: Simulated seconds the robot announces an attempt before it moves, when a person can take
            over (a human channel with ``announces_attempts``; the tablet).
        exploration_credit: Explore only while one more failure keeps failures ≤ α × attempts + 1 (the strict
            promise, gate.budget.has_credit); off: the budget's exploration rule alone.
        probe: The heft test's settings (config.tree_parameters.ProbeParameters; the budget gate only). Only the
            fields set on it (``model_fields_set``) override the tree file's ``probe:`` section (`resolve`).
        cache_dir: On-disk embedding cache, or None.
        experience_path: Experience store: an SQLite file, a postgresql:// URL (a fleet's shared store), or None
            for in-memory learning only.
        robot_id: This robot's id in a fleet, recorded with each outcome ("": the arm's name).
        learn_from: Whose stored outcomes rebuild κ̂: "self", "same-model" (same arm and profile) or "fleet".
        profile: Configuration label recorded with each outcome (e.g. a proficiency profile; "" for none).
        seed: Seeds perception noise, the estimators, the planners and the gate's draws, each from its own
            stream (`scone_bt.episode.seeds.SeedPlan`); the world and the human are seeded by
            `EpisodeOptions.seed`: give both to reseed a whole episode.

    The fields of the tree file's ``parameters:`` (embedder, estimator, the thresholds, recipe_aware,
    clarify_margin, max_failures_per_action, gate, target_failure_rate, trust_aware,
    takeover_window_s, exploration_credit, probe) left at None come from the
    tree file (`resolve`): one source. They are `TreeParameters`' fields, each optional, of the same types (a test holds
    them to it); `scone-run` sets them from the options `scone_bt.cli.tree_options` derives from that model.
    """

    embedder: str | None = None
    estimator: str | None = None
    confidence_threshold: float | None = None
    relevance_threshold: float | None = None
    use_self_confidence: bool = True
    recipe_aware: bool | None = None
    clarify_margin: float | None = None
    max_failures_per_action: int | None = None
    gate: GateName | None = None
    target_failure_rate: float | None = None
    trust_aware: bool | None = None
    takeover_window_s: float | None = None
    exploration_credit: bool | None = None
    probe: ProbeParameters | None = None
    cache_dir: Path | None = None
    experience_path: Path | str | None = None
    robot_id: str = ""
    learn_from: str = EPISODE.learn_from
    profile: str = ""
    seed: int = EPISODE.seed

    def resolve(self, parameters: Mapping[str, Any] | None = None) -> BehaviourOptions:
        """A copy whose unset tree parameters come from ``parameters`` (a tree file's validated section), then
        from the `TreeParameters` defaults."""
        from scone_bt.config.tree_parameters import PARAMETER_NAMES, TreeParameters

        base = TreeParameters(**dict(parameters or {}))
        filled = {k: getattr(base, k) for k in PARAMETER_NAMES if getattr(self, k) is None}
        if not self.use_self_confidence and self.max_failures_per_action is None:
            # the paper's control condition is the paper's robot: it asks after 3 failures, whatever the tree's
            # robot does (unless told otherwise: scone-run --max-failures-per-action)
            filled["max_failures_per_action"] = PAPER_FAILURE_LIMIT
        probe = self.probe
        if probe is not None:  # a partial section (a scenario's mapping, scone-run's --probe-*): key by key
            given = probe if isinstance(probe, Mapping) else probe.model_dump(include=probe.model_fields_set)
            filled["probe"] = base.probe.model_validate({**base.probe.model_dump(), **given})
        return replace(self, **filled) if filled else self

    @property
    def resolved(self) -> bool:
        """Whether every tree parameter is set."""
        from scone_bt.config.tree_parameters import PARAMETER_NAMES

        return all(getattr(self, k) is not None for k in PARAMETER_NAMES)
