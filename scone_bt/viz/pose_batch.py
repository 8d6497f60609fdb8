"""The bodies that moved, arm links and products: kept per tick and sent to rerun in row batches
(`viz.tick_rows.TickRows`: one call per batch, each row at its own tick and simulated time)."""

from __future__ import annotations

import numpy as np
import rerun as rr

from scone_bt.viz import paths as P
from scone_bt.viz.sinks import Sinks
from scone_bt.viz.snapshot import Pose
from scone_bt.viz.tick_rows import TickRows

__all__ = ["POSE_EPS", "PoseBatch", "moved"]

POSE_EPS = 1e-5
"""Metres / quaternion units: below this a link or object has not moved and is not re-logged."""


def moved(a: Pose | None, b: Pose) -> bool:
    """Whether pose ``b`` differs from ``a`` (None: never logged) by more than POSE_EPS."""
    # Plain Python: numpy's per-call overhead dominates for 3- and 4-vectors.
    if a is None:
        return True
    return any(abs(x - y) > POSE_EPS for x, y in zip(a[0], b[0], strict=True)) or any(
        abs(x - y) > POSE_EPS for x, y in zip(a[1], b[1], strict=True)
    )


def _transforms(rows: list[tuple[str, Pose]]) -> object:
    """The Transform3D columns of (transform frame id, world pose) rows."""
    return rr.Transform3D.columns(
        translation=np.array([pose[0] for _, pose in rows], dtype=float),
        quaternion=np.array([pose[1] for _, pose in rows], dtype=float),
        parent_frame=[f"tf#/{P.WORLD}"] * len(rows),
        child_frame=[frame for frame, _ in rows],
    )


class PoseBatch:
    """Moved bodies of this tick, each as (transform frame id, world pose), until `send` keeps them."""

    def __init__(self, sinks: Sinks) -> None:
        self._pending: list[tuple[str, Pose]] = []
        self._rows: TickRows[tuple[str, Pose]] = TickRows(sinks, P.POSES, _transforms)

    def add(self, frame: str, pose: Pose) -> None:
        self._pending.append((frame, pose))

    def send(self, tick: int, sim_time: float) -> None:
        """This tick's moved bodies, kept with its tick and time until their batch is due."""
        self._rows.keep(tick, sim_time, self._pending)
        self._pending = []

    def flush(self) -> None:
        """Send every kept row now (the recorder's flush and close call it)."""
        self._rows.flush()
