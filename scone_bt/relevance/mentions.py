"""Which items a text names: whole names or their wordings in singular or plural, or an unambiguous head noun.

"Add the minced garlic" names "garlic"; "add the liver" names "beef liver" when no other item ends in "liver";
"add the oil" names no item when both "canola oil" and "sesame oil" are candidates (``ambiguous_heads`` lists
those). Matching works on ASCII-folded, lower-cased words, so "Jalapeño" matches "jalapeno".
"""

from __future__ import annotations

import re
import unicodedata
from collections import Counter
from collections.abc import Iterable, Mapping

from scone_bt.recipes.normalise import item_key

__all__ = ["fold_text", "surface_forms", "mentioned_items", "ambiguous_heads", "negated_items"]

# A mention right after one of these words is a mention of what not to use ("without the garlic").
_NEGATORS = re.compile(
    r"\b(?:without|except|instead of|no|not|omit|omitting|skip|reserve|reserving)\s+(?:the\s+)?$"
)


def fold_text(text: str) -> str:
    """ASCII-folded, lower-cased words separated by single spaces, padded with a space at both ends."""
    folded = unicodedata.normalize("NFKD", text).encode("ascii", "ignore").decode()
    return " " + " ".join(re.sub(r"[^a-z0-9' -]+", " ", folded.lower()).split()) + " "


def surface_forms(item: str) -> set[str]:
    """Singular and plural spellings of an item name ("berry" → berry, berries)."""
    key = item_key(item)
    forms = {item.lower(), key}
    for base in (item.lower(), key):
        if base.endswith("y") and not base.endswith(("ay", "ey", "oy", "uy")):
            forms.add(base[:-1] + "ies")
        elif base.endswith(("ch", "sh", "s", "x")):
            forms.add(base + "es")
        elif base.endswith("o"):  # tomatoes, but jalapenos
            forms |= {base + "es", base + "s"}
        else:
            forms.add(base + "s")
    return {f for f in forms if f}


def _forms(item: str, wordings: Mapping[str, Iterable[str]] | None) -> set[str]:
    forms = surface_forms(item)
    for w in (wordings or {}).get(item, ()):
        forms |= surface_forms(w)
    return forms


def _heads(items: list[str]) -> Counter[str]:
    return Counter(item_key(i.split()[-1]) for i in items if i.split())


def mentioned_items(
    text: str,
    items: Iterable[str],
    head_nouns: bool = True,
    wordings: Mapping[str, Iterable[str]] | None = None,
) -> list[str]:
    """Items ``text`` names, in the order given.

    Args:
        text: A recipe step.
        items: Candidate item names.
        head_nouns: Also accept an item's last word when no other candidate ends in it.
        wordings: Item → other names the recipe uses for it (its ingredient lines' items, aliases).
    """
    items = list(items)
    lowered = fold_text(text)
    heads = _heads(items)
    found = []
    for item in items:
        forms = _forms(item, wordings)
        head = item.split()[-1] if item.split() else ""
        if head_nouns and " " in item and heads[item_key(head)] == 1:
            forms |= surface_forms(head)
        if any(f" {form} " in lowered for form in forms):
            found.append(item)
    return found


def ambiguous_heads(
    text: str, items: Iterable[str], wordings: Mapping[str, Iterable[str]] | None = None
) -> list[tuple[str, ...]]:
    """Groups of candidates that share a head noun the text uses on its own ("the oil": canola oil, sesame
    oil), where the text names none of the group in full."""
    items = list(items)
    lowered = fold_text(text)
    by_head: dict[str, list[str]] = {}
    for item in items:
        if " " in item:
            by_head.setdefault(item_key(item.split()[-1]), []).append(item)
    groups = []
    for head, group in by_head.items():
        if len(group) < 2 or not any(f" {f} " in lowered for f in surface_forms(head)):
            continue
        if mentioned_items(text, group, head_nouns=False, wordings=wordings):
            continue
        groups.append(tuple(group))
    return groups


def negated_items(
    text: str, items: Iterable[str], wordings: Mapping[str, Iterable[str]] | None = None
) -> set[str]:
    """Items every mention of which follows "without", "except", "reserve", … ("toss without the cheese")."""
    lowered = fold_text(text)
    out = set()
    for item in items:
        spans = [
            m.start() for form in _forms(item, wordings) for m in re.finditer(re.escape(f" {form} "), lowered)
        ]
        if spans and all(_NEGATORS.search(lowered[: s + 1]) for s in spans):
            out.add(item)
    return out
