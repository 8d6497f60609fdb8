"""A recipe record, as in ../shared/data/recipes/recipes.jsonl, and where to find one."""

from __future__ import annotations

import difflib
import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

from scone_bt.errors import RecipeError
from scone_bt.resources import shared_dir

__all__ = ["Recipe", "load_recipe", "recipe_corpus_path", "recipe_from_record", "EXAMPLES_DIR"]

EXAMPLES_DIR = Path(__file__).resolve().parent / "examples"


@dataclass(frozen=True)
class Recipe:
    """A recipe: ingredient strings and ordered steps.

    Attributes:
        id: Corpus id ("pdr:…", "nw:…"), "example:<name>" for bundled examples, or the file path.
        title: Display name.
        ingredients: Ingredient strings with quantities ("1 can chickpeas, drained").
        steps: Instructions in order.
        step_ingredients: Per step, the ingredients the author marked in it (``nw:`` records), else None.
    """

    id: str
    title: str
    ingredients: tuple[str, ...]
    steps: tuple[str, ...]
    step_ingredients: tuple[tuple[str, ...], ...] | None = None


def recipe_corpus_path() -> Path | None:
    shared = shared_dir()
    if shared is None:
        return None
    path = shared / "data" / "recipes" / "recipes.jsonl"
    return path if path.is_file() else None


def recipe_from_record(record: Any, where: str) -> Recipe:
    """Validate one JSON/YAML record of the corpus's shape."""
    if not isinstance(record, dict):
        raise RecipeError(f"{where}: a recipe must be a mapping with id, title, ingredients, steps")
    missing = [k for k in ("ingredients", "steps") if k not in record]
    if missing:
        raise RecipeError(
            f"{where}: recipe lacks {', '.join(missing)}; required: ingredients, steps (optional: id, title, step_ingredients)"
        )
    ingredients, steps = record["ingredients"], record["steps"]
    if not isinstance(ingredients, list) or not all(isinstance(i, str) for i in ingredients):
        raise RecipeError(f"{where}: 'ingredients' must be a list of strings")
    if not isinstance(steps, list) or not all(isinstance(s, str) for s in steps):
        raise RecipeError(f"{where}: 'steps' must be a list of strings")
    steps = [s.strip() for s in steps]
    if not steps or any(not s for s in steps):
        raise RecipeError(f"{where}: every step must be a non-empty instruction (found {len(steps)} steps)")
    per_step = record.get("step_ingredients")
    if per_step is not None:
        if not isinstance(per_step, list) or len(per_step) != len(steps):
            raise RecipeError(f"{where}: 'step_ingredients' must have one list per step ({len(steps)})")
        per_step = tuple(tuple(str(i) for i in s) for s in per_step)
    return Recipe(
        id=str(record.get("id", where)),
        title=str(record.get("title", record.get("id", where))),
        ingredients=tuple(ingredients),
        steps=tuple(steps),
        step_ingredients=per_step,
    )


def _load_file(path: Path) -> Recipe:
    try:
        text = path.read_text()
        record = json.loads(text) if path.suffix == ".json" else yaml.safe_load(text)
    except (json.JSONDecodeError, yaml.YAMLError) as exc:
        raise RecipeError(
            f"{path}: not valid {'JSON' if path.suffix == '.json' else 'YAML'} ({exc})".splitlines()[0]
        ) from None
    return recipe_from_record(record, str(path))


def example_names() -> list[str]:
    return sorted(p.stem for p in EXAMPLES_DIR.glob("*.yaml"))


def load_recipe(id_or_path: str) -> Recipe:
    """Load a recipe from a JSON/YAML file, a bundled example ("example:<name>") or the shared corpus by id."""
    path = Path(id_or_path)
    if path.suffix in (".json", ".yaml", ".yml"):
        if not path.is_file():
            raise RecipeError(f"recipe file not found: {path}")
        return _load_file(path)
    if id_or_path.startswith("example:"):
        name = id_or_path.removeprefix("example:")
        file = EXAMPLES_DIR / f"{name}.yaml"
        if not file.is_file():
            raise RecipeError(
                f"unknown example recipe {name!r}; valid: {', '.join('example:' + n for n in example_names())}"
            )
        return _load_file(file)
    corpus = recipe_corpus_path()
    if corpus is None:
        raise RecipeError(
            f"recipe {id_or_path!r}: the corpus ../shared/data/recipes/recipes.jsonl is not here; "
            f"use a JSON/YAML file or one of: {', '.join('example:' + n for n in example_names())}"
        )
    ids = []
    with corpus.open() as fh:
        for line_no, line in enumerate(fh, 1):
            record = json.loads(line)
            if record.get("id") == id_or_path:
                return recipe_from_record(record, f"{corpus}:{line_no}")
            ids.append(record.get("id", ""))
    close = difflib.get_close_matches(id_or_path, ids, n=3, cutoff=0.5)
    hint = f"; did you mean {', '.join(close)}?" if close else f"; ids look like {ids[0]!r} (see {corpus})"
    raise RecipeError(f"unknown recipe id {id_or_path!r} among {len(ids)} recipes{hint}")
