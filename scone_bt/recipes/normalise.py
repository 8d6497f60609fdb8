"""Ingredient strings → fetchable items ("1 can chickpeas, drained" → "chickpeas").

Hand-written rules, not a learnt parser: ``ingredient-parser-nlp`` (the usual library) needs NLTK's POS-tagger
data, which it downloads at run time and no PyPI package ships, so it cannot run offline here. The rules strip,
in order: parentheticals, trailing notes (after a comma, a sentence stop, "for …", "to taste"), quantities with
their units and containers ("1 15-oz can", "5-6 cloves of", "~150g"), and preparation words ("chopped",
"fresh", "large"). Of two alternatives ("cilantro or parsley") the first is kept; of a list ("salt and pepper")
the first item.
"""

from __future__ import annotations

import re
import unicodedata

__all__ = ["normalise_ingredient", "is_fetchable", "item_key"]

_UNITS = (
    "cups?|c|t|table ?spoons?|tea ?spoons?|spoons?|tbsps?|tbs|tbl|tb|tsps?|teaspoons?|grams?|g|gr|kilograms?|kgs?|millilit(?:re|er)s?|ml|"
    "centilit(?:re|er)s?|cl|decilit(?:re|er)s?|dl|lit(?:re|er)s?|l|ounces?|oz|fl\\.? ?oz|pounds?|lbs?|quarts?|qts?|"
    "pints?|pts?|gallons?|gals?|inch(?:es)?|in|cm|mm|pinch(?:es)?|dash(?:es)?|drops?|handfuls?|bunch(?:es)?|"
    "cans?|tins?|jars?|bottles?|packages?|pkgs?|packets?|pouch(?:es)?|bags?|boxes|box|containers?|cartons?|sticks?|"
    "cloves?|heads?|sprigs?|stalks?|slices?|pieces?|pcs?|sheets?|knobs?|blocks?|scoops?|splash(?:es)?|"
    "glugs?|shots?|wedges?|fillets?|leaves|leaf|ears?|rashers?|strips?|cubes?|bars?|envelopes?|servings?|"
    "squares?|dollops?|sachets?|punnets?|loaf|loaves|links?|bulbs?"
)


def _words(text: str) -> frozenset[str]:
    return frozenset(text.split())


# Words about size, state or preparation that do not change which container the robot fetches.
_PREP_WORDS = _words(
    """
    chopped diced minced sliced thinly thickly finely roughly coarsely freshly fresh large medium small big
    extra-large jumbo peeled drained rinsed softened melted cooled beaten whisked sifted packed heaping heaped
    level lightly firmly shredded grated crushed halved quartered cubed trimmed seeded deseeded pitted cored
    optional divided room temperature warm cold chilled frozen thawed cooked uncooked raw dry dried good quality
    organic plain about approximately approx roughly generous scant pinch some a an the few more additional
    overfilled half quarter whole-kernel
    your favourite favorite store-bought homemade prepared ripe firm to taste softly boneless skinless
    julienned torn juiced zested cut into
    """
)
_ADJ_ALTERNATIVES = _words(
    """
    red green yellow orange white black brown dark light sweet smooth crunchy salted unsalted hot mild fresh
    dried whole low-fat full-fat nonfat skim regular large small medium fine coarse
    """
)
_NOT_FETCHABLE = frozenset(
    {
        "water",
        "ice",
        "ice cubes",
        "boiling water",
        "hot water",
        "cold water",
        "warm water",
        "tap water",
        "thermometer",
        "cheesecloth",
        "parchment",
        "parchment paper",
        "baking paper",
        "foil",
        "aluminum foil",
        "aluminium foil",
        "plastic wrap",
        "cling film",
        "skewers",
        "toothpicks",
        "kitchen twine",
        "twine",
        "paper towels",
        "muffin liners",
        "cupcake liners",
    }
)

