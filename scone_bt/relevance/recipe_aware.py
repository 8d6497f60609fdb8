"""ρ with the recipe: which of the recipe's items the current step needs now, which later, and when the step's
wording does not say which item it means.

The robot knows the whole recipe card, not only the current step: its ingredient list (as kitchen items), the
wordings its ingredient lines use for them, and the steps ahead. `select_for_step` is a pure rule:

1. Candidates are the recipe's items that stand on the shelf. An item the recipe never uses is never a candidate.
2. NOW: the candidates the step names (whole name, a recipe wording, or an unambiguous head noun; see
   `scone_bt.relevance.mentions`), unless every mention is negated ("without the cheese"), best cosine first.
3. If the step names no recipe item (on the shelf or not), the semantic fallback: the most similar candidate is NOW when its cosine similarity
   reaches ``rho`` and beats the runner-up by ``margin``; two or more candidates within ``margin`` of each other
   above ``rho`` are AMBIGUOUS (the robot should ask which one is meant). A shared head noun the step uses alone
   ("the oil" with canola and sesame oil on the shelf) is ambiguous too.
4. LATER: the other candidates, those a step ahead names first, in the order they are needed, then the rest of
   the recipe card, less the items a step ahead means only by a shared head noun ("the oil"): which one is
   asked at that step. They are fetched only when the step has nothing left to fetch now.
5. The step is DONE when it names items and every named item is on the table (observed) and none is left on the
   shelf.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from enum import StrEnum

from scone_bt.errors import SconeError
from scone_bt.recipes.normalise import item_key
from scone_bt.relevance.mentions import ambiguous_heads, mentioned_items, negated_items

__all__ = ["Need", "RecipeContext", "SelectionOptions", "StepSelection", "select_for_step"]


class Need(StrEnum):
    """Why an action is a candidate for the current step."""

    NOW = "now"  # the current step needs it
    LATER = "later"  # a step ahead needs it; fetched when the current step has nothing left


@dataclass(frozen=True)
class RecipeContext:
    """What the robot knows of the recipe at one step.

    Attributes:
        items: The recipe's ingredient list as kitchen items, in list order.
        wordings: Item → other names the recipe uses for it (its ingredient lines, a product's aliases).
        steps_ahead: The texts of the steps after the current one, in order.
        on_table: Items observed on the table.
    """

    items: tuple[str, ...]
    wordings: Mapping[str, tuple[str, ...]] = field(default_factory=dict)
    steps_ahead: tuple[str, ...] = ()
    on_table: frozenset[str] = frozenset()


@dataclass(frozen=True)
class SelectionOptions:
    """The semantic fallback's thresholds (learnt on the IF train split; see `fit_selection_options`).

    Attributes:
        rho: Cosine similarity an unnamed candidate needs to be NOW, in [-1, 1].
        margin: How far the best unnamed candidate must beat the runner-up, cosine similarity ≥ 0; closer than
            this (both above ``rho``) is AMBIGUOUS.
    """

    rho: float = 0.45
    margin: float = 0.03

    def __post_init__(self) -> None:
        if not -1.0 <= self.rho <= 1.0:
            raise SconeError(f"selection rho must be a cosine similarity in [-1, 1], got {self.rho}")
        if not 0.0 <= self.margin <= 2.0:
            raise SconeError(f"selection margin must be in [0, 2], got {self.margin}")


@dataclass(frozen=True)
class StepSelection:
    """Which shelf items the current step wants.

    Attributes:
        now: Items the step needs now, best cosine first.
        later: Items steps ahead need, in the order they are first needed.
        ambiguous: Items the step could mean about equally (ask which); empty when the step is clear.
        named: Every recipe item the step names (on the shelf, on the table or neither).
        done: The step names items and all of them are on the table.
        reason: One short sentence for the decision line.
    """

    now: tuple[str, ...]
    later: tuple[str, ...]
    ambiguous: tuple[str, ...]
    named: tuple[str, ...]
    done: bool
    reason: str

    def need(self, item: str) -> Need | None:
        """NOW, LATER or None (not a candidate for this step)."""
        if item in self.now:
            return Need.NOW
        return Need.LATER if item in self.later else None


def select_for_step(
    step: str,
    shelf: Sequence[str],
    context: RecipeContext,
    similarity: Mapping[str, float],
    options: SelectionOptions | None = None,
) -> StepSelection:
    """Apply the module's rule to one step.

    Args:
        step: The current step's text.
        shelf: Items seen on the shelf (any order).
        context: The recipe as the robot knows it.
        similarity: Item → cosine similarity of its action to ``step`` (items missing from it count as -1).
        options: The semantic fallback's thresholds.
    """
    opts = options or SelectionOptions()
    recipe_keys = {item_key(i) for i in context.items}
    candidates = [i for i in shelf if item_key(i) in recipe_keys]
    wordings = dict(context.wordings)
    everything = list(dict.fromkeys([*context.items, *candidates]))
    named = mentioned_items(step, everything, wordings=wordings)
    negated = negated_items(step, named, wordings=wordings)
    named = [i for i in named if i not in negated]
    sim = {i: float(similarity.get(i, -1.0)) for i in candidates}
    now = sorted((i for i in candidates if i in named), key=lambda i: -sim[i])
    ambiguous: tuple[str, ...] = ()
    reason = "the step names it" if now else ""
    # The fallback is for a step that names no recipe item: a step whose named items are not on the shelf (the
    # human may be fetching them) needs those, not the most similar item; its candidates stay LATER.
    if not now and not named:
        groups = [g for g in ambiguous_heads(step, candidates, wordings=wordings) if all(i in sim for i in g)]
        unnamed = sorted((i for i in candidates if i not in negated), key=lambda i: -sim[i])
        if groups:
            ambiguous = tuple(sorted(groups[0], key=lambda i: -sim[i]))
            reason = f"the step says '{item_key(ambiguous[0].split()[-1])}' alone"
        elif unnamed and sim[unnamed[0]] >= opts.rho:
            close = [i for i in unnamed if sim[i] >= opts.rho and sim[unnamed[0]] - sim[i] < opts.margin]
            if len(close) > 1:
                ambiguous = tuple(close)
                reason = "several items fit the step about equally"
            else:
                now = [unnamed[0]]
                reason = f"most similar item ({sim[unnamed[0]]:.2f} ≥ ρ {opts.rho:.2f})"
    later: list[str] = []
    held: set[str] = set()
    for ahead in context.steps_ahead:
        rest = [i for i in candidates if i not in now and i not in later]
        later += mentioned_items(ahead, rest, wordings=wordings)
        if not mentioned_items(ahead, everything, wordings=wordings):
            # a step ahead that says only "the oil" with two oils on the card: which one it means is asked
            # there, so neither is fetched before (fetching both would answer the question by guessing)
            held.update(i for g in ambiguous_heads(ahead, candidates, wordings=wordings) for i in g)
    # what no step ahead names is still on the recipe card: gathered last
    later += [
        i for i in candidates if i not in now and i not in later and i not in ambiguous and i not in held
    ]
    shelf_keys = {item_key(i) for i in shelf}
    table_keys = {item_key(i) for i in context.on_table}
    done = bool(named) and all(item_key(i) in table_keys and item_key(i) not in shelf_keys for i in named)
    if not reason:
        reason = "all it names is on the table" if done else "nothing on the shelf for this step"
    return StepSelection(
        now=tuple(now),
        later=tuple(later),
        ambiguous=ambiguous,
        named=tuple(named),
        done=done,
        reason=reason,
    )
