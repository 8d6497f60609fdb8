"""Which catalogue products a recipe's steps need, i.e. what the robot can fetch for each step.

An ingredient line is normalised to one item ("1 15-oz can chickpeas, drained" → "chickpeas") and classified: food,
water or ice, a tool, or nothing. A food item is looked up in the catalogue (`ProductIndex.resolve`), in this order:

1. the most specific product named in the line that contains the item ("1 can diced tomatoes" → diced tomatoes,
   although "diced" is a preparation word the normaliser drops);
2. a product name or alias equal to the item, plural-insensitive;
3. the same after dropping grade words that do not change the product on the shelf ("sharp cheddar cheese",
   "unsweetened almond milk", "ground cinnamon");
4. the same after dropping a trailing part word: the product is where that part comes from ("lemon juice",
   "egg yolks", "garlic cloves", "basil leaves").

Each product is then assigned to the first step that mentions it (its name, an alias, or the recipe's own item
words); a product no step names is needed from the first step on (it is gathered before cooking starts).
"""

from __future__ import annotations

import difflib
import functools
import re
import unicodedata
from dataclasses import dataclass
from enum import Enum

from scone_bt.config import Catalogue
from scone_bt.recipes.normalise import ItemClass, classify_item, item_key, normalise_ingredient
from scone_bt.recipes.recipe import Recipe

__all__ = [
    "MatchRule",
    "ProductMatch",
    "StockedStep",
    "StockedRecipe",
    "ProductIndex",
    "match_catalogue",
    "stock_recipe",
]


# Grade words: the same product on the shelf whatever the word says.
def _words(text: str) -> frozenset[str]:
    return frozenset(text.split())


_GRADE_WORDS = _words(
    """
    whole ground pure organic natural plain regular fine coarse freshly sharp mild lean extra-lean baby mini
    low-sodium reduced-sodium no-salt-added sodium low-fat full-fat fat-free nonfat non-fat reduced-fat
    unsweetened tj's tjs trader joe's good-quality quality store-bought homemade canned tinned bottled
    mashed sized medium-sized stale toasted roasted preroasted crumbled quick-cooking hot little bit melty soft
    hard-boiled boiled mixed skim thick thin normal enriched tepid salted normandy unblanched unseasoned
    brewed strong
    italian english mexican asian persian scottish norwegian irish spanish greek-style
    """
)
# Fat grades written as two words ("fat free yoghurt", "whole fat milk"): the same product on the shelf.
_FAT_GRADE = re.compile(r"\b(?:(?:low|high|full|whole|reduced|non|no|medium)[ -]fat|fat[ -]free)\b")
# Part words: the product is the whole the part comes from.
_PART_WORDS = _words(
    "juice zest peel rind yolk white clove leave leaf sprig stalk rib floret wedge slice half segment crumb green"
    " puree flake wash cube piece meat fillet frond pod noodle"
)
# Generic products that stand for their whole kind: a kind the catalogue lacks ("scamorza cheese") is fetched
# as the generic product, the way a cook takes the cheese there is. Only heads where any kind is a fair stand-in:
# not "milk" (almond milk), "butter" (peanut butter), "pepper" (bell pepper) or "oil".
_KIND_HEADS = _words(
    "cheese mushroom potato onion apple rice sausage salmon peanut tomato bread chocolate honey pasta noodle tea"
    " lettuce chicken beef pork lamb beer olive cracker pear"
)
# Names that end in a kind head without being that kind: ginger beer is no beer, a prickly pear no pear.
_NOT_KINDS = frozenset(
    {"ginger beer", "root beer", "birch beer", "prickly pear", "alligator pear", "balsam pear"}
)
_WORD = re.compile(r"[a-z][a-z'&-]*")


