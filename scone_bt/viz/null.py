"""A recorder that records nothing: headless runs without --save/--viewer/--connect pay no logging cost."""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from scone_bt.viz.scene import SceneView
    from scone_bt.viz.snapshot import TickSnapshot

__all__ = ["NullRecorder"]


class NullRecorder:
    """Same interface as `Recorder`; every call returns at once."""

    recording_id = ""
    save_path = None

    def __init__(self) -> None:
        self.ticks_logged = 0

    def log_static_scene(self, kitchen: SceneView | None) -> None:
        """Do nothing (a backend that cannot be recorded has no scene to give)."""

    def log_tick(self, snap: TickSnapshot) -> None:
        """Count the tick, log nothing."""
        self.ticks_logged += 1

    def flush(self) -> None:
        """Do nothing."""

    def close(self, complete: bool = True) -> None:
        """Do nothing."""

    def __enter__(self) -> NullRecorder:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
