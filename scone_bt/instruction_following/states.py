"""Labelled instruction-following states built from real recipes.

A simulated kitchen holds one recipe's ingredients plus distractors drawn from other recipes, each on a random
shelf slot. The simulated human works through the steps; a step's relevant actions are the ingredients it uses
that are still in the kitchen, and an ingredient is used up after the last step that uses it.

File schema (JSON Lines, one state per line): ``instruction`` (str), ``available`` (action texts, "Put X on
table"), ``relevant`` (a subset of ``available``); optional ``recipe_id``, ``step`` (0-based), ``split``
("train", "dev", "test"), ``labels`` ("author": the recipe author's Cooklang markup; "mentions": items named in
the step text), ``locations`` (action text → [shelf tier, slot], tier 0 lowest) and ``recipe_items`` (the
recipe's ingredient list as kitchen items, in list order: what the robot knows from the recipe card, not a label).
"""

from __future__ import annotations

import hashlib
import json
import os
from collections import Counter
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal

import numpy as np

from scone_bt.affordances.types import action_text, object_of_action
from scone_bt.errors import RecipeError, SconeError
from scone_bt.files import write_atomic
from scone_bt.recipes.normalise import is_fetchable, item_key, normalise_ingredient
from scone_bt.recipes.recipe import Recipe
from scone_bt.relevance.mentions import mentioned_items

__all__ = [
    "IfState",
    "StateOptions",
    "Labels",
    "Split",
    "SPLITS",
    "build_states",
    "recipe_split",
    "mentioned_items",
    "item_of_action",
    "load_states",
    "save_states",
    "check_states_files",
    "save_states_files",
    "states_text",
]

Labels = Literal["author", "mentions"]
Split = Literal["train", "dev", "test"]
SPLITS: tuple[Split, ...] = ("train", "dev", "test")
item_of_action = object_of_action  # the IF benchmark's name for it


@dataclass(frozen=True)
class IfState:
    """One instruction with the actions available then and the relevant ones.

    Attributes:
        instruction: The recipe step, verbatim.
        available: Action texts of every item in the kitchen, in shelf order.
        relevant: The available actions that the step needs (subset of ``available``).
        recipe_id: Source recipe id ("" when unknown).
        step: 0-based step index in the recipe (-1 when unknown).
        split: "train", "dev", "test" or "" when the file does not say.
        labels: How ``relevant`` was obtained: "author", "mentions" or "".
        locations: Action text → (shelf tier, slot index); tier 0 is the lowest.
        recipe_items: The recipe's ingredient list as kitchen items (empty when the file does not say).
    """

    instruction: str
    available: tuple[str, ...]
    relevant: frozenset[str]
    recipe_id: str = ""
    step: int = -1
    split: str = ""
    labels: str = ""
    locations: dict[str, tuple[int, int]] = field(default_factory=dict, compare=False, hash=False)
    recipe_items: tuple[str, ...] = ()

    def to_json(self) -> dict[str, object]:
        """The state as one JSON object of the documented schema."""
        return {
            "instruction": self.instruction,
            "available": list(self.available),
            "relevant": [a for a in self.available if a in self.relevant],
            "recipe_id": self.recipe_id,
            "step": self.step,
            "split": self.split,
            "labels": self.labels,
            "locations": {a: list(loc) for a, loc in self.locations.items()},
            "recipe_items": list(self.recipe_items),
        }


@dataclass(frozen=True)
class StateOptions:
    """How the simulated kitchen is stocked.

    Attributes:
        labels: "author" uses per-step Cooklang markup (``nw:`` recipes only); "mentions" labels the kitchen
            items named in each step (any recipe).
        distractors: Items from other recipes added to each kitchen.
        tiers: Shelf tiers (perception/kitchen.yaml has 3).
        slots_per_tier: Slots on each tier (perception/kitchen.yaml has 5).
        min_recipe_items: Recipes with fewer fetchable items are skipped.
        split_fractions: Shares of recipes for train and dev; the rest is test.
        seed: Seeds distractor choice and placement.
    """

    labels: Labels = "author"
    distractors: int = 5
    tiers: int = 3
    slots_per_tier: int = 5
    min_recipe_items: int = 2
    split_fractions: tuple[float, float] = (0.7, 0.1)
    seed: int = 0

    @property
    def capacity(self) -> int:
        """Shelf slots in the kitchen."""
        return self.tiers * self.slots_per_tier


