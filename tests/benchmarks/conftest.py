"""Fixtures shared by the benchmark tests."""

from __future__ import annotations

import pytest


@pytest.fixture
def whole_held_fast_record(monkeypatch: pytest.MonkeyPatch) -> None:
    """The gate as it carried on by feel before commit d6da581 (2026-12-07, twenty-first session): the held-fast
    record read whole, whatever load the probe felt, and no separate record of carries by feel. For tests that
    compare a replay with results committed before then."""
    from dataclasses import replace

    import scone_bt.gate.after_probe as after_probe
    from scone_bt.gate.budget import has_credit

    def whole(options, budget, counts, traction=None):  # noqa: ANN001, ANN202 - feel_doubt's own signature
        if options is None:
            return ""
        own = replace(budget, excess_allowance=options.feel_allowance)
        return None if has_credit(own, counts.held_fast_record()) else "the record ran out"

    monkeypatch.setattr(after_probe, "feel_doubt", whole)