class MatchRule(Enum):
    """How an item was matched to a product (the order `ProductIndex.lookup` tries them in)."""

    IN_LINE = "in_line"
    """A more specific product name in the ingredient line ("can diced tomatoes")."""
    EXACT = "exact"
    """The item is a product name or alias."""
    GRADE = "grade"
    """The item less grade words ("sharp cheddar" → cheddar cheese)."""
    PART = "part"
    """The item less a trailing part word ("lemon juice" → lemon), or the whole of "A of B" ("zest of lemon")."""
    KIND = "kind"
    """An unlisted kind of a generic product ("cotija cheese" → cheese, "porcini mushrooms" → mushrooms)."""
    SPELLING = "spelling"
    """A misspelt product name or alias, word for word ("broccli", "ground tumeric")."""


@dataclass(frozen=True)
class ProductMatch:
    """A catalogue product found for an item, and the rule that found it."""

    product: str
    rule: MatchRule


@dataclass(frozen=True)
class StockedStep:
    """One instruction and the catalogue objects that must be on the table before it can be done."""

    instruction: str
    objects: tuple[str, ...]


@dataclass(frozen=True)
class StockedRecipe:
    """A recipe mapped onto a kitchen.

    Attributes:
        recipe: The source recipe.
        steps: One StockedStep per recipe step (objects may be empty: the human does that step alone).
        needed: Every catalogue object the robot may fetch, in first-use order.
        unstocked: Food ingredient lines no catalogue product matches (the human brings those).
        not_fetchable: Ingredient lines that name water, ice or a tool (not fetched from a shelf).
        off_shelf: Stocked products that did not fit on the shelf (the human brings those too).
    """

    recipe: Recipe
    steps: tuple[StockedStep, ...]
    needed: tuple[str, ...]
    unstocked: tuple[str, ...]
    not_fetchable: tuple[str, ...] = ()
    off_shelf: tuple[str, ...] = ()


def _lower(text: str) -> str:
    """Lower case, accents folded, typographic apostrophes straightened."""
    return (
        unicodedata.normalize("NFKD", text.replace("\u2019", "'")).encode("ascii", "ignore").decode().lower()
    )


def _fold(text: str) -> str:
    return " ".join(_WORD.findall(_lower(text)))


