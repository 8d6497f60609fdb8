import json

import pytest

from scone_bt.errors import RecipeError
from scone_bt.recipes import load_recipe
from scone_bt.recipes.recipe import recipe_corpus_path
from scone_bt.stocking import match_catalogue, stock_recipe


def test_examples_load_and_stock(kitchen_cfg):
    stocked = stock_recipe(load_recipe("example:tomato-pasta"), kitchen_cfg.catalogue)
    assert [s.objects for s in stocked.steps] == [
        ("salt",),
        ("spaghetti",),
        ("olive oil", "garlic"),
        ("crushed tomatoes",),
        ("parmesan",),
    ]
    assert stocked.needed == ("salt", "spaghetti", "olive oil", "garlic", "crushed tomatoes", "parmesan")
    assert stocked.unstocked == () and stocked.off_shelf == ()


def test_longest_alias_wins(kitchen_cfg):
    assert match_catalogue("2 tbsp extra virgin olive oil", kitchen_cfg.catalogue) == [
        "extra virgin olive oil"
    ]
    assert match_catalogue("salt and pepper to taste", kitchen_cfg.catalogue) == ["salt", "black pepper"]


def test_unknown_example_names_valid_ones():
    with pytest.raises(RecipeError, match="example:tomato-pasta"):
        load_recipe("example:nope")


@pytest.mark.skipif(recipe_corpus_path() is None, reason="../shared recipe corpus not present")
def test_corpus_lookup_and_suggestion(kitchen_cfg):
    recipe = load_recipe("pdr:aelplermagronen")
    assert recipe.steps and recipe.ingredients
    stocked = stock_recipe(recipe, kitchen_cfg.catalogue)
    assert "milk" in stocked.needed
    with pytest.raises(RecipeError, match="did you mean"):
        load_recipe("pdr:aelplermagronenn")


def test_malformed_and_empty_recipes(tmp_path, kitchen_cfg):
    bad = tmp_path / "r.json"
    bad.write_text("{not json")
    with pytest.raises(RecipeError, match="not valid JSON"):
        load_recipe(str(bad))
    broken = tmp_path / "r.yaml"  # the line is named, as in every other file the robot reads
    broken.write_text("title: x\nsteps:\n  - [unclosed\n")
    with pytest.raises(RecipeError, match=r"r.yaml: line 4 is not valid YAML \(expected ','"):
        load_recipe(str(broken))
    empty = tmp_path / "e.json"
    empty.write_text(json.dumps({"ingredients": ["salt"], "steps": ["  "]}))
    with pytest.raises(RecipeError, match="non-empty"):
        load_recipe(str(empty))
    # A recipe of no ingredients, or of blank ones, used to be "served" without the robot doing anything.
    for items, message in (([], "at least 1 item"), (["salt", "  "], "ingredient 2 of 2 is empty")):
        empty.write_text(json.dumps({"ingredients": items, "steps": ["Stir."]}))
        with pytest.raises(RecipeError, match=f"e.json: ingredients: .*{message}"):
            load_recipe(str(empty))
    # JSON keeps the last of two equal keys silently; the YAML loader refuses them, and so does this.
    empty.write_text('{"id": "a", "id": "b", "ingredients": ["salt"], "steps": ["Stir."]}')
    with pytest.raises(RecipeError, match=r"e.json: not valid JSON \(the key 'id' is given twice\)"):
        load_recipe(str(empty))
    # A recipe with nothing stocked still runs: the human brings everything.
    nothing = tmp_path / "n.json"
    nothing.write_text(json.dumps({"ingredients": ["unobtainium", "1 cup water"], "steps": ["Admire it."]}))
    stocked = stock_recipe(load_recipe(str(nothing)), kitchen_cfg.catalogue)
    assert stocked.needed == () and stocked.unstocked == ("unobtainium",)
    assert stocked.not_fetchable == ("1 cup water",)


def test_a_folder_given_as_the_recipe_says_so(tmp_path):
    with pytest.raises(RecipeError) as err:
        load_recipe(str(tmp_path))
    assert str(err.value) == (
        f"recipe {str(tmp_path)!r} is a folder; give a recipe file (.json, .yaml), example:<name> "
        "(hummus, pancakes, tomato-pasta) or a corpus id"
    )


def test_the_corpus_is_read_from_scone_bt_shared_and_its_absence_says_how_to_point_at_it(
    tmp_path, monkeypatch
) -> None:
    import json

    from scone_bt.recipes import recipe as recipe_module

    corpus = tmp_path / "elsewhere" / "data" / "recipes"
    corpus.mkdir(parents=True)
    record = {
        "id": "mine:toast",
        "title": "Toast",
        "ingredients": ["bread", "butter"],
        "steps": ["Toast the bread.", "Butter the toast."],
    }
    (corpus / "recipes.jsonl").write_text(json.dumps(record) + "\n", encoding="utf-8")
    monkeypatch.setenv("SCONE_BT_SHARED", str(tmp_path / "elsewhere"))
    assert recipe_corpus_path() == corpus / "recipes.jsonl"
    assert load_recipe("mine:toast").title == "Toast"

    monkeypatch.setattr(recipe_module, "recipe_corpus_path", lambda: None)
    with pytest.raises(
        RecipeError, match=r"is not here \(set SCONE_BT_SHARED .*example:tomato-pasta"
    ) as info:
        load_recipe("pdr:aelplermagronen")
    assert "\n" not in str(info.value)


def test_an_empty_recipe_file_and_a_file_of_another_kind_say_so(tmp_path) -> None:
    """An empty file said "got NoneType"; an existing .txt was looked up as a corpus id."""
    empty = tmp_path / "empty.yaml"
    empty.write_text("")
    with pytest.raises(
        RecipeError, match=r"empty.yaml: is empty; a recipe is a mapping with ingredients and steps"
    ):
        load_recipe(str(empty))
    notes = tmp_path / "notes.txt"
    notes.write_text("salt\n")
    with pytest.raises(RecipeError, match=r"a recipe file is \.json, \.yaml or \.yml \(got \.txt\)"):
        load_recipe(str(notes))
