"""The robot's own place in the recipe, from what it observes (ρ's second role: completed and irrelevant steps).

The robot does not read the human's step counter. It starts at the first step (which also gathers the recipe
items no step names, as the recipe's stocking does) and moves past a step when the
step is *completed* (every item it names is on the table) or *irrelevant to the robot* (it names no recipe item
and the similarity fallback finds none). A step that names an item the robot cannot see yet keeps it waiting (the
human may be fetching it). Answers to clarification questions are kept per step.

An item is on the table when the table camera sees it *or* the robot placed it there itself (a labelled success)
and has not seen it back on the shelf since: products standing close together hide each other from the table
camera, and what the robot did is better evidence than one occluded view.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace

from scone_bt.recipes.normalise import item_key
from scone_bt.relevance.mentions import ambiguous_heads, mentioned_items
from scone_bt.relevance.recipe_aware import RecipeContext, SelectionOptions, StepSelection, select_for_step

__all__ = ["StepView", "track_recipe"]


@dataclass(frozen=True)
class StepView:
    """Where the robot is in the recipe and what that step wants.

    Attributes:
        index: 0-based index of the step the robot works on (== number of steps when it sees nothing left).
        instruction: That step's text ("" past the end).
        selection: The step's selection (empty past the end).
        skipped: Steps passed over on the way, each with why ("completed" or "nothing to fetch").
        placed_by_robot: Items the robot placed on the table itself and has not seen back on the shelf since
            (counted as on the table whether the table camera sees them or not).
        placed_unseen: Those of ``placed_by_robot`` the table camera does not see now.
        missing: Items this step names that the robot sees neither on the shelf nor on the table and did not
            place itself (what it may ask the human for); empty past the end.
    """

    index: int
    instruction: str
    selection: StepSelection
    skipped: tuple[tuple[int, str], ...] = ()
    placed_by_robot: frozenset[str] = frozenset()
    placed_unseen: frozenset[str] = frozenset()
    missing: tuple[str, ...] = ()


_EMPTY = StepSelection(now=(), later=(), ambiguous=(), named=(), done=True, reason="recipe finished")


def track_recipe(
    steps: Sequence[str],
    start: int,
    shelf: Sequence[str],
    items: Sequence[str],
    wordings: Mapping[str, tuple[str, ...]],
    on_table: frozenset[str],
    similarity: Callable[[str], Mapping[str, float]],
    options: SelectionOptions,
    clarified: Mapping[int, tuple[str, ...]] | None = None,
    placed: frozenset[str] = frozenset(),
) -> StepView:
    """From step ``start`` on, the first step that still wants something of the robot.

    Args:
        steps: The recipe's step texts.
        start: Where the robot was (it never moves back).
        shelf: Items seen on the shelf.
        items: The recipe's items as kitchen products.
        wordings: Product → other names the recipe or catalogue use for it.
        on_table: Items observed on the table.
        similarity: Step text → item → cosine similarity of its action to the step.
        options: The selection's thresholds.
        clarified: Step index → the items the human said it wants (empty: none of those asked about).
        placed: Items the robot placed on the table itself (labelled successes); one seen on the shelf again
            does not count.
    """
    clarified = clarified or {}
    shelf_keys = {item_key(i) for i in shelf}
    held = frozenset(i for i in placed if item_key(i) not in shelf_keys)
    seen_keys = {item_key(i) for i in on_table}
    unseen = frozenset(i for i in held if item_key(i) not in seen_keys)
    table = on_table | held
    table_keys = seen_keys | {item_key(i) for i in held}
    skipped: list[tuple[int, str]] = []
    # What no step names is gathered before cooking starts, as a cook reading the card would: needed now at the
    # first step.
    # An item a step means by a shared head noun alone ("the cheese": cheddar or swiss) is that step's question,
    # not an unnamed one.
    meant = {i for step in steps for g in ambiguous_heads(step, items, wordings=wordings) for i in g}
    unnamed = [
        i
        for i in items
        if i not in meant and not any(mentioned_items(step, [i], wordings=wordings) for step in steps)
    ]
    for k in range(max(0, start), len(steps)):
        context = RecipeContext(
            items=tuple(items), wordings=dict(wordings), steps_ahead=tuple(steps[k + 1 :]), on_table=table
        )
        sel = select_for_step(steps[k], shelf, context, similarity(steps[k]), options)
        if k == 0 and unnamed:
            first = tuple(i for i in shelf if i in unnamed and i not in sel.now)
            if first:
                later = tuple(i for i in sel.later if i not in first)
                sel = replace(sel, now=sel.now + first, later=later, named=sel.named + first, done=False)
        if k in clarified:
            answer = tuple(i for i in clarified[k] if i in shelf)
            sel = replace(sel, now=answer or sel.now, ambiguous=(), reason="the human said which")
        if sel.done:
            skipped.append((k, "completed"))
            continue
        if not sel.named and not sel.now and not sel.ambiguous:
            skipped.append((k, "nothing to fetch"))
            continue
        missing = tuple(i for i in sel.named if item_key(i) not in shelf_keys | table_keys)
        return StepView(k, steps[k], sel, tuple(skipped), held, unseen, missing)
    keys = {item_key(i) for i in items}
    left = tuple(i for i in shelf if item_key(i) in keys)  # on the card, named by no step still open
    return StepView(len(steps), "", replace(_EMPTY, later=left, done=not left), tuple(skipped), held, unseen)
