"""What the behaviours share: the world, the human, the configs, and lazily built heavy components.

Behaviours receive a `Services` in their (cheap) constructor and build the heavy parts they need in `setup()`
through the cached factories below, so that the embedder, κ̂ and the motion system exist once per episode.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from scone_bt.affordances.types import object_of_action
from scone_bt.config import KitchenConfig, RobotConfig
from scone_bt.gate.types import Decision, DecisionKind
from scone_bt.recipes import StockedRecipe
from scone_bt.world import Kitchen

if TYPE_CHECKING:
    from scone_bt.confidence import ConfidenceEstimator
    from scone_bt.embedding import Embedder
    from scone_bt.experience import OutcomeStore
    from scone_bt.motion import MotionSystem

__all__ = ["EpisodeStats", "BehaviourOptions", "Services"]


@dataclass
class EpisodeStats:
    """Counters of one episode (mutable, updated by the behaviours)."""

    decisions: int = 0
    attempted: int = 0
    successes: int = 0
    failures: int = 0
    help_requests: int = 0
    clarifications: int = 0
    cancelled: int = 0
    failures_by_stage: dict[str, int] = field(default_factory=dict)
    failures_by_action: dict[str, int] = field(default_factory=dict)
    decision_log: list[str] = field(default_factory=list)


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
        max_failures_per_action: After this many failures on one action in an episode, ask (the paper used 3).
        cache_dir: On-disk embedding cache, or None.
        experience_path: Experience store: an SQLite file, a postgresql:// URL (a fleet's shared store), or None
            for in-memory learning only.
        robot_id: This robot's id in a fleet, recorded with each outcome ("": the arm's name).
        learn_from: Whose stored outcomes rebuild κ̂: "self", "same-model" (same arm and profile) or "fleet".
        profile: Configuration label recorded with each outcome (e.g. a proficiency profile; "" for none).
        seed: Seeds perception noise, the estimators and the planners.

    The fields of the tree file's ``parameters:`` (embedder, estimator, the thresholds, recipe_aware,
    clarify_margin, max_failures_per_action) left at None come from the tree file (`resolve`): one source.
    """

    embedder: str | None = None
    estimator: str | None = None
    confidence_threshold: float | None = None
    relevance_threshold: float | None = None
    use_self_confidence: bool = True
    recipe_aware: bool | None = None
    clarify_margin: float | None = None
    max_failures_per_action: int | None = None
    cache_dir: Path | None = None
    experience_path: Path | str | None = None
    robot_id: str = ""
    learn_from: str = "self"
    profile: str = ""
    seed: int = 0

    def resolve(self, parameters: Mapping[str, Any] | None = None) -> BehaviourOptions:
        """A copy whose unset tree parameters come from ``parameters`` (a tree file's validated section), then
        from the `TreeParameters` defaults."""
        from scone_bt.tree.parameters import PARAMETER_NAMES, TreeParameters

        base = TreeParameters(**dict(parameters or {}))
        filled = {k: getattr(base, k) for k in PARAMETER_NAMES if getattr(self, k) is None}
        return replace(self, **filled) if filled else self

    @property
    def resolved(self) -> bool:
        """Whether every tree parameter is set."""
        from scone_bt.tree.parameters import PARAMETER_NAMES

        return all(getattr(self, k) is not None for k in PARAMETER_NAMES)


