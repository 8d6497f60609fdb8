"""RankByRelevance (ζ, ρ): where the robot is in the recipe, and the affordances ranked against that step.

Recipe-aware (the default): the robot tracks its own step from what it observes and what it did (its labelled
successful placements, `Keys.OUTCOME`; `scone_bt.relevance.tracker`), and each action carries why it is a candidate ("now", "later", or "" when the recipe never uses it). With
``recipe_aware`` off, the paper's setting: the human's current step text alone, every action a candidate.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import TYPE_CHECKING

import py_trees

from scone_bt.behaviours.base import Keys, StageBehaviour
from scone_bt.behaviours.context import EpisodeContext
from scone_bt.behaviours.ports import HumanChannel, Provider

if TYPE_CHECKING:
    import numpy as np

    from scone_bt.affordances.types import Affordance
    from scone_bt.embedding import Embedder
    from scone_bt.relevance.recipe_aware import SelectionOptions
    from scone_bt.relevance.tracker import StepView

__all__ = ["RankByRelevance"]


class RankByRelevance(StageBehaviour):
    """ρ · ζ: embeds the actions, tracks the robot's place in the recipe from what stands on the table, and
    ranks the actions by relevance to the step (recipe-aware), or to the human's current instruction alone (the
    paper's recipe-blind setting); always SUCCESS."""

    READS = (Keys.AFFORDANCES, Keys.TABLE_DETECTIONS, Keys.CLARIFIED, Keys.OUTCOME)
    WRITES = (Keys.INSTRUCTION, Keys.RANKED, Keys.ACTION_EMBEDDINGS, Keys.STEP)

    def __init__(
        self,
        name: str,
        embedder: Provider[Embedder],
        steps: Sequence[str],
        wordings: Mapping[str, tuple[str, ...]],
        selection: SelectionOptions,
        recipe_aware: bool,
        human: HumanChannel,
    ) -> None:
        """Args: ``steps`` are the recipe's instructions, ``wordings`` each recipe item's aliases (its keys are
        the items, in the recipe's order); ``human`` is read only with ``recipe_aware`` off (the paper's setting).
        """
        super().__init__(name)
        self._embedder = embedder
        self.step = 0
        self.steps = tuple(steps)
        self.items = tuple(wordings)
        self.wordings = dict(wordings)
        self.selection_options = selection
        self.recipe_aware = recipe_aware
        self.human = human
        # What the robot put on the table itself and has not seen back on the shelf since.
        self.placed: set[str] = set()
        self._outcome: object = None  # the last outcome read (each is counted once)

    @classmethod
    def from_context(cls, name: str, context: EpisodeContext) -> RankByRelevance:
        from scone_bt.relevance.recipe_aware import SelectionOptions

        recipe, opts = context.recipe, context.options
        rho, margin = opts.relevance_threshold, opts.clarify_margin
        assert rho is not None and margin is not None  # the episode's options are resolved
        return cls(
            name,
            context.embedder,
            tuple(step.instruction for step in recipe.steps),
            {n: tuple(context.catalogue.get(n).aliases) for n in recipe.needed},
            SelectionOptions(rho=rho, margin=margin),
            bool(opts.recipe_aware),
            context.human,
        )

    def setup(self, **kwargs: object) -> None:
        self.embedder = self._embedder()

    def update(self) -> py_trees.common.Status:
        affordances = self.read(Keys.AFFORDANCES, [])
        texts = [a.text for a in affordances]
        vectors: np.ndarray | Sequence[np.ndarray] = self.embedder.embed(texts) if texts else []
        self.write(Keys.ACTION_EMBEDDINGS, dict(zip(texts, vectors, strict=True)))
        if self.recipe_aware:
            self._rank_by_recipe(affordances)
        else:
            self._rank_by_instruction(texts)
        return py_trees.common.Status.SUCCESS

    def _rank_by_instruction(self, texts: Sequence[str]) -> None:
        """The paper's recipe-blind setting: rank by the human's current instruction alone."""
        from scone_bt.relevance import rank_actions

        instruction = self.human.current_instruction
        self.write(Keys.INSTRUCTION, instruction)
        self.write(Keys.STEP, None)
        ranked = rank_actions(instruction, texts, self.embedder) if texts and instruction else []
        self.write(Keys.RANKED, ranked)
        self.feedback_message = f"best: {ranked[0].text} ({ranked[0].relevance:.2f})" if ranked else "idle"

    def _rank_by_recipe(self, affordances: Sequence[Affordance]) -> None:
        """Track the robot's place in the recipe, then rank the actions by relevance to its step."""
        from scone_bt.relevance import RankedAction, relevance_matrix

        texts = [a.text for a in affordances]
        names = [a.object_name for a in affordances]
        self._note_placements(names)
        scored: dict[str, dict[str, float]] = {}  # the tracker and the ranking below ask for the same steps

        def similarity(step: str) -> dict[str, float]:
            if step not in scored:
                row = relevance_matrix([step], texts, self.embedder)[0]
                scored[step] = dict(zip(names, map(float, row), strict=True))
            return scored[step]

        view = self._track(names, similarity)
        step_text = view.instruction or (self.steps[-1] if self.steps else "")
        scores = similarity(step_text) if texts and step_text else {}
        ranked = sorted(
            (
                RankedAction(a.text, scores.get(a.object_name, 0.0), view.selection.need(a.object_name) or "")
                for a in affordances
            ),
            key=lambda r: -r.relevance,
        )
        self.write(Keys.RANKED, ranked)
        sel = view.selection
        self.feedback_message = (
            f"step {view.index + 1}: now {', '.join(sel.now) or '-'}; later {', '.join(sel.later) or '-'}"
            + (f"; which of {', '.join(sel.ambiguous)}?" if sel.ambiguous else "")
        )

    def _track(self, names: Sequence[str], similarity: Callable[[str], dict[str, float]]) -> StepView:
        """The robot's place in the recipe from what stands on the table and what it placed (written to
        `Keys.STEP` and `Keys.INSTRUCTION`)."""
        from scone_bt.relevance.tracker import track_recipe

        on_table = frozenset(d.name for d in self.read(Keys.TABLE_DETECTIONS, ()) or ())
        view = track_recipe(
            self.steps,
            self.step,
            names,
            self.items,
            self.wordings,
            on_table,
            similarity,
            self.selection_options,
            self.read(Keys.CLARIFIED, {}),
            frozenset(self.placed),
        )
        self.step = view.index
        self.write(Keys.STEP, view)
        self.write(Keys.INSTRUCTION, view.instruction or None)
        return view

    def _note_placements(self, shelf: Sequence[str]) -> None:
        """Keep `placed` up to date: a new labelled success adds its object; a failure on it, or seeing it on the
        shelf again, says it is not (or no longer) on the table."""
        outcome = self.read(Keys.OUTCOME, None)
        if outcome is not None and outcome is not self._outcome:
            if outcome.success:
                self.placed.add(outcome.object_name)
            else:
                self.placed.discard(outcome.object_name)
        self._outcome = outcome
        self.placed.difference_update(shelf)
