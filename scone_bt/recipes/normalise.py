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
from enum import Enum

__all__ = ["ItemClass", "classify_item", "normalise_ingredient", "is_fetchable", "item_key"]

_UNITS = (
    "cups?|c|t|table ?spoons?|tea ?spoons?|spoons?|tblsps?|tbsps?|tbs|tbl|tb|tsps?|teaspoons?|grams?|g|gr|kilograms?|kgs?|millilit(?:re|er)s?|ml|"
    "centilit(?:re|er)s?|cl|decilit(?:re|er)s?|dl|lit(?:re|er)s?|l|ounces?|oz|fl\\.? ?oz|pounds?|lbs?|quarts?|qts?|"
    "pints?|pts?|gallons?|gals?|inch(?:es)?|in|cm|mm|pinch(?:es)?|dash(?:es)?|drops?|handfull?s?|bunch(?:es)?|"
    "cans?|tins?|jars?|bottles?|packages?|pkgs?|packets?|pouch(?:es)?|bags?|boxes|box|containers?|cartons?|sticks?|"
    "cloves?|heads?|sprigs?|stalks?|slices?|pieces?|pcs?|sheets?|knobs?|blocks?|scoops?|splash(?:es)?|"
    "glugs?|shots?|wedges?|fillets?|leaves|leaf|ears?|rashers?|strips?|cubes?|bars?|envelopes?|servings?|"
    "squares?|dollops?|sachets?|punnets?|loaf|loaves|links?|bulbs?|dozen|pods?|sleeves?|tubs?|each|recipes?|ribs?|"
    "bricks?|stems?|sprigs?|fl|quarts?|bowls?|mugs?|glass(?:es)?|pats?|tubes?|batch(?:es)?|"
    # Old cookbooks' and typed units: "a tea-spoonful of", "a wine-glass of", "600gm", "5 strands saffron".
    "tea-?spoonfuls?|table-?spoonfuls?|spoonfuls?|wine-?glass(?:es)?|glassfuls?|jiggers?|teapsoons?|gms?|"
    "strands?|branch(?:es)?|twigs?|metric cups?"
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
    julienned torn juiced zested cut into un-cooked uncooked sized medium-sized free-range quick-cooking overfilled
    very grounded pealed cleaned shucked smashed shaved pressed pulverized tepid warmed live bone-in skin-on
    """
)
_ADJ_ALTERNATIVES = _words(
    """
    red green yellow orange white black brown dark light sweet smooth crunchy salted unsalted hot mild fresh
    dried whole low-fat full-fat nonfat skim regular large small medium fine coarse
    """
)
# Kind words of one alternative that name the product with the shared noun ("semisweet or bittersweet
# chocolate" → semisweet chocolate): the first alternative is kept, with its noun.
_KIND_ALTERNATIVES = _words(
    "semisweet bittersweet granulated quick evaporated button long short rye wheat field canned all-purpose cotija"
    " cajun"
)
# Not fetched from a shelf: water comes from the tap and ice from the freezer; tools and consumables are not food.
_WATER_HEADS = (("water",), ("ice",), ("ice", "cube"))
_WATER_NOT = _words("rose coconut tonic sparkling soda orange-blossom blossom flower chestnut seltzer")


def _phrases(text: str) -> frozenset[str]:
    return frozenset(p.strip() for p in text.replace("\n", " ").split(",") if p.strip())


_TOOLS = _phrases(
    """
    thermometer, candy thermometer, meat thermometer, cheesecloth, parchment, parchment paper, baking paper,
    wax paper, waxed paper, foil, aluminum foil, aluminium foil, tin foil, plastic wrap, cling film, skewer,
    wooden skewer, bamboo skewer, toothpick, kitchen twine, twine, butcher's twine, cooking twine, string,
    paper towel, muffin liner, cupcake liner, paper liner, baking cup, piping bag, zip-top bag, ziploc bag,
    freezer bag, sealable bag, mason jar, jar, bowl, pan, baking sheet, baking pan, cake pan, pie dish,
    baking dish, springform pan, loaf pan, sheet pan, muffin tin, ramekin, mold, mould, cookie cutter,
    food processor, blender, mixer, stand mixer, hand mixer, whisk, spatula, knife, cutting board, rolling pin,
    sieve, strainer, colander, cooling rack, wire rack, ladle, tongs, grater, zester, kitchen scale, scale,
    oven, grill, skillet, saucepan, pot, dutch oven, wok, steamer, popsicle stick, popsicle mold,
    ice cream maker, coffee filter, tea towel, kitchen towel, rubber band, cooking spray bottle, chopsticks,
    wood chips, wood chip, smoking chips, applewood, slow cooker, oven-safe pan, thermos, thermo, marble,
    glass marble, oven bag, reynold's oven bag, roasting bag, well-washed stone, stone, baking paper square
    """
)


class ItemClass(Enum):
    """What a normalised ingredient item is, for stocking a kitchen."""

    FOOD = "food"
    """Something fetched from the shelf (whether or not this kitchen stocks it)."""
    WATER = "water"
    """Water or ice: from the tap or the freezer, not the shelf."""
    TOOL = "tool"
    """Equipment or a consumable (thermometer, cheesecloth, foil): not an ingredient."""
    NOTHING = "nothing"
    """No item left after normalising ("2 Tbsp")."""


_NUMBER_WORDS = "one|two|three|four|five|six|seven|eight|nine|ten|eleven|twelve|a dozen|dozen"
_NUMBER = rf"(?:\d+(?:[.,]\d+)?(?:\s*/\s*\d+)?|[¼½¾⅓⅔⅛⅜⅝⅞⅕]|\b(?:{_NUMBER_WORDS})\b)"
# Size words a quantity may carry before its unit ("1 small handful", "1 heaping tbsp", "2 large cloves").
_SIZES = "small|medium|large|big|heaping|heaped|level|generous|scant|good|rounded|baby|extra-large|whole|thick|thin"
_QUANTITY = re.compile(
    rf"(?<![a-z]){_NUMBER}(?:\s*(?:-|–|to|or)\s*{_NUMBER})*"
    rf"(?:(?:\s+(?:{_SIZES}))?\s*-?\s*(?:{_UNITS})\b\.?)?(?:\s+of\b)?",
    re.IGNORECASE,
)
# Unit words that are also the item when nothing else is left ("3 cloves" of the spice).
_UNIT_ITEMS = frozenset({"cloves", "clove", "bay leaves", "leaves", "sticks"})
_UNIT_ALONE = re.compile(
    rf"^(?:a|an|one|some|few)?\s*(?:(?:{_SIZES})\s+)?(?:{_UNITS})\b\.?(?:\s+of\b)?\s*", re.IGNORECASE
)
_UNIT_WORD = re.compile(rf"(?:{_UNITS})")
# Unit words that also start real item names ("glass noodles", "in season").
_NOT_UNITS = frozenset({"glass", "in", "c", "t", "l", "g", "each"})
# State words a first comma-separated segment may consist of ("raw, unsalted almonds").
_STATE_WORDS = _words(
    "unsalted salted roasted toasted raw bone-in skin-on skin-off strong unflavored unflavoured unsweetened"
    " sweetened full fat low non-uht uht thick thin hot lightly"
)
_PAREN = re.compile(r"\([^)]*\)|\[[^\]]*\]")
_CUT = re.compile(
    r",|;|:|/|\*|\.\s|\.$|\s-\s|\s–\s|\bfor\b|\bper\b|\bwithout\b|\bor less\b|\bor more\b|\bto taste\b|\bas needed\b|\bif desired\b|\bplus\b|\bsuch as\b|\bof (?:your |the )?(?:choice|favou?rite|preference|liking)\b"
    # Notes that follow the item: "water to thin", "cut into ribbons", "separated from the yolks", "q.b.".
    r"|\sto\s|\binto\b|\bas (?:a )?garnish\b|\bseparated\b|\bif needed\b|\bpreferably\b|\bat room\b|\bthat\b"
    r"|\bweighing\b|\bby\b|\bas you\b|\bin (?:a )?squirt bottle\b|\bq\.?\s?b\b"
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
        left, right = " ".join(w for w in left.split() if w not in _PREP_WORDS), right.strip()
        if left and right and len(left.split()) == 1 and len(right.split()) > 1:
            if left in _ADJ_ALTERNATIVES:
                return right
            if left in _KIND_ALTERNATIVES:
                return " ".join([left, *right.split()[1:]])
        return left or right
    return text


def normalise_ingredient(text: str) -> str:
    """The fetchable item an ingredient string names, lower case ("" when it names none).

    Args:
        text: An ingredient line with optional quantity, unit and notes, e.g. "1 15-oz can chickpeas, drained".

    Returns:
        The item, e.g. "chickpeas"; "" for strings without any food word left ("2 Tbsp", "").
    """
    s = _ascii_fold(text).lower().replace("&", " and ").replace("~", " ").replace("\u2019", "'")
    s = _PAREN.sub(" ", s)
    s = s.replace("(", " ").replace(")", " ").replace("and/or", "or")
    s = re.sub(r"\b(?:small|medium|large)/(?=(?:small|medium|large|medium-sized)\b)", "", s)  # "small/medium"
    s = re.sub(r"\b(?:half|quarter|third)\s+(?:of\s+)?an?\b", " ", s)
    s = re.sub(r"\b(?:around|about|approximately|approx\.?|roughly)\s+(?=\d)", " ", s)
    s = re.sub(r"-(peel|rind|zest|water|flakes?)\b", r" \1", s)  # "lemon-peel", "rose-water"
    unit_only = _unit_item(s)
    s = _QUANTITY.sub(" ", s)
    s = re.sub(r"\s+", " ", s).strip()
    s = re.sub(r"^(?:or|and)\s+", "", s)  # "14 ounces or 400 grams of chicken": the second quantity's "or"
    head, cut, rest = _split_note(s)
    # "bone-in, skin-on chicken thighs", "raw, unsalted almonds": a first segment of state words only is not the
    # item; the item follows the comma.
    while (
        cut == ","
        and rest.strip()
        and all(w in _PREP_WORDS or w in _STATE_WORDS for w in _WORD.findall(head))
    ):
        head, cut, rest = _split_note(rest)
    s = head
    s = re.sub(
        r"^(?:a little bit|a little|little bit|little|a bit|a couple|couple|enough|as much|a|an|one|some|few)\s+"
        r"(?:of\s+)?",
        "",
        s.strip(),
    )
    for _ in range(2):  # "a jar of" then "a bunch of"
        s = _UNIT_ALONE.sub("", s).strip()
    s = _pick_alternative(s)
    parts = s.split(" and ")
    while len(parts) > 1 and all(w in _PREP_WORDS for w in parts[0].split()):  # "peeled and chopped ginger"
        parts = parts[1:]
    s = parts[0]
    s = s.partition(" with ")[0]
    words = _WORD.findall(s)
    while words and words[0] in ("of", "and", "or"):
        words = words[1:]
    if not words:
        return unit_only
    # A unit word repeated as part of the name ("1/2 lemon lemon juice", "3 yolks egg yolks"): keep the name.
    if len(words) > 1 and item_key(words[0]) in {item_key(w) for w in words[1:]}:
        words = words[1:]
    words = _strip_prep(words)
    # A unit word left first by a preparation word before it ("3 peeled cloves garlic"): the item follows it.
    if len(words) > 1 and words[0] not in _NOT_UNITS and _UNIT_WORD.fullmatch(words[0]):
        words = words[1:]
    return " ".join(words).strip(" -'")


def _split_note(text: str) -> tuple[str, str, str]:
    """(item part, the separator, the rest) at the first note separator of `_CUT`."""
    m = _CUT.search(f"{text} ")
    if m is None:
        return text, "", ""
    return text[: m.start()], m.group(0), f"{text} "[m.end() :]


def _unit_item(text: str) -> str:
    """The item when a line is only a count and a unit word that is also a food ("3 cloves" of the spice)."""
    words = _WORD.findall(text)
    units = re.compile(rf"(?:{_UNITS})", re.IGNORECASE)
    if (
        words
        and words[-1] in _UNIT_ITEMS
        and all(units.fullmatch(w) for w in words[:-1])
        and _QUANTITY.search(text)
    ):
        return words[-1]
    return ""


def classify_item(item: str) -> ItemClass:
    """Whether a normalised item is food for the shelf, water or ice, a tool, or nothing at all."""
    if not item:
        return ItemClass.NOTHING
    key = item_key(item)
    words = key.split()
    if key in _TOOLS or item in _TOOLS:
        return ItemClass.TOOL
    # "boiling water", "ice water", "crushed ice", but not "rose water" or "coconut water"
    if any(tuple(words[-len(h) :]) == h for h in _WATER_HEADS) and not any(w in _WATER_NOT for w in words):
        return ItemClass.WATER
    return ItemClass.FOOD


def is_fetchable(item: str) -> bool:
    """Whether a normalised item is something a robot fetches from a shelf (not water, ice or a tool)."""
    return classify_item(item) is ItemClass.FOOD


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
