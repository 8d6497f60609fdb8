"""A tree file is checked by pydantic models, node by node; every problem is one line naming the node and choices."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from scone_bt.errors import ConfigError, UnknownNameError
from scone_bt.tree import load_tree_spec

OK = {"behaviour": "Perceive"}


@pytest.mark.parametrize(
    ("doc", "message"),
    [
        (
            {"root": {"selector": "S", "children": "x"}},
            "t.yaml:root: selector 'S' needs a non-empty 'children' list",
        ),
        (
            {"root": {"sequence": "S", "children": []}},
            "t.yaml:root: sequence 'S' needs a non-empty 'children' list",
        ),
        ({"root": {"selector": 3, "children": [OK]}}, "t.yaml:root: the selector's name must be text, got 3"),
        (
            {"root": {"selector": "S", "memory": "yes", "children": [OK]}},
            "t.yaml:root: 'memory' must be true or false, got 'yes'",
        ),
        ({"root": {"selector": "S", "name": 5, "children": [OK]}}, "t.yaml:root: 'name' must be text, got 5"),
        (
            {"root": {"selector": "S", "kind_name": 1, "children": [OK]}},
            "t.yaml:root: unknown key 'kind_name'; valid: selector, name, memory, children",
        ),
        (
            {"root": {"selector": "S", "children": [{"behaviour": "Perceive", "bogus": 1}]}},
            "t.yaml:root/S[0]: unknown key 'bogus'; valid: behaviour, name, args",
        ),
        (
            {"root": {"behaviour": "Perceive", 3: 1}},
            "t.yaml:root: unknown key '3'; valid: behaviour, name, args",
        ),
        (
            {"root": {"behaviour": "Perceive", "sequence": "x"}},
            "t.yaml:root: a node needs exactly one of: sequence, selector, behaviour (got ['behaviour', 'sequence'])",
        ),
        ({"root": []}, "t.yaml:root: a node must be a mapping with one of: sequence, selector, behaviour"),
        (
            {"root": {"behaviour": "WaitForHuman", "args": ["soon"]}},
            "t.yaml:root: 'args' must be a mapping, got list",
        ),
        ({"name": 3, "root": OK}, "t.yaml: 'name' must be text, got 3"),
        ({"bogus": 3, "root": OK}, "t.yaml: unknown key 'bogus'; valid: name, root, parameters"),
        ({"name": "x"}, "t.yaml: missing 'root'"),
        ({"root": OK, "parameters": [1]}, "t.yaml: 'parameters' must be a mapping"),
    ],
)
def test_a_bad_tree_file_is_one_line_naming_the_node(tmp_path: Path, doc, message):
    path = tmp_path / "t.yaml"
    path.write_text(yaml.safe_dump(doc))
    with pytest.raises(ConfigError) as err:
        load_tree_spec(path)
    assert str(err.value) == f"{tmp_path}/{message}"


@pytest.mark.parametrize("name", ["Dance", 7])
def test_an_unknown_behaviour_deep_in_the_tree_lists_the_valid_ones(tmp_path: Path, name):
    path = tmp_path / "t.yaml"
    doc = {"root": {"selector": "S", "children": [{"sequence": "T", "children": [OK, {"behaviour": name}]}]}}
    path.write_text(yaml.safe_dump(doc))
    with pytest.raises(UnknownNameError) as err:
        load_tree_spec(path)
    message = str(err.value)
    assert message.startswith(f"unknown behaviour at {path}:root/S[0]/T[1] '{name}'; valid: AskForHelp, ")
    assert "Perceive" in message and "\n" not in message


def test_nesting_past_the_limit_is_refused_not_a_recursion_error(tmp_path: Path):
    node: dict = OK
    for _ in range(70):
        node = {"sequence": "S", "children": [node]}
    path = tmp_path / "t.yaml"
    path.write_text(yaml.safe_dump({"root": node}))
    with pytest.raises(ConfigError, match="the tree is nested deeper than 64 levels"):
        load_tree_spec(path)


@pytest.mark.parametrize(
    ("key", "value", "message"),
    [
        (
            "estimator",
            "nosuch",
            "parameters.estimator: unknown estimator 'nosuch'; valid: conformal, eps-conformal, ",
        ),
        (
            "embedder",
            "nosuch",
            "parameters.embedder: unknown embedder 'nosuch'; valid: glove, minilm, mpnet, ",
        ),
        # a name that is not text said only "Input should be a valid string"
        ("estimator", 5, "parameters.estimator: unknown estimator '5'; valid: conformal, "),
    ],
)
def test_an_unknown_estimator_or_embedder_names_the_file_and_key(tmp_path: Path, key, value, message):
    path = tmp_path / "t.yaml"
    path.write_text(yaml.safe_dump({"root": OK, "parameters": {key: value}}))
    with pytest.raises(ConfigError) as err:
        load_tree_spec(path)
    assert str(err.value).startswith(f"{path}: {message}") and "\n" not in str(err.value)


@pytest.mark.parametrize(
    ("key", "value"), [("estimator", "grounded-knn-cal"), ("estimator", "xgboost"), ("embedder", "onehot")]
)
def test_every_registry_name_is_accepted_in_a_tree_file(tmp_path: Path, key, value):
    path = tmp_path / "t.yaml"
    path.write_text(yaml.safe_dump({"root": OK, "parameters": {key: value}}))
    assert load_tree_spec(path).parameters[key] == value
