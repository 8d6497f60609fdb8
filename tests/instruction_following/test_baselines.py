"""PDDL (LAMA) and TICC-style MCTS baselines on tiny problems."""

from __future__ import annotations

import numpy as np

from scone_bt.instruction_following.mcts_baseline import MctsOptions, TiccMctsPolicy, mcts_decide
from scone_bt.instruction_following.metric import evaluate
from scone_bt.instruction_following.pddl_baseline import PddlPolicy, instruction_goal, plan_fetches


def test_lama_solves_a_tiny_fetch_problem() -> None:
    plan = plan_fetches(
        ["salt", "flour", "eggs"], {"salt": (0, 1), "flour": (2, 3), "eggs": (1, 0)}, ["flour", "eggs"]
    )
    assert plan.status.startswith("SOLVED")
    assert sorted(plan.placed) == ["eggs", "flour"]
    # One hand: every place follows its own pick.
    assert len(plan.actions) == 4
    for pick, place in zip(plan.actions[::2], plan.actions[1::2], strict=True):
        assert pick.startswith("pick(") and place.startswith("place(")


def test_empty_goal_needs_no_planner() -> None:
    plan = plan_fetches(["salt"], {}, [])
    assert plan.status == "EMPTY_GOAL" and plan.placed == ()


def test_pddl_policy_is_blind_to_negation(salad_state) -> None:
    assert instruction_goal(salad_state.instruction, ["olive oil", "vinegar", "salt", "sugar"]) == [
        "olive oil",
        "vinegar",
        "salt",
    ]
    score = evaluate(PddlPolicy(), [salad_state])
    assert set(score.episodes[0].picks) == {
        "Put olive oil on table",
        "Put vinegar on table",
        "Put salt on table",
    }
    assert score.accuracy == 2 / 3


def test_mcts_fetches_likely_items_and_stops() -> None:
    belief = {"a": 0.95, "b": 0.05, "c": 0.1}
    success = {"a": 0.9, "b": 0.9, "c": 0.9}
    opts = MctsOptions(simulations=400)
    choice, values = mcts_decide(["a", "b", "c"], belief, success, opts, np.random.default_rng(0))
    assert choice == "a"
    assert values["a"] > values["b"]
    choice, _ = mcts_decide(["b", "c"], belief, success, opts, np.random.default_rng(0))
    assert choice is None


def test_mcts_weighs_its_proficiency() -> None:
    # Equally likely to be needed, but the robot rarely manages "high": it fetches "low" first.
    belief = {"low": 0.8, "high": 0.8}
    success = {"low": 0.95, "high": 0.3}
    choice, values = mcts_decide(
        ["low", "high"], belief, success, MctsOptions(simulations=400), np.random.default_rng(1)
    )
    assert choice == "low"
    assert values["low"] > values["high"]


def test_ticc_policy_on_a_state(salad_state) -> None:
    def belief(state):
        return {
            a: (0.9 if a in ("Put olive oil on table", "Put vinegar on table") else 0.05)
            for a in state.available
        }

    score = evaluate(TiccMctsPolicy(belief, MctsOptions(simulations=200)), [salad_state])
    assert score.accuracy == 1.0
    assert score.recall == 1.0
