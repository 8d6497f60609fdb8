"""Fixtures shared by the benchmark tests."""

from __future__ import annotations

import pytest


@pytest.fixture
def whole_held_fast_record(monkeypatch: pytest.MonkeyPatch) -> None:
    """The gate as it carried on by feel before 2026-12-07: the held-fast record read whole, whatever load the
    probe felt (gate.budget.BudgetCounts.held_fast_record without a traction). For tests that compare a replay
    with results committed before then."""
    import scone_bt.gate.after_probe as after_probe
    from scone_bt.gate.probe import feel_credit

    def whole(options, budget, counts, traction=None):  # noqa: ANN001, ANN202 - feel_credit's own signature
        return feel_credit(options, budget, counts)

    monkeypatch.setattr(after_probe, "feel_credit", whole)
