"""A recipe record, as in ../shared/data/recipes/recipes.jsonl, where to find one, and the one reader of the corpus."""

from __future__ import annotations

import difflib
import json
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any

import yaml
from pydantic import Field, field_validator, model_validator

from scone_bt.config.schema import MAX_DATA_FILE_BYTES, StrictModel, read_text, validate
from scone_bt.config.yaml_io import safe_load
from scone_bt.errors import RecipeError
from scone_bt.resources import shared_dir

__all__ = [
    "CorpusEntry",
    "Recipe",
    "RecipeRecord",
    "corpus_entries",
    "load_recipe",
    "read_corpus",
    "recipe_corpus_path",
    "recipe_from_record",
    "EXAMPLES_DIR",
    "MAX_ITEMS",
    "MAX_TEXT",
]

EXAMPLES_DIR = Path(__file__).resolve().parent / "examples"
MAX_ITEMS = 500
"""At most this many ingredients, steps or per-step ingredients in one recipe."""
MAX_TEXT = 5000
"""At most this many characters in one ingredient, step or title."""


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
    """../shared/data/recipes/recipes.jsonl beside the checkout, or None where it is not."""
    shared = shared_dir()
    if shared is None:
        return None
    path = shared / "data" / "recipes" / "recipes.jsonl"
    return path if path.is_file() else None


_Text = Annotated[str, Field(min_length=1, max_length=MAX_TEXT)]


class RecipeRecord(StrictModel):
    """The schema of one recipe (a JSON/YAML file, or one line of recipes.jsonl).

    Corpus metadata (source, license, tags, ...) is accepted and not used; any other key is an error, so a typo
    like `stpes` is reported rather than ignored.
    """

    id: Annotated[str, Field(min_length=1, max_length=MAX_TEXT)] | None = None
    title: Annotated[str, Field(max_length=MAX_TEXT)] | None = None
    ingredients: Annotated[
        list[Annotated[str, Field(max_length=MAX_TEXT)]], Field(min_length=1, max_length=MAX_ITEMS)
    ]
    steps: Annotated[list[str], Field(min_length=1, max_length=MAX_ITEMS)]
    step_ingredients: (
        Annotated[
            list[Annotated[list[Annotated[str, Field(max_length=MAX_TEXT)]], Field(max_length=MAX_ITEMS)]],
            Field(max_length=MAX_ITEMS),
        ]
        | None
    ) = None
    # corpus metadata, see ../shared/data/recipes/SOURCE.md
    source: Any = None
    license: Any = None
    category: Any = None
    ingredients_structured: Any = None
    original_source: Any = None
    serves: Any = None
    tags: Any = None
    author: Any = None
    direction_notes: Any = None
    ingredient_groups: Any = None
    notes: Any = None

    @field_validator("steps")
    @classmethod
    def _steps_are_instructions(cls, steps: list[str]) -> list[str]:
        for i, step in enumerate(steps):
            if not step.strip():
                raise ValueError(
                    f"step {i + 1} of {len(steps)} is empty; every step must be a non-empty instruction"
                )
            if len(step) > MAX_TEXT:
                raise ValueError(f"step {i + 1} has {len(step)} characters (at most {MAX_TEXT})")
        return steps

    @field_validator("ingredients")
    @classmethod
    def _ingredients_are_named(cls, ingredients: list[str]) -> list[str]:
        # A recipe of nothing, or of blank lines, would be "served" without the robot doing anything.
        for i, item in enumerate(ingredients):
            if not item.strip():
                raise ValueError(
                    f"ingredient {i + 1} of {len(ingredients)} is empty; every ingredient must name an item"
                )
        return ingredients

    @model_validator(mode="after")
    def _one_list_per_step(self) -> RecipeRecord:
        if self.step_ingredients is not None and len(self.step_ingredients) != len(self.steps):
            raise ValueError(
                f"step_ingredients must have one list per step ({len(self.steps)}), got {len(self.step_ingredients)}"
            )
        return self


def recipe_from_record(record: Any, where: str) -> Recipe:
    """Validate one JSON/YAML record of the corpus's shape; RecipeError (one line) if it does not fit."""
    if record is None:
        raise RecipeError(f"{where}: is empty; a recipe is a mapping with ingredients and steps")
    if not isinstance(record, dict):
        raise RecipeError(
            f"{where}: a recipe must be a mapping with ingredients and steps (optional: id, title, step_ingredients), "
            f"got {type(record).__name__}"
        )
    r = validate(RecipeRecord, record, where, error=RecipeError)
    return Recipe(
        id=r.id if r.id is not None else where,
        title=r.title if r.title else (r.id if r.id is not None else where),
        ingredients=tuple(r.ingredients),
        steps=tuple(s.strip() for s in r.steps),
        step_ingredients=(
            tuple(tuple(x) for x in r.step_ingredients) if r.step_ingredients is not None else None
        ),
    )


