"""The bodies that moved in one tick (arm links and products), sent to rerun together in one row batch."""

from __future__ import annotations

import numpy as np
import rerun as rr

from scone_bt.viz import paths as P
from scone_bt.viz.sinks import Sinks
from scone_bt.viz.snapshot import Pose

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


class PoseBatch:
    """Moved bodies of this tick, each as (transform frame id, world pose), until `send`."""

    def __init__(self, sinks: Sinks) -> None:
        self._sinks = sinks
        self._pending: list[tuple[str, Pose]] = []

    def add(self, frame: str, pose: Pose) -> None:
        self._pending.append((frame, pose))

    def send(self, tick: int, sim_time: float) -> None:
        """All moved links and objects of this tick in one row batch: one call instead of one per body."""
        if not self._pending:
            return
        n = len(self._pending)
        frames = [f for f, _ in self._pending]
        translations = np.array([p[0] for _, p in self._pending], dtype=float)
        quaternions = np.array([p[1] for _, p in self._pending], dtype=float)
        self._pending = []
        self._sinks.rec.send_columns(
            P.POSES,
            indexes=[
                rr.TimeColumn(P.TICK, sequence=[tick] * n),
                rr.TimeColumn(P.SIM_TIME, duration=[sim_time] * n),
            ],
            columns=rr.Transform3D.columns(
                translation=translations,
                quaternion=quaternions,
                parent_frame=[f"tf#/{P.WORLD}"] * n,
                child_frame=frames,
            ),
        )
