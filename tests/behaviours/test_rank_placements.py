"""RankByRelevance with fakes: the robot's labelled placements count as on the table for its own step."""

from __future__ import annotations

import py_trees

from scone_bt.behaviours import Keys, RankByRelevance
from scone_bt.embedding import load_embedder
from scone_bt.experience.types import Outcome
from scone_bt.relevance.recipe_aware import SelectionOptions
from tests.behaviours.fakes import FakeHuman, affordance

STEPS = ("Fry the bacon.", "Add macaroni and the milk.", "Serve with applesauce.")
NEEDED = ("bacon", "macaroni", "milk", "applesauce")


def _outcome(name: str, success: bool) -> Outcome:
    return Outcome(0.0, f"Put {name} on table", name, "onehot", success, None if success else "grasp")


class _Board:
    def __init__(self) -> None:
        self.writer = py_trees.blackboard.Client(name="test")
        for key in (Keys.AFFORDANCES, Keys.TABLE_DETECTIONS, Keys.OUTCOME):
            self.writer.register_key(key=key, access=py_trees.common.Access.WRITE)
        self.reader = py_trees.blackboard.Client(name="reader")
        self.reader.register_key(key=Keys.STEP, access=py_trees.common.Access.READ)

    def tick(self, rank: RankByRelevance, shelf: tuple[str, ...], outcome: Outcome | None = None):
        self.writer.set(Keys.AFFORDANCES, [affordance(n) for n in shelf])
        self.writer.set(Keys.TABLE_DETECTIONS, ())  # the table camera sees nothing (everything hidden)
        if outcome is not None:
            self.writer.set(Keys.OUTCOME, outcome)
        rank.tick_once()
        return self.reader.get(Keys.STEP)


def _rank(tmp_path) -> RankByRelevance:
    embedder = load_embedder("onehot", tmp_path)
    rank = RankByRelevance(
        "rank",
        lambda: embedder,
        STEPS,
        {n: () for n in NEEDED},
        SelectionOptions(rho=0.5, margin=0.03),
        True,
        FakeHuman(),
    )
    rank.setup()
    return rank


def test_the_robots_successful_placements_complete_a_step_the_camera_cannot_see(tmp_path) -> None:
    board, rank = _Board(), _rank(tmp_path)
    view = board.tick(rank, ("macaroni", "milk", "applesauce"), _outcome("bacon", True))
    assert view.index == 1 and view.placed_by_robot == {"bacon"}
    view = board.tick(rank, ("milk", "applesauce"), _outcome("macaroni", True))
    assert view.index == 1 and view.missing == ()  # macaroni: placed by the robot, not missing
    view = board.tick(rank, ("applesauce",), _outcome("milk", True))
    assert view.index == 2 and view.placed_unseen == {"bacon", "macaroni", "milk"}
    assert view.selection.now == ("applesauce",)


def test_a_failure_or_the_shelf_says_a_placed_item_is_not_on_the_table(tmp_path) -> None:
    board, rank = _Board(), _rank(tmp_path)
    board.tick(rank, ("macaroni", "milk", "applesauce"), _outcome("bacon", True))
    view = board.tick(rank, ("milk", "applesauce"), _outcome("macaroni", True))
    assert view.index == 1 and view.placed_by_robot == {"bacon", "macaroni"}
    view = board.tick(rank, ("macaroni", "milk", "applesauce"))  # macaroni is back on the shelf
    assert view.placed_by_robot == {"bacon"} and view.selection.now == ("macaroni", "milk")
    view = board.tick(rank, ("milk", "applesauce"))  # out of sight again: no longer counted as placed
    assert view.index == 1 and view.missing == ("macaroni",)
    board.tick(rank, ("milk", "applesauce"), _outcome("macaroni", True))
    view = board.tick(rank, ("milk", "applesauce"), _outcome("macaroni", False))
    assert view.placed_by_robot == {"bacon"} and view.missing == ("macaroni",)
