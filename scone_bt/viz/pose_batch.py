"""The bodies that moved, arm links and products, sent to rerun in row batches: a tick's rows are kept until
`BATCH_TICKS` ticks or `BATCH_WALL_S` of wall time have gathered (or the recording is flushed), then sent in one
call. One `send_columns` call costs about as much as a tick's physics step: sending every tick's moved bodies in
its own call was a quarter of the recorder's cost (`scone-bench viz`). The rows carry their own tick and
simulated time, so the recording is the same either way; a live viewer sees them at most `BATCH_WALL_S` later."""

from __future__ import annotations

import time

import numpy as np
import rerun as rr

from scone_bt.viz import paths as P
from scone_bt.viz.sinks import Sinks
from scone_bt.viz.snapshot import Pose

__all__ = ["BATCH_TICKS", "BATCH_WALL_S", "POSE_EPS", "PoseBatch", "TickBatch", "moved"]

POSE_EPS = 1e-5
"""Metres / quaternion units: below this a link or object has not moved and is not re-logged."""
BATCH_TICKS = 10
"""Ticks whose rows are sent together at the most."""
BATCH_WALL_S = 0.1
"""Wall seconds a kept row waits at the most (what a live viewer lags by)."""


def moved(a: Pose | None, b: Pose) -> bool:
    """Whether pose ``b`` differs from ``a`` (None: never logged) by more than POSE_EPS."""
    # Plain Python: numpy's per-call overhead dominates for 3- and 4-vectors.
    if a is None:
        return True
    return any(abs(x - y) > POSE_EPS for x, y in zip(a[0], b[0], strict=True)) or any(
        abs(x - y) > POSE_EPS for x, y in zip(a[1], b[1], strict=True)
    )


class TickBatch:
    """When kept rows are due: after `BATCH_TICKS` ticks or `BATCH_WALL_S` of wall time since the first."""

    def __init__(self) -> None:
        self.ticks = 0
        self._since: float | None = None

    def kept(self) -> bool:
        """Count one more tick with rows; True when the rows are due."""
        self.ticks += 1
        if self._since is None:
            self._since = time.monotonic()
        return self.ticks >= BATCH_TICKS or time.monotonic() - self._since >= BATCH_WALL_S

    def reset(self) -> None:
        self.ticks, self._since = 0, None


class PoseBatch:
    """Moved bodies, each as (transform frame id, world pose), kept per tick until they are due (`send`)."""

    def __init__(self, sinks: Sinks) -> None:
        self._sinks = sinks
        self._pending: list[tuple[str, Pose]] = []
        self._rows: list[tuple[int, float, str, Pose]] = []
        self._batch = TickBatch()

    def add(self, frame: str, pose: Pose) -> None:
        self._pending.append((frame, pose))

    def send(self, tick: int, sim_time: float) -> None:
        """This tick's moved bodies, kept with its tick and time; every kept row goes out once they are due."""
        if not self._pending:
            return
        self._rows.extend((tick, sim_time, f, p) for f, p in self._pending)
        self._pending = []
        if self._batch.kept():
            self.flush()

    def flush(self) -> None:
        """Send every kept row now, in one call (the recorder's flush and close call it)."""
        self._batch.reset()
        if not self._rows:
            return
        rows, self._rows = self._rows, []
        n = len(rows)
        self._sinks.rec.send_columns(
            P.POSES,
            indexes=[
                rr.TimeColumn(P.TICK, sequence=[r[0] for r in rows]),
                rr.TimeColumn(P.SIM_TIME, duration=[r[1] for r in rows]),
            ],
            columns=rr.Transform3D.columns(
                translation=np.array([r[3][0] for r in rows], dtype=float),
                quaternion=np.array([r[3][1] for r in rows], dtype=float),
                parent_frame=[f"tf#/{P.WORLD}"] * n,
                child_frame=[r[2] for r in rows],
            ),
        )