@dataclass
class Services:
    kitchen: Kitchen
    kitchen_config: KitchenConfig
    robot_config: RobotConfig
    recipe: StockedRecipe
    human: Any  # SimulatedHuman or a UI-driven human with the same interface
    options: BehaviourOptions
    printer: Callable[[str], None] = print
    on_event: Callable[[str, dict[str, Any]], None] | None = None
    stats: EpisodeStats = field(default_factory=EpisodeStats)
    context: dict[str, Any] = field(default_factory=dict)
    _cache: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self._last_line: str | None = None
        self._repeats = 0
        if not self.options.resolved:  # built without a tree file (tests, scripts): the defaults' one source
            self.options = self.options.resolve()
        self.rng = np.random.default_rng(self.options.seed)

    def _once(self, key: str, build: Callable[[], Any]) -> Any:
        if key not in self._cache:
            self._cache[key] = build()
        return self._cache[key]

    def embedder(self) -> Embedder:
        from scone_bt.embedding import load_embedder

        return self._once(
            "embedder", lambda: load_embedder(self.options.embedder, cache_dir=self.options.cache_dir)
        )

    @property
    def robot_id(self) -> str:
        """This robot's id in the experience store (the arm's name unless one was given)."""
        return self.options.robot_id or self.robot_config.name

    def store(self) -> OutcomeStore | None:
        if self.options.experience_path is None:
            return None
        from scone_bt.experience import open_store

        def build() -> OutcomeStore:
            store = open_store(self.options.experience_path)
            if getattr(store, "notice", None):
                self.printer(store.notice)
            return store

        return self._once("store", build)

    def estimator(self) -> ConfidenceEstimator:
        """κ̂, rebuilt from this robot's stored outcomes on first use."""
        return self._once("estimator", self._build_estimator)

    def _build_estimator(self) -> ConfidenceEstimator:
        from scone_bt.confidence import make_estimator, rebuild_estimator

        est = make_estimator(self.options.estimator, seed=self.options.seed)
        store = self.store()
        if store is not None:
            from scone_bt.experience import LearnFrom

            learn_from = LearnFrom.parse(self.options.learn_from)
            who = (self.robot_id, self.robot_config.name, self.options.profile)
            n = rebuild_estimator(est, store, self.embedder(), **learn_from.filters(*who))
            if n:
                self.printer(f"κ̂ rebuilt from {n} stored outcomes {learn_from.describe(*who)}")
        return est

    def motion(self) -> MotionSystem:
        from scone_bt.motion import MotionSystem

        return self._once("motion", lambda: MotionSystem.build(self.kitchen, self.robot_config))

    def emit(self, event: str, **data: Any) -> None:
        """Send an event (decision, act, outcome, help_request, intervention) to the episode's listener."""
        if self.on_event is not None:
            self.on_event(event, {"sim_time": round(self.kitchen.sim_time, 3), **data})

    def report_decision(self, instruction: str, decision: Decision, step_index: int | None = None) -> None:
        """Print and emit one decision; ``step_index`` is the robot's own place in the recipe (0-based; None:
        the human's current step, the recipe-blind setting)."""
        total = len(self.recipe.steps)
        step = min(total, (self.human.step_index if step_index is None else step_index) + 1)
        if not instruction:
            instruction = "(every step is served)"
        short = instruction if len(instruction) <= 48 else instruction[:45] + "..."
        if decision.kind is DecisionKind.CLARIFY:
            target = "which: " + " | ".join(object_of_action(c) for c in decision.candidates) + "?"
        elif decision.kind is DecisionKind.IDLE and decision.reason.startswith("waiting: "):
            target = "(" + decision.reason + ")"
        else:
            target = decision.action or "(none)"
        note = "  (needed later)" if decision.need == "later" and decision.action else ""
        line = (
            f"[step {step}/{total}] {short!r:52} -> {target:28} "
            f"rel {decision.relevance:5.2f}  conf {decision.confidence:4.2f}  {decision.kind.label}{note}"
        )
        self.emit(
            "decision",
            step=step,
            instruction=instruction,
            action=decision.action,
            relevance=round(decision.relevance, 4),
            confidence=round(decision.confidence, 4),
            kind=decision.kind.value,
            need=decision.need,
            candidates=list(decision.candidates),
        )
        self.stats.decisions += 1
        self.stats.decision_log.append(line)
        # A run of identical idle decisions is printed once, then counted (the log and the events keep all).
        if decision.kind is DecisionKind.IDLE and line == self._last_line:
            self._repeats += 1
            return
        self.flush_repeats()
        self._last_line = line
        self.printer(line)

    def flush_repeats(self) -> None:
        """Print the count of repeated idle decisions not yet printed (at a change, and at the episode's end)."""
        if self._repeats:
            self.printer(f"    … the same {self._repeats} more time{'s' if self._repeats > 1 else ''}")
        self._repeats = 0
