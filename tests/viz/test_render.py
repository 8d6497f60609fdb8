"""Pure rendering helpers: tree flattening and layout, markdown panels."""

from __future__ import annotations

import py_trees
import pytest

from scone_bt.gate.types import Decision, DecisionKind
from scone_bt.viz import RecipeView
from scone_bt.viz.render import (
    affordances_markdown,
    decision_markdown,
    flatten_tree,
    layout_tree,
    rank_affordances,
    recipe_markdown,
    slug,
    tree_text,
)


def small_tree() -> py_trees.behaviour.Behaviour:
    root = py_trees.composites.Sequence("Root", memory=False)
    gate = py_trees.composites.Selector("Gate", memory=False)
    gate.add_children([py_trees.behaviours.Failure("Confident?"), py_trees.behaviours.Running("Ask help")])
    # two siblings with one name must stay distinct nodes
    root.add_children(
        [py_trees.behaviours.Success("Perceive"), gate, py_trees.behaviours.Success("Perceive")]
    )
    return root


def test_slug_makes_one_path_part():
    assert slug("black pepper") == "black_pepper"
    assert slug("Confident?") == "Confident"
    assert slug("a/b") == "a_b"
    assert slug("???") == "_"


def test_flatten_tree_is_preorder_with_unique_ids_and_statuses():
    root = small_tree()
    root.tick_once()
    nodes = flatten_tree(root)
    ids = [n.node_id for n in nodes]
    assert ids == [
        "Root",
        "Root/Perceive",
        "Root/Gate",
        "Root/Gate/Confident",
        "Root/Gate/Ask_help",
        "Root/Perceive_2",
    ]
    status = {n.node_id: n.status for n in nodes}
    assert status["Root/Gate/Confident"] == "FAILURE"
    assert status["Root/Gate/Ask_help"] == "RUNNING"
    assert status["Root/Perceive_2"] == "INVALID"  # the sequence stopped at the running gate
    assert nodes[0].parent is None and nodes[0].depth == 0 and not nodes[0].is_leaf
    assert nodes[3].parent == "Root/Gate" and nodes[3].depth == 2 and nodes[3].is_leaf


def test_layout_centres_parents_beside_children_and_separates_leaves():
    nodes = flatten_tree(small_tree())
    pos = layout_tree(nodes, dx=100, dy=50)
    leaves = [pos[n.node_id] for n in nodes if n.is_leaf]
    assert len({y for _, y in leaves}) == len(leaves)
    assert pos["Root/Gate"][1] == pytest.approx(
        (pos["Root/Gate/Confident"][1] + pos["Root/Gate/Ask_help"][1]) / 2
    )
    assert pos["Root/Gate/Ask_help"][0] == 200 and pos["Root"][0] == 0


def test_tree_text_shows_every_node_with_status():
    root = small_tree()
    root.tick_once()
    text = tree_text(flatten_tree(root))
    lines = text.splitlines()
    assert len(lines) == 6
    assert lines[0].startswith("[*] Root (Sequence): running")
    assert "        [✕] Confident?: failure" in lines


def test_affordances_are_ranked_and_the_choice_marked():
    rows = [("Put salt on table", 0.2, 0.9), ("Put flour on table", 0.7, 0.3)]
    assert [r[0] for r in rank_affordances(rows)] == ["Put flour on table", "Put salt on table"]
    ask = Decision(DecisionKind.ASK, "Put flour on table", 0.7, 0.3, "confidence 0.30 below gate 0.50")
    md = affordances_markdown(rows, ask)
    body = md.splitlines()[2:]
    assert "**▶ Put flour on table**" in body[0] and "ASK" in body[0]
    assert "▶" not in body[1] and "ASK" not in body[1]
    act = Decision(DecisionKind.ACT, "Put salt on table", 0.2, 0.9, "confident")
    assert "ACT" in affordances_markdown(rows, act).splitlines()[3]
    assert "no affordances" in affordances_markdown([], None)
    assert decision_markdown(ask).startswith("### ASK-HELP: Put flour on table")


def test_recipe_markdown_marks_done_and_current_steps():
    recipe = RecipeView("Pasta", ("Boil water", "Add salt", "Add pasta"), 1, (True, False, False))
    lines = recipe_markdown(recipe).splitlines()
    assert lines[0] == "## Pasta"
    assert lines[2] == "1. ✔ ~~Boil water~~"
    assert lines[3] == "2. ▶ **Add salt**"
    assert lines[4] == "3. ○ Add pasta"
    finished = RecipeView("Pasta", ("Boil water",), None, (True,))
    assert "recipe finished" in recipe_markdown(finished)


def test_recipe_view_rejects_mismatched_flags():
    with pytest.raises(ValueError, match="2 steps but 1 done flags"):
        RecipeView("x", ("a", "b"), 0, (False,))


def test_clarify_marks_every_candidate_and_names_them() -> None:
    rows = [
        ("Put canola oil on table", 0.5, 0.9),
        ("Put sesame oil on table", 0.5, 0.9),
        ("Put honey on table", 0.2, 0.9),
    ]
    which = Decision(
        DecisionKind.CLARIFY,
        None,
        float("nan"),
        float("nan"),
        "which one",
        candidates=("Put canola oil on table", "Put sesame oil on table"),
    )
    body = affordances_markdown(rows, which).splitlines()[2:]
    assert sum("ASK-CLARIFY" in line for line in body) == 2 and "ASK-CLARIFY" not in body[2]
    card = decision_markdown(which)
    assert card.startswith("### ASK-CLARIFY: Put canola oil on table or Put sesame oil on table")
