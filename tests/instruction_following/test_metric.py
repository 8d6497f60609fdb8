"""The IF metric on a hand-made state."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import pytest

from scone_bt.instruction_following.metric import evaluate, run_episode, score_episode
from scone_bt.instruction_following.states import IfState


@dataclass
class Scripted:
    order: tuple[str, ...]
    name: str = "scripted"

    def choose(self, state: IfState, remaining: Sequence[str], picked: Sequence[str]) -> str | None:
        return self.order[len(picked)] if len(picked) < len(self.order) else None


def test_accuracy_and_recall(salad_state) -> None:
    ep = run_episode(Scripted(("Put olive oil on table", "Put salt on table")), salad_state)
    assert ep.picks == ("Put olive oil on table", "Put salt on table")
    assert ep.accuracy == pytest.approx(0.5)
    assert ep.recall == pytest.approx(0.5)


def test_picking_everything_scores_the_base_rate(salad_state) -> None:
    ep = run_episode(Scripted(salad_state.available), salad_state)
    assert ep.accuracy == pytest.approx(2 / 5)
    assert ep.recall == 1.0


def test_stopping_at_once(salad_state) -> None:
    assert score_episode(salad_state, []).accuracy == 0.0
    empty = IfState("Preheat the oven.", ("Put salt on table",), frozenset())
    assert score_episode(empty, []).accuracy == 1.0
    assert score_episode(empty, ["Put salt on table"]).accuracy == 0.0


def test_evaluate_averages_over_states(salad_state) -> None:
    other = IfState(
        "Add the sugar.", ("Put sugar on table", "Put salt on table"), frozenset({"Put sugar on table"})
    )
    score = evaluate(Scripted(("Put sugar on table",)), [salad_state, other])
    # salad: picks sugar (wrong) → 0; other: picks sugar (right) → 1.
    assert score.accuracy == pytest.approx(0.5)
    assert score.recall == pytest.approx(0.5)
    assert score.picks_per_state == 1.0


def test_policy_may_not_pick_twice(salad_state) -> None:
    with pytest.raises(ValueError, match="not among the remaining"):
        run_episode(Scripted(("Put salt on table", "Put salt on table")), salad_state)
