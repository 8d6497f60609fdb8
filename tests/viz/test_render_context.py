"""The viewer's affordance table shows the context the gate perceived for each action (when there is one)."""

from __future__ import annotations

from scone_bt.experience.types import ExecutionContext
from scone_bt.gate.types import Decision, DecisionKind
from scone_bt.viz.render import affordances_markdown, context_text

ROWS = [("Put salt on table", 0.6, 0.9), ("Put parmesan on table", 0.1, 0.2)]
ACT = Decision(DecisionKind.ACT, "Put salt on table", 0.6, 0.9, "confident")


def test_a_context_column_appears_only_with_contexts() -> None:
    contexts = {"Put parmesan on table": ExecutionContext(2, 0.0374, 1, True, 0.059, 0.04)}
    lines = affordances_markdown(ROWS, ACT, contexts).splitlines()
    assert lines[0].endswith("| context |") and lines[1].count("|") == 7
    assert lines[3].endswith("| tier 2 · gap 4 cm · 1 near · 6×4 cm |")
    assert lines[2].endswith("|  |")  # salt: no context perceived
    assert affordances_markdown(ROWS, ACT) == affordances_markdown(ROWS, ACT, {})
    assert "context" not in affordances_markdown(ROWS, ACT)


def test_unknown_values_show_as_question_marks() -> None:
    assert (
        context_text(ExecutionContext(neighbours=0, detected=True)) == "tier ? · gap ? cm · 0 near · ?×? cm"
    )
    assert context_text(None) == ""