def _unique_keys(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    """A JSON object whose keys are unique (json keeps the last of two silently; the YAML loader refuses them)."""
    seen: dict[str, Any] = {}
    for key, value in pairs:
        if key in seen:
            raise ValueError(f"the key {key!r} is given twice")
        seen[key] = value
    return seen


def _load_file(path: Path) -> Recipe:
    text = read_text(path, error=RecipeError)
    try:
        record = (
            json.loads(text, object_pairs_hook=_unique_keys) if path.suffix == ".json" else safe_load(text)
        )
    except RecursionError:
        raise RecipeError(f"{path}: nested too deeply to be a recipe") from None
    except yaml.YAMLError as exc:
        from scone_bt.config.yaml_io import yaml_syntax_error

        raise RecipeError(yaml_syntax_error(path, exc)) from None
    except (json.JSONDecodeError, ValueError, TypeError, OverflowError) as exc:
        kind = "JSON" if path.suffix == ".json" else "YAML"
        first = (str(exc).splitlines() or ["syntax error"])[0]
        raise RecipeError(f"{path}: not valid {kind} ({first})") from None
    return recipe_from_record(record, str(path))


def example_names() -> list[str]:
    return sorted(p.stem for p in EXAMPLES_DIR.glob("*.yaml"))


def load_recipe(id_or_path: str) -> Recipe:
    """Load a recipe from a JSON/YAML file, a bundled example ("example:<name>") or the shared corpus by id."""
    path = Path(id_or_path)
    if path.suffix in (".json", ".yaml", ".yml"):
        if not path.exists():  # a device or FIFO exists: read_text refuses it with what it is
            where = "" if path.is_absolute() else f" (looked for {path.absolute()})"
            raise RecipeError(f"recipe file not found: {path}{where}")
        return _load_file(path)
    if id_or_path.startswith("example:"):
        name = id_or_path.removeprefix("example:")
        file = EXAMPLES_DIR / f"{name}.yaml"
        if not file.is_file():
            raise RecipeError(
                f"unknown example recipe {name!r}; valid: {', '.join('example:' + n for n in example_names())}"
            )
        return _load_file(file)
    if path.is_file():  # an existing file of another kind: it is no corpus id either
        raise RecipeError(
            f"recipe {id_or_path!r}: a recipe file is .json, .yaml or .yml (got {path.suffix or 'no suffix'})"
        )
    if path.is_dir():  # a folder is no recipe id (ids have no '/'), nor a recipe file
        raise RecipeError(
            f"recipe {id_or_path!r} is a folder; give a recipe file (.json, .yaml), example:<name> "
            f"({', '.join(example_names())}) or a corpus id"
        )
    corpus = recipe_corpus_path()
    if corpus is None:
        raise RecipeError(
            f"recipe {id_or_path!r}: the corpus ../shared/data/recipes/recipes.jsonl is not here (set "
            f"SCONE_BT_SHARED to the folder that holds data/recipes/); use a JSON/YAML file or one of: "
            f"{', '.join('example:' + n for n in example_names())}"
        )
    ids = []
    for entry in corpus_entries(corpus):
        if entry.record.get("id") == id_or_path:
            return entry.recipe()
        ids.append(str(entry.record.get("id", "")))
    close = difflib.get_close_matches(id_or_path, ids, n=3, cutoff=0.5)
    hint = (
        f"; did you mean {', '.join(close)}?"
        if close
        else (f"; ids look like {ids[0]!r} (see {corpus})" if ids else f"; {corpus} holds none")
    )
    raise RecipeError(f"unknown recipe id {id_or_path!r} among {len(ids)} recipes{hint}")


@dataclass(frozen=True)
class CorpusEntry:
    """One line of the recipe corpus.

    Attributes:
        where: "<file>:<line>", for messages.
        record: The line's JSON object as it is (corpus metadata such as ``ingredients_structured`` included).
    """

    where: str
    record: dict[str, Any]

    def recipe(self) -> Recipe:
        """The record validated (`RecipeRecord`); RecipeError naming the file, the line and the key otherwise."""
        return recipe_from_record(self.record, self.where)


def corpus_entries(path: str | Path | None = None) -> Iterator[CorpusEntry]:
    """Every line of the recipe corpus (JSON Lines; default: `recipe_corpus_path()`), blank lines skipped.

    Each line must be a JSON object; a record's keys are checked when its `recipe()` is asked for.

    Raises:
        RecipeError: one line: the corpus is missing, unreadable or too large, or a line (named) is not a JSON
            object.
    """
    corpus = Path(path) if path is not None else recipe_corpus_path()
    if corpus is None or not corpus.exists():  # a device or FIFO exists: read_text refuses it with what it is
        raise RecipeError(f"recipe corpus not found: {corpus or '../shared/data/recipes/recipes.jsonl'}")
    for line_no, line in enumerate(
        read_text(corpus, error=RecipeError, limit=MAX_DATA_FILE_BYTES).splitlines(), 1
    ):
        if not line.strip():
            continue
        try:
            record = json.loads(line, object_pairs_hook=_unique_keys)
        except (json.JSONDecodeError, RecursionError):
            raise RecipeError(f"{corpus}:{line_no}: not valid JSON; the corpus file is damaged") from None
        except ValueError as exc:  # a key given twice (_unique_keys)
            raise RecipeError(f"{corpus}:{line_no}: {exc}; the corpus file is damaged") from None
        if not isinstance(record, dict):
            raise RecipeError(
                f"{corpus}:{line_no}: a recipe must be a JSON object; the corpus file is damaged"
            )
        yield CorpusEntry(f"{corpus}:{line_no}", record)


def read_corpus(path: str | Path | None = None) -> list[Recipe]:
    """Every recipe of the corpus, each validated (`corpus_entries`, then `CorpusEntry.recipe`)."""
    return [entry.recipe() for entry in corpus_entries(path)]
