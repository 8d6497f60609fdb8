"""Benchmarks and the scenario runner take `emit_report` from scone_bt.reporting, never from the CLI above them."""

from __future__ import annotations

from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[2] / "scone_bt"


def test_no_module_imports_emit_report_from_the_cli():
    from scone_bt.cli import bench

    assert not hasattr(bench, "emit_report")  # no re-export left for an importer to find
    upward = sorted(
        str(path.relative_to(PACKAGE))
        for path in PACKAGE.rglob("*.py")
        if "from scone_bt.cli.bench import emit_report" in path.read_text(encoding="utf-8")
    )
    assert upward == []
