"""The long-lived parts of an episode, owned by one object that closes them.

`EpisodeResources` owns the robot (for the simulation: the kitchen and the motion worker thread), the experience
store and κ̂; `run_episode` uses it as a context manager, so they are released however the episode ends. The
embedder (the model and its cache) comes from a `ModelPool`, which outlives episodes: `scone-study simulate` runs
many episodes in one process and loads MiniLM once.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

from scone_bt.behaviours.options import BehaviourOptions
from scone_bt.robot.interface import Robot
from scone_bt.robot.registry import DEFAULT_BACKEND

if TYPE_CHECKING:
    from scone_bt.confidence import ConfidenceEstimator
    from scone_bt.embedding import Embedder
    from scone_bt.experience import OutcomeStore

__all__ = ["ModelPool", "EpisodeResources"]


class ModelPool:
    """Embedders by (name, cache folder), loaded once and shared by every episode that uses the pool."""

    def __init__(self) -> None:
        self._embedders: dict[tuple[str, Path | None], Embedder] = {}
        self.loads = 0

    def embedder(self, name: str, cache_dir: Path | None = None) -> Embedder:
        key = (name, cache_dir)
        if key not in self._embedders:
            from scone_bt.embedding import load_embedder

            self._embedders[key] = load_embedder(name, cache_dir=cache_dir)
            self.loads += 1
        return self._embedders[key]

    def embedders(self) -> tuple[Embedder, ...]:
        """The embedders loaded so far."""
        return tuple(self._embedders.values())

    def close(self) -> None:
        """Close the embeddings' on-disk caches."""
        for embedder in self._embedders.values():
            cache = getattr(embedder, "cache", None)
            if cache is not None and hasattr(cache, "close"):
                cache.close()
        self._embedders.clear()

    def __enter__(self) -> ModelPool:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class EpisodeResources:
    """The robot, the experience store and κ̂ of one episode (each built on first use), closed together.

    Args:
        robot: The robot backend (owned: closed with the resources).
        options: The resolved decision settings.
        robot_id: This robot's id in the store.
        arm: The arm model's name.
        printer: Receives notices (a store's warning, how many outcomes rebuilt κ̂).
        models: Where the embedder comes from (None: a pool of this episode's own).
        estimator_seed: Seeds κ̂ (None: the options' seed).
        gripper_opening_m: The arm's gripper opening, metres (the physical κ̂ measures widths against it;
            None: its default, the Panda's).
        backend: The robot backend's name (`scone_bt.robot.registry.BACKENDS`): "self" and "same-model" learn
            only from outcomes observed on it (`experience.learn_from`).
    """

    def __init__(
        self,
        robot: Robot,
        options: BehaviourOptions,
        robot_id: str,
        arm: str,
        printer: Callable[[str], None] = print,
        models: ModelPool | None = None,
        estimator_seed: int | None = None,
        gripper_opening_m: float | None = None,
        backend: str = DEFAULT_BACKEND,
    ) -> None:
        self.robot = robot
        self.backend = backend
        self.gripper_opening_m = gripper_opening_m
        self.estimator_seed = options.seed if estimator_seed is None else estimator_seed
        self.options = options
        self.robot_id = robot_id
        self.arm = arm
        self.printer = printer
        self._own_models = models is None
        self.models = models or ModelPool()
        self._embedder: Embedder | None = None
        self._store: OutcomeStore | None = None
        self._store_opened = False
        self._estimator: ConfidenceEstimator | None = None

    def embedder(self) -> Embedder:
        """ζ (from the model pool)."""
        if self._embedder is None:
            self._embedder = self.models.embedder(str(self.options.embedder), self.options.cache_dir)
        return self._embedder

    def store(self) -> OutcomeStore | None:
        """The experience store, or None for in-memory learning only."""
        if not self._store_opened:
            self._store_opened = True
            if self.options.experience_path is not None:
                from scone_bt.experience import open_store

                self._store = open_store(self.options.experience_path)
                if self._store.notice:
                    self.printer(self._store.notice)
        return self._store

    def estimator(self) -> ConfidenceEstimator:
        """κ̂, rebuilt from this robot's stored outcomes on first use."""
        if self._estimator is None:
            from scone_bt.confidence import make_estimator

            opts = self.options
            # a hardware-relative κ̂ measures widths against this arm's own gripper
            hardware = (
                {"gripper_opening_m": self.gripper_opening_m}
                if opts.estimator == "physical" and self.gripper_opening_m is not None
                else {}
            )
            est = make_estimator(str(opts.estimator), seed=self.estimator_seed, **hardware)
            store = self.store()
            if store is not None:
                self._rebuild(est, store)
            self._estimator = est
        return self._estimator

    def _rebuild(self, est: ConfidenceEstimator, store: OutcomeStore) -> None:
        """Fit κ̂ on the stored outcomes --learn-from selects, and say how many (and how many name no backend)."""
        from scone_bt.confidence import fit_on_outcomes
        from scone_bt.experience import LearnFrom, unlabelled_backend

        learn_from = LearnFrom.parse(self.options.learn_from)
        who = (self.robot_id, self.arm, self.options.profile, self.backend)
        filters = learn_from.filters(*who)
        outcomes = store.outcomes(**filters)  # read once: fitted on, and counted below
        n = fit_on_outcomes(est, outcomes, self.embedder())
        if not n:
            return
        line = f"κ̂ rebuilt from {n} stored outcomes {learn_from.describe(*who)}"
        # outcomes stored before outcomes named their backend count for every backend: say how many
        unnamed = sum(1 for o in outcomes if unlabelled_backend(o)) if "where" in filters else 0
        if unnamed:
            line += f" ({unnamed} stored before outcomes named their backend, taken as this one's)"
        self.printer(line)

    def close(self) -> None:
        """Release the robot (worker thread, simulation), the store and an own model pool."""
        try:
            self.robot.close()
        finally:
            if self._store is not None:
                self._store.close()
                self._store = None
            if self._own_models:
                self.models.close()

    def __enter__(self) -> EpisodeResources:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
