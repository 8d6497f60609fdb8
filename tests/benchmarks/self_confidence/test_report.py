"""The report's figures are written whole or not at all: an interrupted write leaves the old PNG in place."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import pytest

from scone_bt.benchmarks.self_confidence.report import plot_curves, plot_reliability

RESULTS = Path(__file__).resolve().parents[3] / "docs" / "results"
PNG = b"\x89PNG\r\n\x1a\n"


def _small_report() -> dict:
    report = json.loads((RESULTS / "self_confidence.json").read_text())
    protocol = next(iter(report["protocols"]))
    report["protocols"] = {protocol: report["protocols"][protocol]}
    report["estimators"] = report["estimators"][:1]
    return report


def _curves(report: dict, folder: Path) -> Path:
    return plot_curves(report, folder, "sc")[0]


def _reliability(report: dict, folder: Path) -> Path:
    return plot_reliability(report, folder / "sc_reliability.png")


@pytest.mark.parametrize("plot", [_curves, _reliability])
def test_an_interrupted_figure_write_leaves_the_old_png_whole(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, plot: Callable[[dict, Path], Path]
) -> None:
    import matplotlib.figure

    report = _small_report()
    first = plot(report, tmp_path)  # where the figure goes, and a complete one there
    old = first.read_bytes()
    assert old.startswith(PNG) and len(old) > 1000

    def half_then_interrupted(self: object, fname: object, *args: object, **kwargs: object) -> None:
        Path(str(fname)).write_bytes(PNG + b"half")
        raise KeyboardInterrupt

    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", half_then_interrupted)
    with pytest.raises(KeyboardInterrupt):
        plot(report, tmp_path)
    assert first.read_bytes() == old
    assert sorted(tmp_path.iterdir()) == [first]  # no temporary file left beside it