_NUMBER = r"(?:\d+(?:[.,]\d+)?(?:\s*/\s*\d+)?|[¼½¾⅓⅔⅛⅜⅝⅞⅕])"
_QUANTITY = re.compile(
    rf"(?<![a-z]){_NUMBER}(?:\s*(?:-|–|to|or)\s*{_NUMBER})*(?:\s*-?\s*(?:{_UNITS})\b\.?)?(?:\s+of\b)?",
    re.IGNORECASE,
)
_UNIT_ALONE = re.compile(rf"^(?:a|an|one|some|few)?\s*(?:{_UNITS})\b\.?(?:\s+of\b)?\s*", re.IGNORECASE)
_PAREN = re.compile(r"\([^)]*\)|\[[^\]]*\]")
_CUT = re.compile(
    r",|;|:|/|\*|\.\s|\.$|\s-\s|\s–\s|\bfor\b|\bper\b|\bwithout\b|\bor less\b|\bor more\b|\bto taste\b|\bas needed\b|\bif desired\b|\bplus\b|\bsuch as\b"
)
_WORD = re.compile(r"[a-z][a-z'&-]*")


def _ascii_fold(text: str) -> str:
    # Keep fraction glyphs (the quantity pattern knows them); fold accents ("Gruyère" → "gruyere").
    out = []
    for ch in text:
        if ch in "¼½¾⅓⅔⅛⅜⅝⅞⅕":
            out.append(ch)
        else:
            out.append(unicodedata.normalize("NFKD", ch).encode("ascii", "ignore").decode())
    return "".join(out)


def _strip_prep(words: list[str]) -> list[str]:
    kept = [w for w in words if w not in _PREP_WORDS]
    return kept or words[-1:]


def _pick_alternative(text: str) -> str:
    # "brown or green lentils": the left side only qualifies the right side's noun.
    if " or " in f" {text} ":
        left, _, right = text.partition(" or ")
        left, right = left.strip(), right.strip()
        if left and right and len(left.split()) == 1 and left in _ADJ_ALTERNATIVES and len(right.split()) > 1:
            return right
        return left or right
    return text


def normalise_ingredient(text: str) -> str:
    """The fetchable item an ingredient string names, lower case ("" when it names none).

    Args:
        text: An ingredient line with optional quantity, unit and notes, e.g. "1 15-oz can chickpeas, drained".

    Returns:
        The item, e.g. "chickpeas"; "" for strings without any food word left ("2 Tbsp", "").
    """
    s = _ascii_fold(text).lower().replace("&", " and ").replace("~", " ")
    s = _PAREN.sub(" ", s)
    s = s.replace("(", " ").replace(")", " ").replace("and/or", "or")
    s = re.sub(r"\b(?:half|quarter|third)\s+(?:of\s+)?an?\b", " ", s)
    s = _QUANTITY.sub(" ", s)
    s = re.sub(r"\s+", " ", s).strip()
    s = _CUT.split(f"{s} ", maxsplit=1)[0]
    s = re.sub(r"^(?:a|an|one|some|few|couple|a couple)\s+(?:of\s+)?", "", s.strip())
    for _ in range(2):  # "a jar of" then "a bunch of"
        s = _UNIT_ALONE.sub("", s).strip()
    s = _pick_alternative(s)
    s = s.partition(" and ")[0] if " and " in f" {s} " else s
    s = s.partition(" with ")[0]
    words = _WORD.findall(s)
    while words and words[0] in ("of", "and", "or"):
        words = words[1:]
    if not words:
        return ""
    words = _strip_prep(words)
    return " ".join(words).strip(" -'")


def is_fetchable(item: str) -> bool:
    """Whether a normalised item is something a robot fetches from a shelf (not water, ice or a tool)."""
    return bool(item) and item not in _NOT_FETCHABLE


def item_key(item: str) -> str:
    """A plural-insensitive key so "egg" and "eggs" count as one item in a kitchen."""
    words = item.split()
    if not words:
        return ""
    last = words[-1]
    if last.endswith("ies") and len(last) > 4:
        last = last[:-3] + "y"
    elif last.endswith(("oes", "ches", "shes", "sses", "xes")):
        last = last[:-2]
    elif last.endswith("s") and not last.endswith(("ss", "us", "is")) and len(last) > 3:
        last = last[:-1]
    return " ".join([*words[:-1], last])
