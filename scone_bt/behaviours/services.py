"""What the behaviours share: the world, the human, the configs, and lazily built heavy components.

Behaviours receive a `Services` in their (cheap) constructor and build the heavy parts they need in `setup()`
through the cached factories below, so that the embedder, κ̂ and the motion system exist once per episode.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from scone_bt.config import KitchenConfig, RobotConfig
from scone_bt.gate.types import Decision
from scone_bt.recipes import StockedRecipe
from scone_bt.world import Kitchen

if TYPE_CHECKING:
    from scone_bt.confidence import ConfidenceEstimator
    from scone_bt.embedding import Embedder
    from scone_bt.experience import ExperienceStore
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
        max_failures_per_action: After this many failures on one action in an episode, ask (the paper used 3).
        cache_dir: On-disk embedding cache, or None.
        experience_path: SQLite experience store, or None for in-memory learning only.
        seed: Seeds perception noise, the estimators and the planners.
    """

    embedder: str = "minilm"
    estimator: str = "eps-knn"
    confidence_threshold: float = 0.5
    relevance_threshold: float = 0.25
    use_self_confidence: bool = True
    max_failures_per_action: int = 3
    cache_dir: Path | None = None
    experience_path: Path | None = None
    seed: int = 0


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

    def store(self) -> ExperienceStore | None:
        if self.options.experience_path is None:
            return None
        from scone_bt.experience import ExperienceStore

        return self._once("store", lambda: ExperienceStore(self.options.experience_path))

    def estimator(self) -> ConfidenceEstimator:
        """κ̂, rebuilt from this robot's stored outcomes on first use."""
        return self._once("estimator", self._build_estimator)

    def _build_estimator(self) -> ConfidenceEstimator:
        from scone_bt.confidence import make_estimator, rebuild_estimator

        est = make_estimator(self.options.estimator, seed=self.options.seed)
        store = self.store()
        if store is not None:
            robot = self.context.get("robot")
            n = rebuild_estimator(
                est, store, self.embedder(), where=lambda o: o.context.get("robot") == robot
            )
            if n:
                self.printer(f"κ̂ rebuilt from {n} stored outcomes of robot {robot!r}")
        return est

    def motion(self) -> MotionSystem:
        from scone_bt.motion import MotionSystem

        return self._once("motion", lambda: MotionSystem.build(self.kitchen, self.robot_config))

    def emit(self, event: str, **data: Any) -> None:
        """Send an event (decision, act, outcome, help_request, intervention) to the episode's listener."""
        if self.on_event is not None:
            self.on_event(event, {"sim_time": round(self.kitchen.sim_time, 3), **data})

    def report_decision(self, instruction: str, decision: Decision) -> None:
        step = self.human.step_index + 1
        total = len(self.recipe.steps)
        short = instruction if len(instruction) <= 48 else instruction[:45] + "..."
        line = (
            f"[step {step}/{total}] {short!r:52} -> {decision.action or '(none)':28} "
            f"rel {decision.relevance:5.2f}  conf {decision.confidence:4.2f}  {decision.kind.value.upper()}"
        )
        self.emit(
            "decision",
            step=step,
            instruction=instruction,
            action=decision.action,
            relevance=round(decision.relevance, 4),
            confidence=round(decision.confidence, 4),
            kind=decision.kind.value,
        )
        self.stats.decisions += 1
        self.stats.decision_log.append(line)
        self.printer(line)