def recipe_split(recipe_id: str, fractions: tuple[float, float] = (0.7, 0.1)) -> Split:
    """Deterministic split of a recipe by a hash of its id, so every step of a recipe lands in one split."""
    u = int(hashlib.sha256(recipe_id.encode()).hexdigest()[:12], 16) / float(1 << 48)
    if u < fractions[0]:
        return "train"
    return "dev" if u < fractions[0] + fractions[1] else "test"


def _items(names: Iterable[str]) -> list[str]:
    """Normalised fetchable items, first spelling of each plural-insensitive key."""
    out: dict[str, str] = {}
    for name in names:
        item = normalise_ingredient(name)
        if is_fetchable(item) and item_key(item) not in out:
            out[item_key(item)] = item
    return list(out.values())


def _step_items(recipe: Recipe, items: list[str], labels: Labels) -> list[list[str]]:
    by_key = {item_key(i): i for i in items}
    per_step: list[list[str]] = []
    for i, step in enumerate(recipe.steps):
        if labels == "author":
            assert recipe.step_ingredients is not None
            keys = [item_key(x) for x in _items(recipe.step_ingredients[i])]
            per_step.append([by_key[k] for k in keys if k in by_key])
        else:
            per_step.append(mentioned_items(step, items))
    return per_step


def build_states(recipes: Sequence[Recipe], options: StateOptions | None = None) -> list[IfState]:
    """Labelled states for every step that needs at least one item still in the kitchen.

    Args:
        recipes: Source recipes; with ``labels="author"`` those without ``step_ingredients`` are skipped.
        options: Kitchen and split settings.

    Returns:
        States in recipe order, then step order.
    """
    opts = options or StateOptions()
    if opts.labels not in ("author", "mentions"):
        raise RecipeError(f"unknown labels {opts.labels!r}; valid: author, mentions")
    usable = [r for r in recipes if opts.labels == "mentions" or r.step_ingredients is not None]
    recipe_items = {r.id: _items(r.ingredients) for r in usable}
    # Distractor pool: every item of every usable recipe, weighted by how many recipes use it.
    pool = Counter(item for items in recipe_items.values() for item in items)
    pool_items = sorted(pool)
    pool_p = np.array([pool[i] for i in pool_items], dtype=float)
    pool_p /= pool_p.sum()
    rng = np.random.default_rng(opts.seed)
    states: list[IfState] = []
    for recipe in usable:
        items = recipe_items[recipe.id]
        if opts.labels == "author":
            # Marked step ingredients missing from the list (rare) are still ingredients.
            extra = _items(x for step in recipe.step_ingredients or () for x in step)
            known = {item_key(i) for i in items}
            items = items + [x for x in extra if item_key(x) not in known]
        if len(items) < opts.min_recipe_items or len(items) > opts.capacity - opts.distractors:
            continue
        keys = {item_key(i) for i in items}
        # The draw below takes items of other recipes until it has enough: with too few it would never end.
        others = {item_key(i) for i in pool_items} - keys
        if len(others) < opts.distractors:
            raise RecipeError(
                f"distractors {opts.distractors}: recipe {recipe.id!r} leaves only {len(others)} other item(s) "
                "in the corpus to draw them from; give fewer distractors or more recipes"
            )
        distractors: list[str] = []
        while len(distractors) < opts.distractors:
            cand = pool_items[int(rng.choice(len(pool_items), p=pool_p))]
            if item_key(cand) not in keys:
                keys.add(item_key(cand))
                distractors.append(cand)
        kitchen = items + distractors
        slots = rng.permutation(opts.capacity)[: len(kitchen)]
        where = {
            item: (int(s) // opts.slots_per_tier, int(s) % opts.slots_per_tier)
            for item, s in zip(kitchen, slots, strict=True)
        }
        shelf_order = sorted(kitchen, key=lambda i: where[i])
        per_step = _step_items(recipe, items, opts.labels)
        last_use = {item: max((k for k, s in enumerate(per_step) if item in s), default=-1) for item in items}
        split = recipe_split(recipe.id, opts.split_fractions)
        for k, (instruction, used) in enumerate(zip(recipe.steps, per_step, strict=True)):
            in_kitchen = [i for i in shelf_order if i not in items or last_use[i] >= k]
            relevant = [i for i in used if i in in_kitchen]
            if relevant:
                available = tuple(action_text(i) for i in in_kitchen)
                states.append(
                    IfState(
                        instruction=instruction,
                        available=available,
                        relevant=frozenset(action_text(i) for i in relevant),
                        recipe_id=recipe.id,
                        step=k,
                        split=split,
                        labels=opts.labels,
                        locations={action_text(i): where[i] for i in in_kitchen},
                        recipe_items=tuple(items),
                    )
                )
    return states


def states_text(states: Iterable[IfState]) -> str:
    """States as the text of a JSON Lines file, one state a line."""
    return "".join(json.dumps(s.to_json(), ensure_ascii=False) + "\n" for s in states)


def save_states(path: str | os.PathLike[str], states: Iterable[IfState]) -> int:
    """Write states as JSON Lines, atomically (a reader never sees half a file); returns how many were written."""
    chosen = list(states)
    write_atomic(Path(path), states_text(chosen))
    return len(chosen)


def check_states_files(
    out: Path, names: Iterable[str], inputs: Mapping[str, Iterable[Path]] | None = None, force: bool = False
) -> list[Path]:
    """The states files a build writes in `out`, checked before it builds anything (one-line SconeError).

    `out` is a folder (or one that can be made); no file is one of `inputs` or an existing file that is not text
    (unless `force`). Judged as text, not JSON: the committed files are over the 1 MiB that a JSON check reads.
    """
    from scone_bt.checks import check_output_dir, check_output_file

    check_output_dir(out, "--out")
    return [check_output_file(out / n, "--out", kind="text", inputs=inputs, force=force) for n in names]


def save_states_files(
    out: Path, files: Mapping[str, Sequence[IfState]], force: bool = False
) -> dict[str, int]:
    """Write every states file of a build, or none of them.

    An existing file that holds other states than the build's is not replaced unless `force`: the committed
    files (tools/data/if) are the benchmark's data, and a build with another seed or corpus must not silently
    take their place. A file that already holds exactly these states is left as it is.

    Args:
        out: The folder.
        files: File name → its states.
        force: Replace existing files that differ.

    Returns:
        File name → states in it.

    Raises:
        SconeError: Files that differ and no `force` (one line naming them); nothing is written then.
    """
    texts = {name: states_text(states).encode() for name, states in files.items()}
    existing = {name: (out / name).read_bytes() for name in texts if (out / name).is_file()}
    differ = [name for name, data in texts.items() if name in existing and existing[name] != data]
    if differ and not force:
        verb = "exists and holds" if len(differ) == 1 else "exist and hold"
        raise SconeError(
            f"--out {out}: {', '.join(differ)} already {verb} other states than this build "
            "(another --seed, --distractors or corpus); not replaced: give another --out, or --force to replace"
        )
    out.mkdir(parents=True, exist_ok=True)
    for name, data in texts.items():
        if existing.get(name) != data:
            write_atomic(out / name, data)
    return {name: len(states) for name, states in files.items()}


def load_states(path: str | os.PathLike[str], split: str | None = None) -> list[IfState]:
    """Read a states file of the documented schema, optionally keeping one split.

    Raises:
        RecipeError: The file is missing or a line breaks the schema (the message names the line).
    """
    if split is not None and split not in SPLITS:
        raise RecipeError(f"unknown split {split!r}; valid: {', '.join(SPLITS)}")
    file = Path(path)
    if not file.is_file():
        raise RecipeError(f"states file not found: {file}")
    states = []
    with file.open() as fh:
        for n, line in enumerate(fh, 1):
            if not line.strip():
                continue
            try:
                rec = json.loads(line)
                instruction, available, relevant = rec["instruction"], rec["available"], rec["relevant"]
            except (json.JSONDecodeError, KeyError, TypeError):
                raise RecipeError(
                    f"{file}:{n}: not a state; required keys: instruction, available, relevant"
                ) from None
            if (
                not isinstance(instruction, str)
                or not isinstance(available, list)
                or not isinstance(relevant, list)
            ):
                raise RecipeError(
                    f"{file}:{n}: instruction must be a string, available and relevant lists of strings"
                )
            if not set(relevant) <= set(available):
                raise RecipeError(f"{file}:{n}: relevant actions must be a subset of the available ones")
            locations = {str(a): (int(v[0]), int(v[1])) for a, v in (rec.get("locations") or {}).items()}
            recipe_items = rec.get("recipe_items") or []
            if not isinstance(recipe_items, list) or not all(isinstance(i, str) for i in recipe_items):
                raise RecipeError(f"{file}:{n}: recipe_items must be a list of strings")
            states.append(
                IfState(
                    instruction=instruction,
                    available=tuple(str(a) for a in available),
                    relevant=frozenset(str(a) for a in relevant),
                    recipe_id=str(rec.get("recipe_id", "")),
                    step=int(rec.get("step", -1)),
                    split=str(rec.get("split", "")),
                    labels=str(rec.get("labels", "")),
                    locations=locations,
                    recipe_items=tuple(recipe_items),
                )
            )
    if split is not None:
        states = [s for s in states if s.split == split]
    return states
