from pathlib import Path

import pytest

from scone_bt.errors import ConfigError, UnknownNameError
from scone_bt.tree import build_tree, load_tree_spec, render_tree


def test_default_tree_builds_and_renders(tmp_path):
    from tests.behaviours.fakes import fake_context

    spec = load_tree_spec("assistive_cooking")
    root = build_tree(spec, fake_context(tmp_path))
    text = render_tree(root)
    order = [
        "Perceive",
        "GenerateAffordances",
        "RankByRelevance",
        "ConfidenceGate",
        "RecordInfeasible",
        "AskForHelp",
        "PickAndPlace",
        "ObserveOutcome",
    ]
    positions = [text.index(name) for name in order]
    assert positions == sorted(positions)
    assert text.count("UpdateSelfConfidence") == 2  # after an infeasible plan and after an attempt
    assert spec.parameters["confidence_threshold"] == 0.5


def test_unknown_behaviour_lists_valid(tmp_path: Path):
    path = tmp_path / "t.yaml"
    path.write_text("root:\n  sequence: S\n  children:\n    - behaviour: Dance\n")
    with pytest.raises(UnknownNameError, match="Perceive"):
        load_tree_spec(path)


def test_composite_without_children(tmp_path: Path):
    path = tmp_path / "t.yaml"
    path.write_text("root:\n  selector: S\n")
    with pytest.raises(ConfigError, match="children"):
        load_tree_spec(path)
