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
    assert (
        "95 % CI [" in rendered and "## Against the targets" in rendered
    )  # the prose and the targets are in it


def test_each_target_label_states_the_threshold_it_is_checked_against():
    from scone_bt.benchmarks.self_confidence.report import report_data, target_checks

    report = json.loads((RESULTS / "self_confidence.json").read_text())
    labels = {c["target"] for c in target_checks(report)}
    targets = report_data()["targets"]
    assert "Algorithm 1: best semantic pair ≥ 0.85 (ungrounded)" in labels
    assert "Whole grid ≤ 10 min" in labels and "Algorithm 1 order semantic > GloVe > one-hot (lgbm)" in labels
    for key in ("best_semantic", "semantic_gap", "novel_products", "ece"):
        shown = f"{targets[key]['threshold']:.2f}"
        assert any(shown in label for label in labels), (key, shown)


def test_the_prose_is_data_beside_the_module_not_code():
    from importlib import resources

    folder = resources.files("scone_bt.benchmarks.self_confidence").joinpath("report_text")
    names = {p.name for p in folder.iterdir()}
    assert {"page.md", "report.yaml", "protocol.md", "metric.md"} <= names
    code = (Path(__file__).resolve().parents[3] / "scone_bt/benchmarks/self_confidence/report.py").read_text()
    assert "Paired intervals" not in code and "≥ 0.85" not in code  # the story lives in report_text/
