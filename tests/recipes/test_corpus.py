"""The one reader of the recipe corpus: every line a validated recipe, or one line of error naming file, line, key."""

from __future__ import annotations

import json

import pytest

from scone_bt.errors import RecipeError
from scone_bt.recipes.recipe import corpus_entries, read_corpus, recipe_corpus_path

GOOD = {"id": "t:1", "title": "Toast", "ingredients": ["1 slice bread"], "steps": ["Toast the bread."]}


def _corpus(tmp_path, *lines: str):
    path = tmp_path / "recipes.jsonl"
    path.write_text("".join(line + "\n" for line in lines), encoding="utf-8")
    return path


def test_reads_every_recipe_and_skips_blank_lines(tmp_path):
    other = {**GOOD, "id": "t:2", "ingredients_structured": [{"name": "bread"}]}
    path = _corpus(tmp_path, json.dumps(GOOD), "", "   ", json.dumps(other))
    recipes = read_corpus(path)
    assert [r.id for r in recipes] == ["t:1", "t:2"]
    entries = list(corpus_entries(path))
    assert [e.where for e in entries] == [f"{path}:1", f"{path}:4"]
    assert entries[1].record["ingredients_structured"] == [{"name": "bread"}]  # metadata kept as it is


@pytest.mark.parametrize(
    ("line", "message"),
    [
        ("{not json", "not valid JSON"),
        ('["a list"]', "must be a JSON object"),
        (json.dumps({**GOOD, "stpes": ["x"]}), "stpes"),
        (json.dumps({**GOOD, "steps": []}), "steps"),
    ],
)
def test_a_malformed_line_is_one_line_naming_file_line_and_key(tmp_path, line, message):
    path = _corpus(tmp_path, json.dumps(GOOD), line)
    with pytest.raises(RecipeError) as err:
        read_corpus(path)
    text = str(err.value)
    assert "\n" not in text
    assert f"{path}:2" in text and message in text


def test_a_missing_corpus_is_named(tmp_path):
    with pytest.raises(RecipeError, match="recipe corpus not found: .*nope.jsonl"):
        read_corpus(tmp_path / "nope.jsonl")
    with pytest.raises(RecipeError, match="not UTF-8"):
        (tmp_path / "latin1.jsonl").write_bytes(b'{"title": "Cr\xe8me"}\n')
        read_corpus(tmp_path / "latin1.jsonl")


@pytest.mark.skipif(recipe_corpus_path() is None, reason="../shared recipe corpus not present")
def test_the_shared_corpus_reads_whole():
    recipes = read_corpus()
    assert len(recipes) == 1227
    assert len({r.id for r in recipes}) == len(recipes)
