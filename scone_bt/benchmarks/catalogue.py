"""``scone-bench catalogue``: the grocery catalogue against the recipe corpus.

Measures, over the 1,227 recipes of ../shared/data/recipes/recipes.jsonl:

- normalisation accuracy on the ``nw:`` recipes, whose ``ingredients_structured`` names (the authors' Cooklang
  markup) are the labels, and on two hand-labelled samples of free-text ``pdr:`` lines (tools/data/normalise/):
  one the rules were revised on, and a held-out one labelled afterwards;
- mention coverage: the fraction of ingredient lines that name a catalogue product or something not fetched from
  a shelf (water, ice, a tool);
- the fraction of recipes with every fetchable ingredient stocked, and of recipes whose stocked products plus four
  distractors fit the kitchen's shelf slots.

The benchmark is deterministic (no sampling), so there is no seed to set.

    scone-bench catalogue --json out.json
"""

from __future__ import annotations

import argparse
import json
import re
import statistics
import time
from collections import Counter
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from scone_bt.argparsing import path_arg
from scone_bt.benchmarks.progress import progress_bar
from scone_bt.errors import RecipeError
from scone_bt.reporting import emit_report
from scone_bt.resources import repo_root

__all__ = [
    "register",
    "run_catalogue_benchmark",
    "label_item",
    "DISTRACTORS",
    "default_pdr_labels",
    "default_pdr_heldout",
]

DISTRACTORS = 4
"""Products not in the recipe that share the shelf with it (the episode's default is larger; the issue asks 4)."""


def _normalise_data(name: str) -> Path | None:
    root = repo_root()
    path = root / "tools" / "data" / "normalise" / name if root is not None else None
    return path if path is not None and path.is_file() else None


def default_pdr_labels() -> Path | None:
    """tools/data/normalise/pdr_labels.jsonl in a checkout (the normaliser's rules were revised on it), else None."""
    return _normalise_data("pdr_labels.jsonl")


def default_pdr_heldout() -> Path | None:
    """tools/data/normalise/pdr_labels_heldout.jsonl (labelled after the last rule change, never tuned on)."""
    return _normalise_data("pdr_labels_heldout.jsonl")


def label_item(name: str) -> str:
    """The item a Cooklang ingredient name labels, by the benchmark's fixed label rule.

    Cooklang names carry notes the way people write them ("unsalted butter, softened", "cinnamon (optional)",
    "spinach or kale"). The label is the name's part before a comma, without parentheses, its first alternative,
    and without the preparation words of the normaliser's vocabulary ("chopped", "fresh"): the item the robot
    fetches. Comparison is plural-insensitive (`item_key`).
    """
    from scone_bt.recipes import normalise as n

    s = n._ascii_fold(name).lower().replace("\u2019", "'")
    s = re.sub(r"\([^)]*\)", " ", s).split(",")[0]
    s = re.sub(r"\bof (?:your )?(?:choice|favou?rite)\b", " ", s)
    s = n._pick_alternative(re.sub(r"\s+", " ", s).strip())
    words = n._WORD.findall(s)
    return n.item_key(" ".join(n._strip_prep(words))) if words else ""


@dataclass(frozen=True)
class _Accuracy:
    correct: int
    total: int
    errors: tuple[tuple[str, str, str], ...]  # (line, label, normalised)

    @property
    def value(self) -> float:
        return self.correct / self.total if self.total else 0.0


def _accuracy(pairs: list[tuple[str, str]], keep_errors: int = 8) -> _Accuracy:
    from scone_bt.recipes.normalise import item_key, normalise_ingredient

    errors: list[tuple[str, str, str]] = []
    correct = 0
    for line, label in pairs:
        got = item_key(normalise_ingredient(line))
        if got == label:
            correct += 1
        elif len(errors) < keep_errors:
            errors.append((line, label, got))
    return _Accuracy(correct, len(pairs), tuple(errors))


def _read_pdr_labels(path: Path) -> list[tuple[str, str]]:
    from scone_bt.recipes.normalise import item_key

    pairs = []
    for no, raw in enumerate(path.read_text().splitlines(), 1):
        if not raw.strip():
            continue
        try:
            rec = json.loads(raw)
            pairs.append((str(rec["line"]), item_key(str(rec["item"]).lower().strip())))
        except (json.JSONDecodeError, KeyError, TypeError) as exc:
            raise RecipeError(f"{path}:{no}: expected {{'line': ..., 'item': ...}} ({exc})") from None
    return pairs


@dataclass(frozen=True)
class _Normalisation:
    """Normalisation accuracy on the nw: labels and on the two hand-labelled pdr: samples (None: no file)."""

    nw: _Accuracy
    pdr: _Accuracy | None
    heldout: _Accuracy | None


