"""DecisionMade carries the chosen action's execution context: stored as a JSON object, read back equal."""

from __future__ import annotations

import pytest

from scone_bt.errors import SconeError
from scone_bt.events import DecisionMade, from_json
from scone_bt.experience.types import ExecutionContext
from scone_bt.gate.types import DecisionKind

CONTEXT = ExecutionContext(2, 0.0374, 1, True, 0.059, None)


def _decision(context: ExecutionContext | None) -> DecisionMade:
    return DecisionMade(
        1.0, 2, "Cook.", "Put parmesan on table", 0.12, 0.8, DecisionKind.ACT, context=context
    )


def test_context_round_trips_through_json() -> None:
    stored = _decision(CONTEXT).to_json()
    assert stored["context"] == {
        "shelf_tier": 2,
        "clearance_m": 0.0374,
        "neighbours": 1,
        "detected": True,
        "detected_width_m": 0.059,
    }
    assert from_json("decision", stored) == _decision(CONTEXT)


def test_no_context_and_logs_without_the_key_read_back_as_none() -> None:
    stored = _decision(None).to_json()
    assert stored["context"] is None and from_json("decision", stored).context is None
    del stored["context"]  # a log written before decisions carried a context
    assert from_json("decision", stored) == _decision(None)


@pytest.mark.parametrize(
    ("context", "message"),
    [
        ({"tier": 1}, "unknown field 'tier'"),
        ({"shelf_tier": "low"}, "shelf_tier must be int"),
        ({"detected": 1}, "detected must be bool"),
        ([1, 2], "expected a JSON object"),
    ],
)
def test_a_bad_context_is_a_one_line_error(context, message) -> None:
    stored = {**_decision(None).to_json(), "context": context}
    with pytest.raises(SconeError, match=message) as info:
        from_json("decision", stored)
    assert "\n" not in str(info.value) and "decision event: context" in str(info.value)
