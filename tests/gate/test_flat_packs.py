"""The too-wide rule and an arm that slides and pinches flat packs (`GateRules.slide_pinch`): a flat pack on a
lowest tier is κ̂'s to decide; wider products elsewhere are still asked for."""

from __future__ import annotations

import pytest

from scone_bt.experience.types import ExecutionContext
from scone_bt.gate.budget import BudgetOptions
from scone_bt.gate.rules import GateInput, GateRules, flat_on_lowest, gate_decision
from scone_bt.gate.types import DecisionKind
from scone_bt.relevance.types import RankedAction

TRAY = "Put chicken breast on table"
OPENING = 0.08


def _contexts(tier: int, height: float) -> dict[str, ExecutionContext]:
    return {TRAY: ExecutionContext(shelf_tier=tier, detected_width_m=0.14, detected_height_m=height)}


def test_a_flat_pack_wider_than_the_gripper_is_flat_on_lowest_only_on_tier_0():
    assert flat_on_lowest(_contexts(0, 0.04), OPENING) == {TRAY}
    assert flat_on_lowest(_contexts(1, 0.04), OPENING) == frozenset()  # a higher tier: the hand cuts into it
    assert flat_on_lowest(_contexts(0, 0.12), OPENING) == frozenset()  # a tall box: not flat
    assert flat_on_lowest(_contexts(0, 0.04), 0.16) == frozenset()  # a gripper that spans it grasps it
    assert flat_on_lowest({TRAY: ExecutionContext(shelf_tier=0)}, OPENING) == frozenset()  # not measured


@pytest.mark.parametrize("slide_pinch, kind", [(False, DecisionKind.ASK), (True, DecisionKind.ACT)])
def test_the_too_wide_rule_leaves_a_flat_pack_on_a_lowest_tier_to_an_arm_that_slides_it(slide_pinch, kind):
    rules = GateRules(budget=BudgetOptions(), opening_m=OPENING, slide_pinch=slide_pinch)
    contexts = _contexts(0, 0.04)
    seen = GateInput(
        ranked=(RankedAction(TRAY, 1.0),),
        confidences=(0.99,),
        objects={TRAY: "chicken breast"},
        widths_m={TRAY: 0.14},
        flat_on_lowest=flat_on_lowest(contexts, OPENING),
    )
    decision = gate_decision(rules, seen).decision
    assert decision.kind is kind
    assert (decision.rule == "too-wide") is (not slide_pinch)
    # on a higher tier the same pack is asked for by either arm
    higher = GateInput(**{**seen.__dict__, "flat_on_lowest": flat_on_lowest(_contexts(1, 0.04), OPENING)})
    assert gate_decision(rules, higher).decision.rule == "too-wide"
