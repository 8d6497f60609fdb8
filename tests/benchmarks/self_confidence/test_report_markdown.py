"""The committed self-confidence report renders again, byte for byte, from its committed JSON."""

from __future__ import annotations

import json
from pathlib import Path

from scone_bt.benchmarks.self_confidence.report import evaluation_markdown

RESULTS = Path(__file__).resolve().parents[3] / "docs" / "results"


def _without_hand_notes(markdown: str) -> str:
    """The committed page less the block quote a maintainer added by hand under the title (a staleness note)."""
    lines = markdown.splitlines(keepends=True)
    out, i = lines[:2], 2
    while i < len(lines) and lines[i].startswith(">"):
        i += 1
    if i > 2 and i < len(lines) and lines[i] == "\n":
        i += 1  # the blank line that closed the note
    return "".join(out + lines[i:])


def test_the_committed_report_renders_byte_for_byte_from_its_json():
    report = json.loads((RESULTS / "self_confidence.json").read_text())
    committed = _without_hand_notes((RESULTS / "self_confidence.md").read_text())
    rendered = evaluation_markdown(report, "self_confidence")
    assert rendered == committed
    assert "95 % CI [" in rendered and "## Against the targets" in rendered  # the prose and the targets are in it
