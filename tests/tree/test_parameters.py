"""One source of defaults: the tree file's parameters reach scone-run and run_episode alike."""

from __future__ import annotations

import pytest

from scone_bt.behaviours import BehaviourOptions
from scone_bt.cli.run import build_parser, options_from_args
from scone_bt.config.tree_parameters import PARAMETER_NAMES, TreeParameters
from scone_bt.errors import ConfigError
from scone_bt.tree import load_tree_spec


def test_the_shipped_tree_states_every_parameter_and_matches_the_model_defaults() -> None:
    params = load_tree_spec("assistive_cooking").parameters
    assert set(params) == set(PARAMETER_NAMES)
    assert TreeParameters(**params) == TreeParameters()


def test_unset_options_come_from_the_tree_file_and_set_ones_win() -> None:
    params = {"relevance_threshold": 0.4, "estimator": "knn", "clarify_margin": 0.1}
    resolved = BehaviourOptions(estimator="lgbm").resolve(params)
    assert (resolved.relevance_threshold, resolved.estimator, resolved.clarify_margin) == (0.4, "lgbm", 0.1)
    assert resolved.resolved and resolved.recipe_aware is True
    assert BehaviourOptions().resolve().relevance_threshold == TreeParameters().relevance_threshold


def test_scone_run_leaves_the_defaults_to_the_tree_file(tmp_path) -> None:
    args = build_parser().parse_args(["--robot", "sim", "--headless"])
    behaviour = options_from_args(args).behaviour
    assert behaviour.relevance_threshold is None  # filled from the tree file by run_episode
    spec = load_tree_spec("assistive_cooking")
    assert behaviour.resolve(spec.parameters).relevance_threshold == spec.parameters["relevance_threshold"]
    given = options_from_args(build_parser().parse_args(["--robot", "sim", "--relevance-threshold", "0.5"]))
    assert given.behaviour.resolve(spec.parameters).relevance_threshold == 0.5


def test_a_bad_parameter_in_a_tree_file_is_one_line(tmp_path) -> None:
    text = (
        load_tree_spec("assistive_cooking")
        .source.read_text()
        .replace("recipe_aware: true", "recipe_aware: 7")
    )
    bad = tmp_path / "bad.yaml"
    bad.write_text(text)
    with pytest.raises(ConfigError) as exc:
        load_tree_spec(bad)
    assert "recipe_aware" in str(exc.value) and "\n" not in str(exc.value)