@dataclass(frozen=True)
class _Stocking:
    """Ingredient mentions by class and stocking rule, and per recipe how many stocked products it needs.

    Attributes:
        kinds: Mentions per class ("stocked", "unstocked", or an `ItemClass` value).
        rules: Stocked mentions per matching rule.
        unstocked_items: Normalised items that name food the catalogue does not stock.
        fully: Recipes with every fetchable ingredient stocked.
        fits: Recipes whose stocked products plus DISTRACTORS fit the shelf slots.
        needed_counts: Stocked products per recipe, in corpus order.
        slots: The kitchen's shelf slots.
    """

    kinds: Counter[str]
    rules: Counter[str]
    unstocked_items: Counter[str]
    fully: int
    fits: int
    needed_counts: list[int]
    slots: int


def _normalisation(
    records: list[dict[str, Any]], pdr_labels: Path | None, pdr_heldout: Path | None
) -> _Normalisation:
    """Score the normaliser on the nw: recipes' Cooklang labels and the labelled pdr: samples."""
    nw_pairs = [
        (line, label_item(s["name"]))
        for r in records
        if str(r.get("id", "")).startswith("nw:") and r.get("ingredients_structured")
        for line, s in zip(r["ingredients"], r["ingredients_structured"], strict=False)
    ]
    pdr_path = pdr_labels or default_pdr_labels()
    pdr = _accuracy(_read_pdr_labels(pdr_path)) if pdr_path is not None else None
    heldout_path = pdr_heldout or (default_pdr_heldout() if pdr_labels is None else None)
    heldout = _accuracy(_read_pdr_labels(heldout_path)) if heldout_path is not None else None
    return _Normalisation(_accuracy(nw_pairs), pdr, heldout)


def _stocking(recipes: list[Any], cfg: Any, bar: Any) -> _Stocking:
    """Classify and match every ingredient line, and stock every recipe (one bar step per recipe)."""
    from scone_bt.recipes.normalise import ItemClass, classify_item, normalise_ingredient
    from scone_bt.stocking.needs import ProductIndex, stock_recipe

    cat = cfg.catalogue
    index = ProductIndex(cat)
    slots = len(cfg.scene.shelf_slots())
    kinds: Counter[str] = Counter()
    rules: Counter[str] = Counter()
    unstocked_items: Counter[str] = Counter()
    fully = fits = 0
    needed_counts = []
    for recipe in recipes:
        for line in recipe.ingredients:
            item = normalise_ingredient(line)
            kind = classify_item(item)
            if kind is ItemClass.FOOD:
                match = index.lookup(item, line)
                if match is None:
                    kinds["unstocked"] += 1
                    unstocked_items[item] += 1
                else:
                    kinds["stocked"] += 1
                    rules[match.rule.value] += 1
            else:
                kinds[kind.value] += 1
        stocked = stock_recipe(recipe, cat, index=index)
        needed_counts.append(len(stocked.needed))
        fully += not stocked.unstocked
        fits += len(stocked.needed) + DISTRACTORS <= slots
        bar.update()
    return _Stocking(kinds, rules, unstocked_items, fully, fits, needed_counts, slots)


def _normalisation_report(norm: _Normalisation) -> dict[str, Any]:
    """The report's accuracy figures and error samples."""
    nw, pdr, heldout = norm.nw, norm.pdr, norm.heldout
    return {
        "normalisation_accuracy": round(nw.value, 4),
        "normalisation_lines": nw.total,
        "pdr_sample_accuracy": round(pdr.value, 4) if pdr is not None else None,
        "pdr_sample_lines": pdr.total if pdr is not None else 0,
        "pdr_heldout_accuracy": round(heldout.value, 4) if heldout is not None else None,
        "pdr_heldout_lines": heldout.total if heldout is not None else 0,
    }


def _error_samples(norm: _Normalisation) -> dict[str, Any]:
    """A few lines each sample normalised wrongly: (line, label, normalised)."""
    return {
        "nw_errors_sample": [list(e) for e in norm.nw.errors],
        "pdr_errors_sample": [list(e) for e in norm.pdr.errors] if norm.pdr is not None else [],
        "pdr_heldout_errors_sample": [list(e) for e in norm.heldout.errors]
        if norm.heldout is not None
        else [],
    }


