"""The states builder on tiny recipes, the file schema, and the committed states files."""

from __future__ import annotations

import json

import pytest

from scone_bt.errors import RecipeError
from scone_bt.instruction_following.cli import default_states_dir
from scone_bt.instruction_following.states import (
    StateOptions,
    build_states,
    item_of_action,
    load_states,
    mentioned_items,
    recipe_split,
    save_states,
)


def test_author_labels_follow_steps_and_consumption(hummus, pancakes) -> None:
    states = build_states([hummus, pancakes], StateOptions(distractors=2, seed=3))
    by_recipe = [s for s in states if s.recipe_id == "test:hummus"]
    # Step 2 ("Rinse the blender") needs nothing and is not a state; water is not fetchable.
    assert [s.step for s in by_recipe] == [0, 1, 3]
    first, second, last = by_recipe
    assert first.relevant == {"Put chickpeas on table", "Put tahini on table"}
    assert second.relevant == {"Put garlic on table"}
    assert last.relevant == {"Put salt on table", "Put lemon on table", "Put tahini on table"}
    # Chickpeas are used up after step 0, tahini only after its last use in step 3.
    assert "Put chickpeas on table" not in second.available
    assert "Put tahini on table" in second.available
    assert "Put garlic on table" not in last.available
    # Two distractors come from the other recipe and stay in the kitchen throughout.
    distractors = set(first.available) - {
        f"Put {i} on table" for i in ("chickpeas", "tahini", "lemon", "garlic", "salt")
    }
    assert len(distractors) == 2
    assert {item_of_action(a) for a in distractors} <= {"flour", "eggs", "milk", "butter"}
    assert distractors <= set(last.available)
    for s in states:
        assert s.relevant <= set(s.available)
        assert set(s.locations) == set(s.available)
        assert len(set(s.locations.values())) == len(s.available)  # one item per shelf slot


def test_states_are_seeded(hummus, pancakes) -> None:
    a = build_states([hummus, pancakes], StateOptions(distractors=2, seed=1))
    b = build_states([hummus, pancakes], StateOptions(distractors=2, seed=1))
    assert [s.to_json() for s in a] == [s.to_json() for s in b]


def test_mentions_labels(hummus) -> None:
    states = build_states([hummus], StateOptions(labels="mentions", distractors=0))
    assert states[0].relevant == {"Put chickpeas on table", "Put tahini on table"}
    assert mentioned_items("Add the sugar and the eggs", ["brown sugar", "egg", "flour"]) == [
        "brown sugar",
        "egg",
    ]
    # A head noun shared by two items names neither.
    assert mentioned_items("Add the sugar", ["brown sugar", "icing sugar"]) == []


def test_split_is_by_recipe() -> None:
    assert recipe_split("nw:a") == recipe_split("nw:a")
    splits = {recipe_split(f"r{i}") for i in range(200)}
    assert splits == {"train", "dev", "test"}


def test_save_load_roundtrip(tmp_path, hummus) -> None:
    states = build_states([hummus], StateOptions(distractors=0))
    path = tmp_path / "s.jsonl"
    assert save_states(path, states) == len(states)
    back = load_states(path)
    assert back == states
    assert back[0].locations == states[0].locations


def test_load_rejects_bad_schema(tmp_path) -> None:
    path = tmp_path / "bad.jsonl"
    path.write_text(json.dumps({"instruction": "x", "available": ["a"], "relevant": ["b"]}) + "\n")
    with pytest.raises(RecipeError, match="subset"):
        load_states(path)
    path.write_text(json.dumps({"instruction": "x"}) + "\n")
    with pytest.raises(RecipeError, match="required keys"):
        load_states(path)
    with pytest.raises(RecipeError, match="valid: train, dev, test"):
        load_states(tmp_path / "bad.jsonl", split="validation")


def test_committed_states_files() -> None:
    folder = default_states_dir()
    assert folder is not None
    splits = {name: load_states(folder / f"{name}.jsonl") for name in ("train", "dev", "test")}
    assert sum(len(v) for v in splits.values()) >= 500
    recipes = {name: {s.recipe_id for s in v} for name, v in splits.items()}
    assert not recipes["train"] & recipes["test"]
    assert not recipes["train"] & recipes["dev"]
    assert not recipes["dev"] & recipes["test"]
    for name, states in splits.items():
        assert all(s.split == name and s.relevant and s.relevant <= set(s.available) for s in states)


def test_save_replaces_the_file_whole(tmp_path, hummus, pancakes) -> None:
    import os

    path = tmp_path / "s.jsonl"
    states = build_states([hummus, pancakes], StateOptions(distractors=2))
    assert len(states) > 1
    save_states(path, states[:1])
    os.link(path, tmp_path / "alias.jsonl")  # a write in place would change the alias too
    assert save_states(path, states) == len(states)
    assert load_states(tmp_path / "alias.jsonl") == states[:1] and load_states(path) == states


def test_too_few_other_items_for_the_distractors_is_an_error_not_a_hang(hummus) -> None:
    # One recipe: every item of the corpus is its own, so no distractor can be drawn (it looped forever).
    with pytest.raises(RecipeError, match="leaves only 0 other item"):
        build_states([hummus], StateOptions(distractors=1))
