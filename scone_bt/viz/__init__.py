"""rerun visualisation of every tick: the 3D kitchen, camera, gate, tree, plots and recipe, live or recorded.

`Recorder` (the rerun adapter) is imported on first use, so headless runs with `NullRecorder` never load rerun.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from scone_bt.viz.null import NullRecorder
from scone_bt.viz.snapshot import AffordanceRow, Pose, RecipeView, TickSnapshot

if TYPE_CHECKING:
    from scone_bt.viz.blueprint import default_blueprint
    from scone_bt.viz.recorder import Recorder

__all__ = [
    "Recorder",
    "NullRecorder",
    "TickSnapshot",
    "RecipeView",
    "AffordanceRow",
    "Pose",
    "default_blueprint",
]


def __getattr__(name: str) -> Any:
    if name == "Recorder":
        from scone_bt.viz.recorder import Recorder

        return Recorder
    if name == "default_blueprint":
        from scone_bt.viz.blueprint import default_blueprint

        return default_blueprint
    raise AttributeError(f"module 'scone_bt.viz' has no attribute {name!r}")
