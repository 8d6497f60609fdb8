"""The shipped tree, every behaviour wired from a context of fakes, ticked through whole decision cycles."""

from __future__ import annotations

import py_trees

from scone_bt.config import load_kitchen
from scone_bt.events import ActOutcome, ActStarted, DecisionMade, HelpRequested
from scone_bt.gate.types import DecisionKind
from scone_bt.tree import build_tree, load_tree_spec
from tests.behaviours.fakes import FakeHuman, FakeRobot, FixedKappa, det, fake_context


def _on_shelf(name: str, i: int = 0):
    x, y, z = load_kitchen().scene.shelf_slots()[i]
    return det(name, (x, y, z + 0.1), track=i)


def _tree(tmp_path, confidence: float):
    robot, human = FakeRobot(shelf=[_on_shelf("salt")]), FakeHuman()
    context = fake_context(tmp_path, robot, human, FixedKappa(confidence))
    root = build_tree(load_tree_spec("assistive_cooking"), context)
    tree = py_trees.trees.BehaviourTree(root)
    tree.setup(timeout=10)
    return tree, robot, human, context


def test_a_confident_cycle_acts_observes_and_learns(tmp_path) -> None:
    tree, robot, human, context = _tree(tmp_path, confidence=0.9)
    tree.tick()
    (request,) = robot.requests
    assert request.target.name == "salt"
    robot.handles[0].finish(True)
    robot.on_table.add("salt")
    tree.tick()
    kinds = [type(e) for e in context.events.events]
    assert kinds == [DecisionMade, ActStarted, ActOutcome]
    assert context.events.stats.successes == 1 and context.kappa().updates == [True]
    assert human.busy == [True, False]


def test_an_unconfident_cycle_asks_for_help(tmp_path) -> None:
    tree, robot, human, context = _tree(tmp_path, confidence=0.1)
    tree.tick()
    decision = context.events.events[0]
    assert decision.verdict is DecisionKind.ASK and robot.requests == []
    assert isinstance(context.events.events[1], HelpRequested) and human.helped == ["salt"]
    human.pending.clear()
    human.done = True
    tree.tick()  # the help cycle ends; the next tick finds the recipe done
    tree.tick()
    assert tree.root.status is py_trees.common.Status.SUCCESS