class ProductIndex:
    """Looks up normalised items in a catalogue (built once per catalogue)."""

    def __init__(self, catalogue: Catalogue) -> None:
        self.catalogue = catalogue
        self._by_key: dict[str, str] = {}
        phrases: list[tuple[str, str]] = []
        for obj in catalogue.objects:
            for label in (obj.name, *obj.aliases):
                folded = _fold(label)
                self._by_key.setdefault(item_key(folded), obj.name)
                self._by_key.setdefault(item_key(folded.replace("-", " ")), obj.name)
                phrases.append((folded, obj.name))
        phrases.sort(key=lambda p: -len(p[0]))
        self._keys = sorted(self._by_key)
        self.step_patterns = _patterns(catalogue)
        # Multi-word aliases only; each is compiled on first use (`_word_pattern`): most never occur in a line.
        self._phrases = [(a, n) for a, n in phrases if " " in a]

    def _kind(self, head: str) -> str | None:
        """The generic product of a kind: the one named by the head word alone ("cheese", "potatoes")."""
        return self._by_key.get(head)

    def _exact(self, words: list[str]) -> str | None:
        return self._by_key.get(item_key(" ".join(words))) if words else None

    def resolve(self, item: str, line: str = "") -> str | None:
        """The catalogue product a normalised item names, or None (see the module docstring for the order)."""
        match = self.lookup(item, line)
        return match.product if match is not None else None

    def lookup(self, item: str, line: str = "") -> ProductMatch | None:
        """Like `resolve`, with the rule that matched."""
        match = self._lookup(item, line)
        if match is None and "-" in item:  # "red-pepper flakes", "all-spice": the name written with a hyphen
            match = self._lookup(item.replace("-", " "), line)
        return match

    def _lookup(self, item: str, line: str) -> ProductMatch | None:
        words = _WORD.findall(_lower(item))
        if not words:
            return None
        if line and (found := self._in_line(words, line)) is not None:
            return found
        graded = [
            w for w in _WORD.findall(_FAT_GRADE.sub(" ", _lower(item))) if w not in _GRADE_WORDS
        ] or words
        # "unsalted" is a grade only where no unsalted product exists ("unsalted almonds", not unsalted butter).
        plain = [w for w in graded if w != "unsalted"] or graded
        candidates = ((words, MatchRule.EXACT), (graded, MatchRule.GRADE), (plain, MatchRule.GRADE))
        for candidate, rule in candidates:
            if (hit := self._exact(candidate)) is not None:
                return ProductMatch(hit, rule)
            part_of = len(candidate) > 1 and item_key(candidate[-1]) in _PART_WORDS
            if part_of and (hit := self._exact(candidate[:-1])) is not None:
                return ProductMatch(hit, MatchRule.PART)
        joint = next((w for w in ("of", "from") if w in graded[1:-1]), None)
        if joint is not None:  # "zest of lemon", "juice from lemon", "twigs of thyme"; "cheese of choice"
            at = graded.index(joint)
            whole, part = graded[at + 1 :], graded[:at]
            if whole and whole[-1] in ("choice", "variety", "kind"):
                whole = part
            if (hit := self._exact(whole)) is not None:
                return ProductMatch(hit, MatchRule.PART)
        key = item_key(" ".join(graded))
        head = key.split()[-1]
        kind_of = (
            head in _KIND_HEADS and len(key.split()) > 1 and " ".join(key.split()[-2:]) not in _NOT_KINDS
        )
        if kind_of and (hit := self._kind(head)) is not None:
            return ProductMatch(hit, MatchRule.KIND)
        if len(key) >= 6:
            for close in difflib.get_close_matches(key, self._keys, n=5, cutoff=0.8):
                if _same_words_misspelt(key.split(), close.split()):
                    return ProductMatch(self._by_key[close], MatchRule.SPELLING)
        return None

    def _in_line(self, words: list[str], line: str) -> ProductMatch | None:
        """A product's phrase around the item's first mention in its line: "milk or almond milk" is milk."""
        head = item_key(words[-1])
        text = _fold(re.sub(r"\([^)]*\)", " ", line))
        first = re.search(rf"\b{re.escape(words[-1])}\b", text)
        if first is None:
            return None
        for alias, name in self._phrases:
            if alias not in text or head not in {item_key(w) for w in alias.split()}:
                continue
            for m in _word_pattern(alias).finditer(text):
                if m.start() <= first.start() < m.end():
                    exact = self._exact(words)
                    return ProductMatch(name, MatchRule.EXACT if exact == name else MatchRule.IN_LINE)
        return None


def _same_words_misspelt(words: list[str], target: list[str]) -> bool:
    """Word for word the same but for small misspellings ("broccli" / "broccoli"; not "rye flour" / "rice flour")."""
    return len(words) == len(target) and all(
        w == t
        or (
            len(t) >= 5
            and w[0] == t[0]
            and abs(len(w) - len(t)) <= 2
            and difflib.SequenceMatcher(None, w, t).ratio() >= 0.8
        )
        for w, t in zip(words, target, strict=True)
    )


@functools.cache
def _word_pattern(alias: str) -> re.Pattern[str]:
    """The alias as a whole-word pattern, compiled once per process (a catalogue has thousands of aliases and a
    text names a few: compiling them all up front cost half a second before the robot's first decision)."""
    return re.compile(rf"\b{re.escape(alias)}\b")


def _patterns(catalogue: Catalogue) -> list[tuple[str, str]]:
    """(alias, product) for every name and alias (lower case), longest first."""
    pairs = [(alias.lower(), obj.name) for obj in catalogue.objects for alias in (obj.name, *obj.aliases)]
    # Longest alias first so "olive oil" wins over "oil" and "canned tomatoes" over "tomatoes".
    pairs.sort(key=lambda p: -len(p[0]))
    return pairs


