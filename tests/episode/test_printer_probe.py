"""The printer, the tablet's notes and rerun's log level know the aborted probe (events.ProbeAborted)."""

from __future__ import annotations

from scone_bt.episode.printer import LinePrinter
from scone_bt.events import ProbeAborted


def test_an_aborted_probe_prints_its_reason() -> None:
    lines: list[str] = []
    LinePrinter(lines.append, 4)(
        ProbeAborted(
            9.0, "Put olive oil on table", "olive oil", "the olive oil slips in my fingers", 8.0, 2.6, 2.1
        )
    )
    assert lines == ["    - set back after the probe: the olive oil slips in my fingers (2.6 s hefting it)"]


def test_rerun_logs_it_as_a_warning() -> None:
    import rerun as rr

    from scone_bt.viz.draw_timeline import _log_level

    assert _log_level("    - set back after the probe: the jar slips in my fingers") == rr.TextLogLevel.WARN
