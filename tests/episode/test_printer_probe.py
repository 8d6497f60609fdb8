"""The printer, the tablet's notes and rerun's log level know the aborted probe (events.ProbeAborted)."""

from __future__ import annotations

import pytest

from scone_bt.episode.printer import LinePrinter
from scone_bt.events import ProbeAborted

# the hard judge's words, and κ̂'s own doubt after feeling the product (gate.after_probe)
REASONS = ["the olive oil slips in my fingers", "I am not sure I can carry the olive oil"]


@pytest.mark.parametrize("reason", REASONS)
def test_an_aborted_probe_prints_its_reason(reason: str) -> None:
    lines: list[str] = []
    LinePrinter(lines.append, 4)(
        ProbeAborted(9.0, "Put olive oil on table", "olive oil", reason, 8.0, 2.6, 2.1)
    )
    assert lines == [f"    - set back after the probe: {reason} (2.6 s hefting it)"]


@pytest.mark.parametrize("reason", REASONS)
def test_rerun_logs_it_as_a_warning(reason: str) -> None:
    """rerun's text log is the printer's lines (episode.snapshot), at a level read from the line."""
    import rerun as rr

    from scone_bt.viz.draw_timeline import _log_level

    lines: list[str] = []
    LinePrinter(lines.append, 4)(
        ProbeAborted(9.0, "Put olive oil on table", "olive oil", reason, 8.0, 2.6, 2.1)
    )
    assert _log_level(lines[0]) == rr.TextLogLevel.WARN


def test_rerun_counts_the_set_backs_apart_from_successes_and_failures() -> None:
    from scone_bt.episode.snapshot import episode_counters
    from scone_bt.events import ActStarted, EventLog

    log = EventLog()
    log(ActStarted(1.0, "Put olive oil on table", "olive oil", 0.5))
    log(ProbeAborted(9.0, "Put olive oil on table", "olive oil", REASONS[1], 8.0, 2.6, 2.1))
    counters = episode_counters(log.stats)
    assert (counters["attempted"], counters["aborted"], counters["successes"], counters["failures"]) == (
        1,
        1,
        0,
        0,
    )
