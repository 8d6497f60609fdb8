"""What an analysis leaves in its folder: results.json, scores.csv and the Fig. 3 figure (PNG and PDF).

Here, above both `scone_bt.study.analysis` (the numbers) and `scone_bt.study.figure` (the plot), so that neither
imports the other.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from scone_bt.strict_json import dumps
from scone_bt.study.analysis import AnalysisResult, StudyData, check_outputs
from scone_bt.study.figure import plot_results

__all__ = ["write_outputs"]


def write_outputs(
    result: AnalysisResult, data: StudyData, folder: str | Path, force: bool = False
) -> dict[str, Path]:
    """results.json, scores.csv and the Fig. 3 figure (PNG and PDF) in `folder`."""
    paths = check_outputs(folder, force)
    paths["json"].write_text(dumps(result.to_json(), indent=2, default=_json_default))
    frame = data.sessions.copy()
    frame.insert(0, "data", "SIMULATED" if data.simulated else "real")
    frame.to_csv(paths["scores"], index=False)
    plot_results(result, data, paths["figure"], pdf=paths["figure_pdf"])
    return paths


def _json_default(obj: Any) -> Any:
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, Sequence):
        return list(obj)
    return str(obj)
