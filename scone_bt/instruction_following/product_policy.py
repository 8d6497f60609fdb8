"""The policy the robot runs, on IF states: recipe-aware selection (`scone_bt.relevance.recipe_aware`) with its
own stop rule: it picks the step's NOW items and stops; on an ambiguous step it picks its best guess (in the
episode it asks which item is meant instead).

Its semantic fallback's thresholds are fitted on the train split (`fit_selection_options`). A state must carry
``recipe_items`` (the recipe's ingredient list); states without it fall back to every available item, which is
the plain (recipe-blind) setting.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from scone_bt.embedding.base import Embedder
from scone_bt.instruction_following.metric import evaluate
from scone_bt.instruction_following.policies import state_scores
from scone_bt.instruction_following.states import IfState, item_of_action
from scone_bt.relevance.recipe_aware import RecipeContext, SelectionOptions, StepSelection, select_for_step

__all__ = ["RecipeAwarePolicy", "RecipeSimilarityPolicy", "fit_selection_options", "fit_similarity_policy"]


@dataclass
class RecipeAwarePolicy:
    """Recipe-aware selection as an IF policy.

    Attributes:
        embedder: ζ for the similarities (the fallback and the order of picks).
        name: Row label.
        options: The fallback's thresholds.
    """

    embedder: Embedder
    name: str
    options: SelectionOptions = field(default_factory=SelectionOptions)
    _picks: dict[tuple[str, tuple[str, ...]], tuple[str, ...]] = field(default_factory=dict, repr=False)

    def selection(self, state: IfState) -> StepSelection:
        """The recipe-aware selection for a state."""
        (sc,) = state_scores(self.embedder, [state])
        items = [item_of_action(a) for a in state.available]
        similarity = dict(zip(items, map(float, sc), strict=True))
        context = RecipeContext(items=tuple(state.recipe_items) or tuple(items))
        return select_for_step(state.instruction, items, context, similarity, self.options)

    def picks(self, state: IfState) -> tuple[str, ...]:
        """Action texts picked in the state, in order."""
        key = (state.instruction, state.available)
        if key not in self._picks:
            sel = self.selection(state)
            chosen = sel.now or sel.ambiguous[:1]
            by_item = {item_of_action(a): a for a in state.available}
            self._picks[key] = tuple(by_item[i] for i in chosen)
        return self._picks[key]

    def choose(self, state: IfState, remaining: Sequence[str], picked: Sequence[str]) -> str | None:
        """The next of the selection's picks, or None when they are all picked."""
        for action in self.picks(state):
            if action in remaining and action not in picked:
                return action
        return None


def fit_selection_options(embedder: Embedder, train: Sequence[IfState], name: str = "") -> SelectionOptions:
    """The (rho, margin) maximising min(accuracy, recall) on the train states (ties: the lower rho)."""
    state_scores(embedder, train)  # one batched pass; the policies read the embedder's cache
    best: tuple[float, float, float] | None = None
    for rho in np.round(np.arange(0.05, 0.80, 0.1), 3):
        for margin in (0.0, 0.05):
            policy = RecipeAwarePolicy(embedder, name, SelectionOptions(float(rho), margin))
            score = evaluate(policy, train)
            value = min(score.accuracy, score.recall)
            if best is None or value > best[0] + 1e-12:
                best = (value, float(rho), margin)
    assert best is not None
    return SelectionOptions(rho=best[1], margin=best[2])


@dataclass
class RecipeSimilarityPolicy:
    """An ablation: the recipe's items only, chosen by similarity alone (no reading of item names).

    Picks, best first, the recipe's items whose cosine similarity is at least ``rho`` and within ``delta`` of
    the best recipe item's; it shows what ζ contributes once the robot knows the recipe.
    """

    embedder: Embedder
    name: str
    rho: float = 0.0
    delta: float = 0.1

    def choose(self, state: IfState, remaining: Sequence[str], picked: Sequence[str]) -> str | None:
        (sc,) = state_scores(self.embedder, [state])
        recipe = set(state.recipe_items) or {item_of_action(a) for a in state.available}
        scores = {
            a: float(v) for a, v in zip(state.available, sc, strict=True) if item_of_action(a) in recipe
        }
        if not scores:
            return None
        top = max(scores.values())
        ok = [a for a in remaining if a in scores and scores[a] >= self.rho and scores[a] >= top - self.delta]
        if not picked and not ok:
            ok = (
                [max(scores, key=scores.__getitem__)]
                if max(scores, key=scores.__getitem__) in remaining
                else []
            )
        return max(ok, key=lambda a: scores[a]) if ok else None


def fit_similarity_policy(embedder: Embedder, train: Sequence[IfState], name: str) -> RecipeSimilarityPolicy:
    """The (rho, delta) of `RecipeSimilarityPolicy` maximising min(accuracy, recall) on the train states."""
    state_scores(embedder, train)
    best: tuple[float, RecipeSimilarityPolicy] | None = None
    for rho in (0.0, 0.1, 0.2, 0.3, 0.4):
        for delta in (0.02, 0.05, 0.1, 0.15, 0.2, 0.3):
            policy = RecipeSimilarityPolicy(embedder, name, rho, delta)
            score = evaluate(policy, train)
            value = min(score.accuracy, score.recall)
            if best is None or value > best[0] + 1e-12:
                best = (value, policy)
    assert best is not None
    return best[1]