def _stocking_report(st: _Stocking, recipes: int) -> dict[str, Any]:
    """The report's coverage and shelf figures."""
    from scone_bt.recipes.normalise import ItemClass

    kinds, needed_counts = st.kinds, st.needed_counts
    mentions = sum(kinds.values())
    covered = kinds["stocked"] + kinds[ItemClass.WATER.value] + kinds[ItemClass.TOOL.value]
    return {
        "recipes": recipes,
        "mentions": mentions,
        "mention_coverage": round(covered / mentions, 4) if mentions else 0.0,
        "mentions_by_class": {k: kinds[k] for k in ("stocked", "water", "tool", "unstocked", "nothing")},
        "stocked_mentions_by_rule": {
            r: st.rules[r] for r in ("exact", "in_line", "grade", "part", "kind", "spelling")
        },
        "recipes_fully_stocked_fraction": round(st.fully / recipes, 4) if recipes else 0.0,
        "recipes_fit_shelf_fraction": round(st.fits / recipes, 4) if recipes else 0.0,
        "shelf_slots": st.slots,
        "distractors": DISTRACTORS,
        "stocked_products_per_recipe": {
            "median": statistics.median(needed_counts) if needed_counts else 0,
            "p90": sorted(needed_counts)[int(0.9 * (len(needed_counts) - 1))] if needed_counts else 0,
            "max": max(needed_counts, default=0),
        },
        "top_unstocked_items": dict(st.unstocked_items.most_common(15)),
    }


def run_catalogue_benchmark(
    kitchen: str = "kitchen",
    catalogues: tuple[str, ...] = (),
    corpus: Path | None = None,
    pdr_labels: Path | None = None,
    pdr_heldout: Path | None = None,
    progress: bool = False,
) -> dict[str, Any]:
    """Every figure of the catalogue benchmark as one JSON-ready mapping (``progress``: a bar on stderr)."""
    from scone_bt.config import load_kitchen
    from scone_bt.config.schema import check_input_file
    from scone_bt.recipes.recipe import corpus_entries

    for flag, given in (("--pdr-labels", pdr_labels), ("--pdr-heldout", pdr_heldout)):
        if given is not None:  # before the corpus is read: a missing file was a traceback at the end
            try:
                check_input_file(given, RecipeError)
            except RecipeError as exc:
                raise RecipeError(f"{flag} {exc}") from None
    wall0, cpu0 = time.perf_counter(), time.process_time()
    cfg = load_kitchen(kitchen, catalogues)
    cat = cfg.catalogue
    entries = list(corpus_entries(corpus))
    records = [e.record for e in entries]
    recipes = [e.recipe() for e in entries]
    bar = progress_bar(len(recipes), "recipes", not progress, unit="recipe")
    bar.set_postfix_str("normalisation accuracy")
    norm = _normalisation(records, pdr_labels, pdr_heldout)
    bar.set_postfix_str("stocking")
    stocking = _stocking(recipes, cfg, bar)
    bar.close()
    return {
        "products": len(cat),
        "families": len(cat.families()),
        "products_per_family": dict(Counter(o.family for o in cat.objects)),
        **_normalisation_report(norm),
        **_stocking_report(stocking, len(recipes)),
        **_error_samples(norm),
        "wall_s": round(time.perf_counter() - wall0, 2),
        "cpu_s": round(time.process_time() - cpu0, 2),
    }


def _run(args: argparse.Namespace) -> int:
    result = run_catalogue_benchmark(
        kitchen=args.kitchen,
        catalogues=tuple(args.catalogue),
        corpus=args.corpus,
        pdr_labels=args.pdr_labels,
        pdr_heldout=args.pdr_heldout,
        progress=not args.quiet,
    )
    emit_report(result, args.json, force=args.force)
    return 0


def register(subparsers: Any) -> None:
    """Add ``catalogue`` to scone-bench."""
    p = subparsers.add_parser(
        "catalogue",
        help="catalogue size, ingredient normalisation accuracy and recipe coverage (JSON)",
        description=__doc__.split("\n\n")[0].replace("``", ""),
    )
    p.add_argument(
        "--kitchen", default="kitchen", help="kitchen file in perception/ or a path (default: kitchen)"
    )
    p.add_argument(
        "--catalogue",
        action="append",
        default=[],
        metavar="FILE",
        help="one more product file merged into the kitchen's catalogue (repeatable)",
    )
    p.add_argument(
        "--corpus", type=path_arg, help="recipes.jsonl (default ../shared/data/recipes/recipes.jsonl)"
    )
    p.add_argument(
        "--pdr-labels",
        type=path_arg,
        help="hand-labelled pdr: lines, JSONL with line and item (default tools/data/normalise/pdr_labels.jsonl)",
    )
    p.add_argument(
        "--pdr-heldout",
        type=path_arg,
        help="a second labelled file never tuned on (default tools/data/normalise/pdr_labels_heldout.jsonl)",
    )
    p.add_argument("--json", metavar="FILE", help="also write the JSON here")
    p.add_argument("--quiet", action="store_true", help="no progress bar on stderr")
    p.set_defaults(func=_run)