def match_catalogue(text: str, catalogue: Catalogue) -> list[str]:
    """Catalogue objects named in a text, in order of first mention, each once."""
    lowered = text.lower()
    # A whole-word match needs the alias as a substring: only those are compiled and searched.
    patterns = [(_word_pattern(a), n) for a, n in _patterns(catalogue) if a in lowered]
    return [name for _, name in _mentions(lowered, patterns)]


def _mentions(lowered: str, patterns: list[tuple[re.Pattern[str], str]]) -> list[tuple[int, str]]:
    """(position, product) of each product named in a lower-case text, first mention only, in text order."""
    hits: list[tuple[int, str]] = []
    taken = [False] * len(lowered)
    for pattern, name in patterns:
        for m in pattern.finditer(lowered):
            if any(taken[m.start() : m.end()]):
                continue
            for i in range(m.start(), m.end()):
                taken[i] = True
            hits.append((m.start(), name))
    first: dict[str, int] = {}
    for pos, name in sorted(hits):
        first.setdefault(name, pos)
    return sorted(((p, n) for n, p in first.items()), key=lambda h: h[0])


def stock_recipe(
    recipe: Recipe, catalogue: Catalogue, capacity: int | None = None, index: ProductIndex | None = None
) -> StockedRecipe:
    """Map ingredients to catalogue products and assign each product to the first step that uses it.

    Args:
        recipe: The recipe.
        catalogue: What the kitchen can stock.
        capacity: Shelf slots for the recipe's products; products past it (in first-use order) are left off the
            shelf, listed in ``off_shelf`` and dropped from the steps (the human brings them).
        index: A prebuilt index of the same catalogue (saves rebuilding it for many recipes).
    """
    index = index or ProductIndex(catalogue)
    products: dict[str, str] = {}  # product → the recipe's item for it
    unstocked: list[str] = []
    not_fetchable: list[str] = []
    for line in recipe.ingredients:
        item = normalise_ingredient(line)
        kind = classify_item(item)
        if kind in (ItemClass.WATER, ItemClass.TOOL):
            not_fetchable.append(line)
            continue
        product = index.resolve(item, line) if kind is ItemClass.FOOD else None
        if product is None:
            if kind is ItemClass.FOOD:
                unstocked.append(line)
            continue
        products.setdefault(product, item)
    # A step names a product by its catalogue name or alias, or by the words the recipe itself used for it.
    # Every catalogue name stays in play (a longer one blocks a shorter inside it: "peanut butter" is not
    # butter), but only those that occur in the recipe's text at all are searched.
    texts = [
        (" ; ".join(recipe.step_ingredients[i]) + " ; " + s)
        if recipe.step_ingredients is not None and recipe.step_ingredients[i]
        else s
        for i, s in enumerate(recipe.steps)
    ]
    everything = " ".join(texts).lower()
    patterns = [(_word_pattern(alias), n) for alias, n in index.step_patterns if alias in everything]
    for product, item in products.items():
        for label in {item, item.split()[-1]} if item else ():
            patterns.append((re.compile(rf"\b{re.escape(label)}s?\b"), product))
    patterns.sort(key=lambda p: -len(p[0].pattern))
    used: set[str] = set()
    per_step: list[list[str]] = []
    for text in texts:
        mentioned = [n for _, n in _mentions(text.lower(), patterns) if n in products and n not in used]
        used.update(mentioned)
        per_step.append(mentioned)
    if per_step:
        per_step[0][:0] = [p for p in products if p not in used]
    order = [n for s in per_step for n in s]
    keep = set(order if capacity is None else order[: max(capacity, 0)])
    steps = tuple(
        StockedStep(instruction, tuple(n for n in names if n in keep))
        for instruction, names in zip(recipe.steps, per_step, strict=True)
    )
    return StockedRecipe(
        recipe=recipe,
        steps=steps,
        needed=tuple(n for n in order if n in keep),
        unstocked=tuple(unstocked),
        not_fetchable=tuple(not_fetchable),
        off_shelf=tuple(n for n in order if n not in keep),
    )
