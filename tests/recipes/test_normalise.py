"""Ingredient strings → fetchable items."""

from __future__ import annotations

import pytest

from scone_bt.recipes.normalise import ItemClass, classify_item, is_fetchable, item_key, normalise_ingredient


@pytest.mark.parametrize(
    ("text", "item"),
    [
        ("1 can chickpeas, drained", "chickpeas"),
        ("1 15-oz can chickpeas", "chickpeas"),
        ("~150g (1/3 lb) bacon cubes", "bacon cubes"),
        ("3 onions (medium size)", "onions"),
        ("A bunch of fresh parsley", "parsley"),
        ("5-6 cloves of garlic", "garlic"),
        ("1/2 cup (110g) extra virgin olive oil", "extra virgin olive oil"),
        ("a jar of apple sauce", "apple sauce"),
        ("1 - 2L (1/4 - 1/2 gal) milk", "milk"),
        ("½ tsp ground cinnamon", "ground cinnamon"),
        ("2 large eggs", "eggs"),
        ("butter for greasing", "butter"),
        ("salt and pepper to taste", "salt"),
        ("cilantro or flat-leaf parsley", "cilantro"),
        ("brown or green lentils", "green lentils"),
        ("peanut butter (smooth supermarket style, not natural)", "peanut butter"),
        ("2 tsp cream of tartar", "cream of tartar"),
        ("1 cup Gruyère", "gruyere"),
        ("Garam Masala/Chicken Masala 1 tbsp", "garam masala"),
        ("half a tin (200g) of baked beans", "baked beans"),
        # The cases issue 12 names, and others from the corpus.
        ("Six eggs.", "eggs"),
        ("1 heaping tbsp Cumin", "cumin"),
        (
            "~150g (1/3 lb) medium soft cheese. Appenzeller works best. Gruyère would be my go-to alternative.",
            "soft cheese",
        ),
        (
            "Lamb shoulder, or something similar, like lamb shank, preferably on the bone. Get something that "
            "will fit in your pot, with room for vegetables around it.",
            "lamb shoulder",
        ),
        ("1 small handful parsley", "parsley"),
        ("2 small heads cabbage", "cabbage"),
        ("1 dozen eggs", "eggs"),
        ("1/4 tsp cloves", "cloves"),
        ("3 cloves", "cloves"),
        ("1/2 lemon lemon juice", "lemon juice"),
        ("1 tsp peeled and chopped fresh ginger", "ginger"),
        ("1 large white or yellow onion", "yellow onion"),
        ("Curry powder of your favourite variety", "curry powder"),
        ("2 small/medium-sized potatoes", "potatoes"),
        # Old cookbooks' and typed units, notes after the item, state-only first segments.
        ("Half a tea-spoonful of rose-water.", "rose water"),
        ("5 strands saffron", "saffron"),
        ("600gm Mutton / Lamb (Boneless)", "mutton"),
        ("a little bit of salt (1/3 of a teaspoon)", "salt"),
        ("Around 14 ounces or 400 grams of chicken breast", "chicken breast"),
        ("3 peeled cloves garlic", "garlic"),
        ("2 very ripe bananas", "bananas"),
        ("water to thin peanut sauce", "water"),
        ("1 large bunch collard greens chopped into ribbons", "collard greens"),
        ("Egg whites separated from the yolks above", "egg whites"),
        ("olive oil q.b. (quanto basta - 'enough')", "olive oil"),
        ("Mayonnaise in squirt bottle", "mayonnaise"),
        ("8 bone-in, skin-on chicken thighs", "chicken thighs"),
        ("Enough flour to make a soft pliable dough", "flour"),
        # Of two kinds of one noun, the first kind with the noun.
        ("6 oz semisweet or bittersweet chocolate", "semisweet chocolate"),
        ("1 tbsp Cajun or Creole Seasoning (Creole Kick)", "cajun seasoning"),
    ],
)
def test_normalise_ingredient(text: str, item: str) -> None:
    assert normalise_ingredient(text) == item


def test_quantity_only_names_nothing() -> None:
    assert normalise_ingredient("2 Tbsp") == ""
    assert normalise_ingredient("") == ""


def test_fetchable_excludes_water_and_tools() -> None:
    assert is_fetchable("chickpeas")
    assert not is_fetchable("water")
    assert not is_fetchable("thermometer")
    assert not is_fetchable("")


@pytest.mark.parametrize(
    ("line", "kind"),
    [
        ("1 cup water", ItemClass.WATER),
        ("2 cups boiling water", ItemClass.WATER),
        ("1 cup crushed ice", ItemClass.WATER),
        ("ice cubes", ItemClass.WATER),
        ("candy thermometer", ItemClass.TOOL),
        ("cheesecloth", ItemClass.TOOL),
        ("parchment paper", ItemClass.TOOL),
        ("8 wooden skewers", ItemClass.TOOL),
        ("Wood chips (optional, fuel for smokey flavour)", ItemClass.TOOL),
        ("2 thermos, 1/2l capacity each", ItemClass.TOOL),
        ("A slow cooker", ItemClass.TOOL),
        ("salt and pepper to taste", ItemClass.FOOD),
        ("1 tbsp rose water", ItemClass.FOOD),
        ("coconut water", ItemClass.FOOD),
        ("2 tbsp lemon juice", ItemClass.FOOD),
        ("2 Tbsp", ItemClass.NOTHING),
    ],
)
def test_item_classes(line: str, kind: ItemClass) -> None:
    assert classify_item(normalise_ingredient(line)) is kind


def test_item_key_ignores_plural() -> None:
    assert item_key("eggs") == item_key("egg")
    assert item_key("cherries") == item_key("cherry")
    assert item_key("tomatoes") == item_key("tomato")
    assert item_key("hummus") == "hummus"
