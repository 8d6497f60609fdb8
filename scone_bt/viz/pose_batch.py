"""The bodies that moved, arm links and products: kept per tick and sent to rerun in row batches
(`viz.tick_rows.TickRows`: one call per batch, each row at its own tick and simulated time)."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import rerun as rr

from scone_bt.viz import paths as P
from scone_bt.viz.sinks import Sinks
from scone_bt.viz.snapshot import Pose
from scone_bt.viz.tick_rows import TickRows

__all__ = ["POSE_EPS", "MovedFilter", "PoseBatch"]

POSE_EPS = 1e-5
"""Metres / quaternion units: below this a link or object has not moved and is not re-logged."""


class MovedFilter:
    """Which bodies moved by more than POSE_EPS (any coordinate) since each was last reported as moved.

    One array comparison for all the bodies of a tick: comparing pose by pose in Python cost more than sending
    the poses. A body seen for the first time has moved.
    """

    def __init__(self) -> None:
        self._names: tuple[str, ...] = ()
        self._last = np.zeros((0, 7))

    def moved(self, poses: Mapping[str, Pose]) -> list[str]:
        """The names in ``poses`` that moved, in their order; they are remembered at these poses."""
        names = tuple(poses)
        now = np.array([(*p[0], *p[1]) for p in poses.values()], dtype=float).reshape(len(names), 7)
        if names != self._names:
            self._realign(names)
        # A body never seen (NaN in _last) has moved; a pose with no number (NaN now) is not sent: the body
        # stays where it was last drawn.
        changed = ~(np.abs(now - self._last) <= POSE_EPS).all(axis=1) & np.isfinite(now).all(axis=1)
        self._last[changed] = now[changed]
        return [names[i] for i in np.flatnonzero(changed)]

    def _realign(self, names: tuple[str, ...]) -> None:
        """Rows for a new set of names: a name seen before keeps its last pose, a new one has none (NaN)."""
        index = {name: i for i, name in enumerate(self._names)}
        last = np.full((len(names), 7), np.nan)
        for i, name in enumerate(names):
            if name in index:
                last[i] = self._last[index[name]]
        self._names, self._last = names, last


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
